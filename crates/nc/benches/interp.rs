//! Reading plain motion blocks, the interpreter's hot path: programs of
//! 200 000 blocks in each family's everyday form, read with a sink that
//! only counts (the replay's own work is not measured here). Throughput in
//! blocks per second.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinpost_nc::AxisSpec;
use kinpost_nc::interp::{Event, Family, Options, Step, run};

const BLOCKS: usize = 200_000;

fn axes() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("A"),
        AxisSpec::endless("C"),
    ]
}

/// A smooth 5-axis path: every block changes every axis.
fn point(k: usize) -> [f64; 5] {
    let t = k as f64 * 1e-3;
    [
        100.0 * t.sin() + 12.345,
        80.0 * (0.7 * t).cos() - 3.2,
        44.1 + 10.0 * (0.3 * t).sin(),
        12.5 + 30.0 * (0.2 * t).sin(),
        (-93.25 + 50.0 * t).rem_euclid(360.0),
    ]
}

fn program(family: Family) -> String {
    let mut s = String::with_capacity(BLOCKS * 64);
    match family {
        Family::LinuxCnc | Family::Fanuc => s.push_str("G21 G90 G94 G1 F1200\n"),
        Family::Sinumerik => s.push_str("G90 G71 G1 F1200\n"),
        Family::Heidenhain => s.push_str("0 BEGIN PGM B MM\n"),
        Family::Csv => s.push_str("line,motion,X,Y,Z,A,C,feed\n"),
    }
    for k in 0..BLOCKS {
        let p = point(k);
        let line = match family {
            Family::LinuxCnc => format!(
                "X{:.4} Y{:.4} Z{:.4} A{:.4} C{:.4}\n",
                p[0], p[1], p[2], p[3], p[4]
            ),
            Family::Fanuc => format!(
                "N{} G01 X{:.3} Y{:.3} Z{:.3} A{:.3} C{:.3}\n",
                k % 99999 + 1,
                p[0],
                p[1],
                p[2],
                p[3],
                p[4]
            ),
            Family::Sinumerik => {
                format!(
                    "X={:.3} Y={:.3} Z{:.3} A{:.3} C=DC({:.3})\n",
                    p[0], p[1], p[2], p[3], p[4]
                )
            }
            Family::Heidenhain => format!(
                "{} L X{:+.3} Y{:+.3} Z{:+.3} A{:+.3} C{:+.3} R0 F1200\n",
                k + 1,
                p[0],
                p[1],
                p[2],
                p[3],
                p[4]
            ),
            Family::Csv => format!(
                "{},feed,{:.6},{:.6},{:.6},{:.6},{:.6},1200.000000\n",
                k + 1,
                p[0],
                p[1],
                p[2],
                p[3],
                p[4]
            ),
        };
        s.push_str(&line);
    }
    s
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("interp");
    group.throughput(Throughput::Elements(BLOCKS as u64));
    group.sample_size(20);
    let axes = axes();
    let options = Options::default();
    for (name, family) in [
        ("linuxcnc", Family::LinuxCnc),
        ("fanuc_numbered", Family::Fanuc),
        ("sinumerik", Family::Sinumerik),
        ("heidenhain", Family::Heidenhain),
        ("csv", Family::Csv),
    ] {
        let text = program(family);
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut moves = 0u64;
                let mut x = 0.0;
                let mut sink = |s: &Step| {
                    if let Event::Move(m) = &s.event {
                        moves += 1;
                        x += m.end[0];
                    }
                };
                run(
                    black_box(&text),
                    family,
                    &axes,
                    &options,
                    "bench",
                    &mut sink,
                )
                .unwrap();
                assert_eq!(moves, BLOCKS as u64);
                black_box(x)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
