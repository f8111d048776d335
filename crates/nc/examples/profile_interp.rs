//! Reads a program many times with a counting sink, for `perf record`:
//! `cargo run --release -p kinpost-nc --example profile_interp -- FILE FAMILY [REPEATS]`
//! (FAMILY: sinumerik, fanuc, linuxcnc, heidenhain, csv; axes X Y Z A C).

use kinpost_nc::AxisSpec;
use kinpost_nc::interp::{Event, Family, Options, Step, run};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: profile_interp FILE FAMILY [REPEATS]");
        std::process::exit(2);
    }
    let text = std::fs::read_to_string(&args[1]).expect("readable program");
    let family = match args[2].as_str() {
        "sinumerik" => Family::Sinumerik,
        "fanuc" => Family::Fanuc,
        "linuxcnc" => Family::LinuxCnc,
        "heidenhain" => Family::Heidenhain,
        _ => Family::Csv,
    };
    let repeats: usize = args.get(3).and_then(|r| r.parse().ok()).unwrap_or(10);
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("A"),
        AxisSpec::endless("C"),
    ];
    let start = std::time::Instant::now();
    let mut moves = 0u64;
    for _ in 0..repeats {
        let mut sink = |s: &Step| {
            if matches!(s.event, Event::Move(_)) {
                moves += 1;
            }
        };
        if let Err(e) = run(
            &text,
            family,
            &axes,
            &Options::default(),
            &args[1],
            &mut sink,
        ) {
            eprintln!("{e}");
            std::process::exit(1);
        }
    }
    let s = start.elapsed().as_secs_f64();
    println!(
        "{moves} moves in {s:.3} s: {:.2} M moves/s",
        moves as f64 / s / 1e6
    );
}
