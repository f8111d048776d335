//! Prints the statements and diagnostics of a CL file: `cargo run -p kinpost-cl --example dump -- FILE [--3axis]`.

use std::io::BufReader;

use kinpost_cl::ClReader;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("usage: dump FILE [--3axis]");
    let three_axis = args.next().is_some_and(|a| a == "--3axis");
    let file = std::fs::File::open(&path).expect("cannot open the file");
    let mut reader = ClReader::new(BufReader::new(file), path);
    if three_axis {
        reader = reader.with_default_axis([0.0, 0.0, 1.0]);
    }
    loop {
        let result = reader.next_statement();
        for w in reader.take_warnings() {
            println!("{w}\n");
        }
        match result {
            Ok(Some(s)) => println!("{:>6}: {:?}", s.line, s.event),
            Ok(None) => break,
            Err(e) => {
                println!("{e}");
                std::process::exit(1);
            }
        }
    }
}
