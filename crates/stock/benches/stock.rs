//! Speed of material removal and of the design comparison.
//!
//! * `wheel_5axis`: the contact wheel (R 50 mm, 25 mm wide, Qiao et al.
//!   2022 §4.1) over a 250 × 80 × 40 mm stock at 0.05 mm: a zig-zag of 40
//!   passes along X, 1.5 mm apart, 0.05 mm deep, in moves of 0.1 mm (100,000
//!   moves), the tool axis on the flat's normal tilting ±0.2° across the
//!   feed (period 37 mm; the belt's edges dip 0.04 mm), so every move turns
//!   the wheel's axis: five-axis moves, sampled (3 new poses a move: 0.1 mm
//!   of travel and the turn move a point of the wheel by just over two ray
//!   spacings).
//! * `ball_3axis`: a 6 mm ball end mill, 0.5 mm deep, the same zig-zag in
//!   0.1 mm moves (pure translations, swept exactly).
//! * `compare`: a 250 × 80 × 40 stock at 0.0576 mm (10 million rays)
//!   against its box as the design.
//!
//! Each iteration cuts the next 500 moves of the program on the same
//! stock (a fresh stock when the program ends, made outside the timing),
//! as `kinpost sim` does: handed over together to `Stock::cut_moves`, each
//! move its own id; pools of 1 and 2 threads.

use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use kinpost_stock::{Design, Mesh, Move, Stock, Tool, ToolPose, compare};
use nalgebra::Point3;

mod programs;
use program::stock;
use programs as program;

const CHUNK: usize = 500;

fn run(c: &mut Criterion, name: &str, tool: Tool, poses: &[ToolPose], threads: usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let mut s = stock(0.05);
    let mut next = 0usize;
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    group.throughput(criterion::Throughput::Elements(CHUNK as u64));
    group.bench_function(format!("{threads}_threads_{CHUNK}_moves"), |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                if next + CHUNK >= poses.len() {
                    s = stock(0.05);
                    next = 0;
                }
                let moves: Vec<Move> = (next..next + CHUNK)
                    .map(|i| Move {
                        from: poses[i],
                        to: poses[i + 1],
                        id: i as u32,
                    })
                    .collect();
                let start = Instant::now();
                pool.install(|| s.cut_moves(&tool, &moves).unwrap());
                total += start.elapsed();
                next += CHUNK;
            }
            total
        })
    });
    group.finish();
}

fn wheel(c: &mut Criterion) {
    let (tool, poses) = program::wheel_5axis();
    for threads in [1, 2] {
        run(c, "wheel_5axis", tool, &poses, threads);
    }
}

fn ball(c: &mut Criterion) {
    let (tool, poses) = program::ball_3axis();
    for threads in [1, 2] {
        run(c, "ball_3axis", tool, &poses, threads);
    }
}

fn comparison(c: &mut Criterion) {
    let h = 0.0576;
    let s = stock(h);
    eprintln!("compare: {} rays", s.ray_count());
    let design = Design::from_mesh(Mesh::cuboid(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(250.0, 80.0, 40.0),
    ))
    .unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut group = c.benchmark_group("compare");
    group.sample_size(10);
    group.bench_function("10M_rays_1_thread", |b| {
        b.iter(|| pool.install(|| compare(&s, &design, 0.01).unwrap()))
    });
    group.finish();
}

fn memory(_: &mut Criterion) {
    let s = Stock::from_box(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(400.0, 100.0, 7.5),
        0.05,
    )
    .unwrap();
    eprintln!(
        "memory: 400 x 100 x 7.5 mm blank at 0.05 mm: {} rays, {} intervals, {:.0} MiB",
        s.ray_count(),
        s.interval_count(),
        s.memory_bytes() as f64 / (1u64 << 20) as f64
    );
}

criterion_group!(benches, memory, comparison, wheel, ball);
criterion_main!(benches);
