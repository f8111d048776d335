//! Writing 1M sinumerik motion blocks to `io::sink()` the way the post does
//! (values rounded for the check, then the block): the hot path of the post.
//! Criterion reports the time for 1M blocks: µs per iteration = ns per block.

use std::hint::black_box;
use std::io;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinpost_nc::{Dialect, NcWriter};

mod write_gen;
use write_gen::{axes, write_block};

const BLOCKS: usize = 1_000_000;

fn values() -> Vec<[f64; 6]> {
    // A smooth path with varied magnitudes and signs (as a real post has).
    (0..4096)
        .map(|i| {
            let t = i as f64 * 0.01;
            [
                459.0 + 30.0 * t.sin(),
                -180.0 + 7.3 * t,
                8.8 + 50.0 * (0.7 * t).cos(),
                361.368 - 12.5 * t.sin(),
                -44.0 + 0.021 * i as f64,
                0.0,
            ]
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let dialect = Dialect::builtin("sinumerik").unwrap();
    let axes = axes();
    let path = values();
    let mut group = c.benchmark_group("nc");
    group.sample_size(10);
    group.throughput(Throughput::Elements(BLOCKS as u64));
    for name in ["sinumerik", "csv"] {
        let dialect = if name == "sinumerik" {
            dialect.clone()
        } else {
            Dialect::builtin(name).unwrap()
        };
        group.bench_function(format!("{name}_1M_blocks"), |b| {
            b.iter(|| {
                let mut w = NcWriter::new(&dialect, &axes, io::sink());
                for i in 0..BLOCKS {
                    write_block(&mut w, i + 1, &path[i & 4095], 250.0);
                }
                black_box(w.blocks_written())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
