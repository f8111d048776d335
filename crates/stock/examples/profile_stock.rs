//! Cuts the first moves of a benchmark program, for `perf stat`,
//! `perf record` and callgrind (instruction counts do not depend on the
//! host's load):
//!
//! ```sh
//! cargo run --release -p kinpost-stock --example profile_stock -- wheel 2000 1
//! ```
//!
//! Arguments: `wheel` or `ball`, the number of moves, the thread count,
//! optionally the first move (default 0) and `reference` for the
//! straightforward removal ([`kinpost_stock::Removal::Reference`]). The
//! moves go to `Stock::cut_moves` 256 at a time, as `kinpost sim` hands
//! them over (`BATCH=n` in the environment for n at a time, `BATCH=0` for
//! `Stock::cut_move` one by one). Prints the time of the cut alone and a
//! checksum of the stock (the same for any thread count and batch).

use std::time::Instant;

#[path = "../benches/programs/mod.rs"]
mod program;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map_or("wheel", String::as_str);
    let moves: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2000);
    let threads: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
    let first: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(0);
    let (tool, poses) = match kind {
        "ball" => program::ball_3axis(),
        _ => program::wheel_5axis(),
    };
    let mut stock = program::stock(0.05);
    if args.get(5).is_some_and(|a| a == "reference") {
        stock.set_removal(kinpost_stock::Removal::Reference);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let last = (first + moves).min(poses.len() - 1);
    let (start, cpu0) = (Instant::now(), cpu_seconds());
    let batch: usize = std::env::var("BATCH")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(256);
    pool.install(|| {
        if batch == 0 {
            for i in first..last {
                stock
                    .cut_move(&tool, &poses[i], &poses[i + 1], i as u32)
                    .unwrap();
            }
        } else {
            let moves: Vec<kinpost_stock::Move> = (first..last)
                .map(|i| kinpost_stock::Move {
                    from: poses[i],
                    to: poses[i + 1],
                    id: i as u32,
                })
                .collect();
            for chunk in moves.chunks(batch) {
                stock.cut_moves(&tool, chunk).unwrap();
            }
        }
    });
    let t = start.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu0;
    let mut sum = 0u64;
    for k in 0..3 {
        for ray in &stock.family(k).rays {
            for s in ray {
                sum = sum
                    .wrapping_mul(0x100000001b3)
                    .wrapping_add(s.lo.to_bits() ^ s.hi.to_bits().rotate_left(17))
                    .wrapping_add(u64::from(s.lo_move) << 32 | u64::from(s.hi_move));
            }
        }
    }
    println!(
        "{kind}: {} moves in {t:.3} s wall ({:.0} moves/s), {cpu:.2} s CPU ({:.0} moves per CPU second), {threads} threads; removed {:.6} mm3; checksum {sum:016x}",
        last - first,
        (last - first) as f64 / t,
        (last - first) as f64 / cpu,
        stock.removed_volume_mm3()
    );
}

/// User and system time of the process so far (Linux: /proc/self/stat, in
/// clock ticks of 10 ms); NaN elsewhere.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the command name (which may hold spaces) in parentheses.
    let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        f.get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    // utime and stime are fields 14 and 15 of the line, 12 and 13 here.
    (ticks(11) + ticks(12)) / 100.0
}
