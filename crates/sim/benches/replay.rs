//! Replay speed: motion blocks per second through `Replay::step` (the
//! travel checks and run time of every block; no CL, no collisions) on a
//! 5-axis program of 200 000 feed blocks for `trunnion-ac`, already read
//! by the interpreter; and the whole `simulate` (interpreter included) on
//! its text. One thread.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinpost_machine::builtin;
use kinpost_nc::interp::{Family, Options, read_all};
use kinpost_sim::{Replay, SimOptions, simulate};
use std::fmt::Write as _;
use std::hint::black_box;

const BLOCKS: usize = 200_000;

/// A program whose blocks move X Y Z A C a little each, inside the travel.
fn program() -> String {
    let mut s = String::from("G21 G90 G94\nG0 X0 Y0 Z100 A0 C0\nG1 F2000\n");
    for k in 0..BLOCKS {
        let t = k as f64 * 1e-3;
        let _ = writeln!(
            s,
            "X{:.4} Y{:.4} Z{:.4} A{:.4} C{:.4}",
            100.0 * t.sin(),
            80.0 * t.cos(),
            50.0 + 10.0 * (3.0 * t).sin(),
            30.0 + 20.0 * (2.0 * t).sin(),
            (t * 50.0) % 360.0
        );
    }
    s.push_str("M2\n");
    s
}

fn bench(c: &mut Criterion) {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let axes = kinpost_post::axis_specs(&m);
    let text = program();
    let options = SimOptions {
        collisions: false,
        ..SimOptions::default()
    };
    let interp = Options {
        start: Some(m.home_joints()),
        ..Options::default()
    };
    let (steps, report) = read_all(&text, Family::LinuxCnc, &axes, &interp, "bench.ngc").unwrap();
    let moves = report.moves;
    let mut g = c.benchmark_group("replay");
    g.throughput(Throughput::Elements(moves));
    g.bench_function("steps_travel_time", |b| {
        b.iter(|| {
            let mut r = Replay::new(&m, &options, None).unwrap();
            for s in &steps {
                r.step(black_box(s));
            }
            black_box(r.finish(&report).unwrap())
        })
    });
    g.bench_function("simulate_with_interpreter", |b| {
        b.iter(|| {
            black_box(
                simulate(
                    &text,
                    Family::LinuxCnc,
                    "bench.ngc",
                    &m,
                    &options,
                    None,
                    &mut |_| {},
                )
                .unwrap(),
            )
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
