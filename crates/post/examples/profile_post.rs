//! Posts a generated CL file of N points (default 1,000,000) on mts1600 to
//! sinumerik into a sink, for profilers (`perf record`, callgrind); the
//! criterion benchmark `benches/post.rs` is the measurement of record.
//! A second argument `point-by-point` turns whole-path planning and
//! linearization off. A first argument that is not a number is a CL file to
//! post instead (so that a profiler sees the post alone).

#[path = "../benches/cl_gen.rs"]
mod cl_gen;

fn main() {
    let first = std::env::args().nth(1);
    let file = first.as_deref().filter(|a| a.parse::<usize>().is_err());
    let points = first
        .as_deref()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let options = match std::env::args().nth(2).as_deref() {
        Some("point-by-point") => kinpost_post::PostOptions {
            planner: kinpost_post::PlannerMode::Nearest,
            lintol_mm: Some(0.0),
            ..Default::default()
        },
        _ => kinpost_post::PostOptions::default(),
    };
    let cl = match file {
        Some(path) => std::fs::read_to_string(path).expect("a readable CL file"),
        None => cl_gen::generate_cl(points),
    };
    let machine = kinpost_post::machine::builtin::load("mts1600")
        .unwrap()
        .unwrap();
    let dialect = kinpost_post::nc::Dialect::builtin("sinumerik").unwrap();
    let summary =
        kinpost_post::post(cl.as_bytes(), &machine, &dialect, std::io::sink(), &options).unwrap();
    eprintln!(
        "{} points, {} blocks in {:.3} s: {:.2} M points/s",
        summary.cl_points,
        summary.blocks,
        summary.seconds,
        summary.cl_points as f64 / summary.seconds / 1e6
    );
}
