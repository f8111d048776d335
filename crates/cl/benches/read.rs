//! Reading speed: a generated 100,000-line CL file from memory.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinpost_cl::{ClEvent, ClReader, Move, Next};

/// A 5-axis CL file of `lines` lines, mostly `GOTO/x,y,z,i,j,k` like NX writes.
fn generate(lines: usize) -> String {
    let mut cl = String::with_capacity(lines * 48);
    cl.push_str("TOOL PATH/BENCH,TOOL,EM10\nTLDATA/MILL,10.0000,0.0000,75.0000,0.0000,0.0000\n");
    cl.push_str(
        "MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000\n",
    );
    cl.push_str("RAPID\nGOTO/-416.0000,70.5000,16.5300,0.0000000,0.0000000,1.0000000\nFEDRAT/MMPM,250.0000\n");
    let mut n = 6;
    let mut k = 0u32;
    while n < lines {
        let t = f64::from(k) * 1e-3;
        let (s, c) = t.sin_cos();
        if k % 1000 == 999 {
            cl.push_str("$$ next pass\n");
        } else if k.is_multiple_of(4) {
            cl.push_str(&format!(
                "GOTO/{:.4},{:.4},{:.4}\n",
                -416.0 + 10.0 * c,
                70.0 + 10.0 * s,
                11.0 + t
            ));
        } else {
            cl.push_str(&format!(
                "GOTO/{:.4},{:.4},{:.4},{:.7},{:.7},{:.7}\n",
                -416.0 + 10.0 * c,
                70.0 + 10.0 * s,
                11.0 + t,
                0.3 * s,
                0.3 * c,
                0.9539392
            ));
        }
        n += 1;
        k += 1;
    }
    cl.push_str("END-OF-PATH\n");
    cl
}

fn read_all(cl: &str) -> usize {
    let mut gotos = 0;
    for statement in ClReader::new(cl.as_bytes(), "bench.cls") {
        if let ClEvent::Goto { point, .. } = statement.expect("valid CL").event {
            black_box(point);
            gotos += 1;
        }
    }
    gotos
}

/// The post's hot path: plain `GOTO` lines written into one reused [`Move`].
fn read_moves(cl: &str) -> usize {
    let mut reader = ClReader::new(cl.as_bytes(), "bench.cls");
    let mut goto = Move::default();
    let mut gotos = 0;
    loop {
        match reader.next_move(&mut goto).expect("valid CL") {
            Next::Move => {
                black_box(&goto);
                gotos += 1;
            }
            Next::Statement(statement) => {
                black_box(statement);
            }
            Next::End => return gotos,
        }
    }
}

fn bench(c: &mut Criterion) {
    let lines = 100_000;
    let cl = generate(lines);
    assert!(read_all(&cl) > 99_000);
    let mut group = c.benchmark_group("cl");
    group.throughput(Throughput::Elements(lines as u64));
    group.bench_function("read_100k_lines", |b| b.iter(|| read_all(black_box(&cl))));
    assert!(read_moves(&cl) > 99_000);
    group.bench_function("next_move_100k_lines", |b| {
        b.iter(|| read_moves(black_box(&cl)))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
