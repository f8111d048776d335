//! Cost of one inverse (all branches) and one forward kinematics call on the
//! built-in mts1600.

use criterion::{Criterion, criterion_group, criterion_main};
use kinpost_machine::{Kinematics, Pose, builtin};
use nalgebra::Vector3;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let m = builtin::load("mts1600").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let q = [459.0, 12.0, 8.8, 361.4, -17.0, 0.0];
    let pose: Pose = kin.fk(&q);
    let mut sols = Vec::with_capacity(16);
    c.bench_function("ik_mts1600", |b| {
        b.iter(|| {
            kin.ik(black_box(&pose), Some(&q), &mut sols).unwrap();
            sols.len()
        })
    });
    c.bench_function("fk_mts1600", |b| b.iter(|| kin.fk(black_box(&q))));
    let _ = Vector3::<f64>::zeros();
}

criterion_group!(benches, bench);
criterion_main!(benches);
