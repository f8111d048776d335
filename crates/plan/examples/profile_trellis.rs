//! Pushes N synthetic points (default 100,000) of K candidates (default 4)
//! on trunnion-ac into a trellis, for callgrind:
//! `profile_trellis [N] [K]`.

#[path = "../benches/trellis_gen.rs"]
mod trellis_gen;

use kinpost_machine::builtin;
use kinpost_plan::{Costs, Trellis};
use std::hint::black_box;

fn main() {
    let mut args = std::env::args().skip(1);
    let points: usize = args.next().map_or(100_000, |a| a.parse().unwrap());
    let per_point: usize = args.next().map_or(4, |a| a.parse().unwrap());
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let costs = Costs::new(&m, 0.5, m.axis_index("C"));
    let layers = trellis_gen::layers(points, per_point.clamp(1, 4));
    let mut t = Trellis::new(costs, 32_768);
    let mut out = Vec::with_capacity(points);
    for (layer, link) in &layers {
        black_box(t.best_last());
        t.push(black_box(layer), *link);
        if t.is_full() {
            t.decide(&mut out);
        }
    }
    t.decide(&mut out);
    let flips = out.iter().filter(|c| !c.continuous).count();
    let sum: f64 = out.iter().map(|c| c.joints[3] + c.joints[4]).sum();
    println!(
        "{} points, {flips} not continuous, checksum {sum:.6}",
        out.len()
    );
}
