//! Cost of `Trellis::push` (with `best_last`, as the post calls it) per
//! point on trunnion-ac, with 1 to 4 candidates per point.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinpost_machine::builtin;
use kinpost_plan::{Costs, Trellis};
use std::hint::black_box;

mod trellis_gen;

fn bench(c: &mut Criterion) {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let costs = Costs::new(&m, 0.5, m.axis_index("C"));
    let points = 10_000;
    let mut group = c.benchmark_group("trellis");
    group.throughput(Throughput::Elements(points as u64));
    for per_point in 1..=4 {
        let layers = trellis_gen::layers(points, per_point);
        let mut out = Vec::with_capacity(points);
        group.bench_function(format!("push_{per_point}_candidates"), |b| {
            b.iter(|| {
                let mut t = Trellis::new(costs.clone(), 32_768);
                for (layer, link) in &layers {
                    black_box(t.best_last());
                    t.push(black_box(layer), *link);
                }
                out.clear();
                t.decide(&mut out);
                out.len()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
