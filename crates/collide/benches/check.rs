//! Collision checking of the built-in mts1600 with a 100,000-triangle blank
//! of the flat part (Qiao et al. 2022, §4.1.2) on its fixture, at the
//! poses of a grinding program: passes along x, 0.5 mm into the blank,
//! the head tilting by B. Poses per second on one thread and on two
//! (rayon over poses).

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinpost_collide::{Motion, World};
use kinpost_machine::{Machine, builtin};
use std::hint::black_box;

/// The world of the benchmark: mts1600 and a 100,000-triangle blank.
pub fn world() -> (Machine, World) {
    let m = builtin::load("mts1600").unwrap().unwrap();
    let mut world = World::new(&m).unwrap();
    world
        .add_part("blank", common::flat_part_blank(100_000, 0.3))
        .unwrap();
    (m, world)
}

/// `n` poses of a grinding program over the blank: passes 10 mm apart
/// from x = −416, the wheel across y = −60..60 with its contact point at
/// `height_mm` (the blank's top at 1.5 ± 0.3), B swinging ±15°.
pub fn program(m: &Machine, n: usize, height_mm: f64) -> Vec<Vec<f64>> {
    let (x, y, z, b) = ["X", "Y", "Z", "B"]
        .map(|a| m.axis_index(a).unwrap())
        .into();
    let per_pass = 1000;
    (0..n)
        .map(|k| {
            let pass = (k / per_pass) % 34;
            let s = (k % per_pass) as f64 / (per_pass - 1) as f64;
            let across = if pass % 2 == 0 { s } else { 1.0 - s };
            let mut q = m.home_joints();
            q[x] = 43.0 - (-416.0 + 10.0 * pass as f64);
            q[y] = 79.2 - (-60.0 + 120.0 * across);
            q[z] = 350.0 + height_mm;
            q[b] = 15.0 * (std::f64::consts::TAU * s).sin();
            q
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let (m, world) = world();
    // Grinding 0.5 mm into the top (the wheel may touch the blank in a
    // feed); rapids 3 mm above it (the wheel's distance to the blank
    // measured at every pose: a near miss where the wave rises).
    for (name, height, motion) in [
        ("grind_feed", 1.0, Motion::Feed),
        ("rapid_3mm_above", 4.5, Motion::Rapid),
    ] {
        let poses = program(&m, 20_000, height);
        let mut group = c.benchmark_group(format!("mts1600_100k_part_{name}"));
        group.throughput(Throughput::Elements(poses.len() as u64));
        group.sample_size(20);
        group.bench_function("check_pose_loop", |bench| {
            bench.iter(|| {
                let mut contacts = 0;
                for q in &poses {
                    contacts += world.check_pose(black_box(q), motion).len();
                }
                contacts
            })
        });
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            group.bench_function(format!("check_poses_{threads}_threads"), |bench| {
                bench.iter(|| pool.install(|| world.check_poses(black_box(&poses), motion)))
            });
        }
        group.finish();
        let steps: Vec<(&Vec<f64>, &Vec<f64>)> = poses.iter().zip(&poses[1..]).take(2000).collect();
        let mut group = c.benchmark_group(format!("mts1600_100k_part_{name}_moves"));
        group.throughput(Throughput::Elements(steps.len() as u64));
        group.sample_size(10);
        group.bench_function("check_move", |bench| {
            bench.iter(|| {
                steps
                    .iter()
                    .map(|(a, b)| world.check_move(black_box(a), b, motion).len())
                    .sum::<usize>()
            })
        });
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
