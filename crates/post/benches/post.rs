//! Posting speed: a generated 1,000,000-point 5-axis CL file on `mts1600`
//! to `sinumerik`, closed-loop check included (issue target: ≥ 3 million CL
//! points per second on one core). Figures go to BENCHMARKS.md.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinpost_post::{PostOptions, post};

mod cl_gen;
use cl_gen::generate_cl;

fn bench(c: &mut Criterion) {
    let points = 1_000_000;
    let cl = generate_cl(points);
    let machine = kinpost_post::machine::builtin::load("mts1600")
        .unwrap()
        .unwrap();
    let dialect = kinpost_post::nc::Dialect::builtin("sinumerik").unwrap();
    let mut group = c.benchmark_group("post");
    group.sample_size(10);
    group.throughput(Throughput::Elements(points as u64));
    // Default: whole-path planning and linearization on. The point-by-point
    // run without linearization is the foundation's pipeline (the
    // planned run stays within 2× of it).
    let point_by_point = PostOptions {
        planner: kinpost_post::PlannerMode::Nearest,
        lintol_mm: Some(0.0),
        ..PostOptions::default()
    };
    for (name, options) in [
        ("mts1600_sinumerik_1M_points", PostOptions::default()),
        ("mts1600_sinumerik_1M_points_point_by_point", point_by_point),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                let summary =
                    post(cl.as_bytes(), &machine, &dialect, std::io::sink(), &options).unwrap();
                assert_eq!(summary.cl_points, points as u64);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
