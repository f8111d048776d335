//! `kinpost surface fit|eval|plot` and `kinpost path`: measured points to a
//! B-spline surface, and a belt-grinding path on it as an NX-style CL file
//! (Li (B-spline grinding), §2 and §5).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use kinpost_surface::grid::{BladeSide, Grid, read_blade_table, read_grid};
use kinpost_surface::json::{from_json, to_json};
use kinpost_surface::svg::{Curvature, plot_surface};
use kinpost_surface::{Ends, FitOptions, Method, Parameterisation, Surface};
use kinpost_toolpath::cl::{ClOptions, write_cl};
use kinpost_toolpath::plot::plot_path;
use kinpost_toolpath::{Direction, PathError, PathOptions, Report, Side, Spacing, Wheel, plan};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::sinks::{deliver, open_outputs};
use crate::{report, usage};

#[derive(clap::Subcommand)]
pub enum SurfaceCommand {
    /// Fit a cubic B-spline surface to a grid of points and save it as JSON;
    /// prints the residual at the data points.
    Fit(FitArgs),
    /// Evaluate a surface: CSV `u,v,x,y,z,nx,ny,nz,gaussian,mean`.
    Eval(EvalArgs),
    /// Draw a surface as SVG (shaded, optionally coloured by curvature),
    /// with its data points.
    Plot(PlotArgs),
    /// Move a surface rigidly into the part frame (the placement `kinpost
    /// path` gives its CL with the same --rotate and --translate), e.g. to
    /// compare a simulated part with it (`kinpost sim --design`).
    Place(PlaceArgs),
}

#[derive(clap::Args)]
pub struct FitArgs {
    /// Points: CSV `row,col,x,y,z`, a whitespace table (`x y z` rows
    /// separated by blank lines, or `row col x y z`), or with --blade-side a
    /// NASA blade table (Rotor 37: Z, R in cm, θ1, θ2 per stream surface;
    /// Rotor 67: blocks of axial distance, r·θ, thickness, radius in feet).
    points: PathBuf,
    /// Output surface file (JSON), or - for standard output.
    #[arg(short = 'o', long = "output-file", value_name = "FILE")]
    output_file: PathBuf,
    /// End conditions of the interpolation.
    #[arg(long, value_enum, default_value = "natural")]
    ends: EndsArg,
    /// Data parameters: uniform (Li (B-spline grinding)), chord-length or centripetal.
    #[arg(long, value_enum, default_value = "uniform")]
    params: ParamsArg,
    /// Least-squares approximation with an NU×NV control net instead of
    /// interpolation (for dense, noisy scans).
    #[arg(long, value_name = "NU,NV")]
    approx: Option<String>,
    /// Read POINTS as a NASA blade table and take blade side 1 (THETA 1) or
    /// 2 (THETA 2): rows are the stream surfaces (hub to tip), columns the
    /// points from leading to trailing edge; x = 10·R·cos θ, y = 10·R·sin θ,
    /// z = 10·Z (mm; z along the rotor axis).
    #[arg(long, value_name = "1|2")]
    blade_side: Option<u8>,
    /// Keep every I-th grid row and J-th column (and the last ones): a
    /// reduced grid over the same area.
    #[arg(long, value_name = "I,J")]
    every: Option<String>,
    /// Also write the grid that was fitted as CSV `row,col,x,y,z` (- for
    /// standard output).
    #[arg(long, value_name = "FILE")]
    write_grid: Option<PathBuf>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum EndsArg {
    Natural,
    NotAKnot,
    ClampedTangent,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum ParamsArg {
    Uniform,
    ChordLength,
    Centripetal,
}

#[derive(clap::Args)]
pub struct EvalArgs {
    /// Surface file (JSON, from `kinpost surface fit`).
    surface: PathBuf,
    /// A parameter pair to evaluate (repeatable).
    #[arg(long, value_name = "U,V", allow_hyphen_values = true)]
    uv: Vec<String>,
    /// An NU×NV grid of parameters over the whole domain, ends included.
    #[arg(long, value_name = "NU,NV", conflicts_with = "uv")]
    grid: Option<String>,
    /// Output CSV file, or - for standard output (the default).
    #[arg(short = 'o', long = "output-file", value_name = "FILE")]
    output_file: Option<PathBuf>,
}

#[derive(clap::Args)]
pub struct PlaceArgs {
    /// Surface file (JSON).
    surface: PathBuf,
    /// Rotate about a part axis through the origin, `x:DEG`, `y:DEG` or
    /// `z:DEG`; repeatable, applied in order, before --translate.
    #[arg(long, value_name = "AXIS:DEG", allow_hyphen_values = true)]
    rotate: Vec<String>,
    /// Translate by X,Y,Z mm (after the rotations).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    translate: Option<String>,
    /// Output surface file (JSON), or - for standard output.
    #[arg(short = 'o', long = "output-file", value_name = "FILE")]
    output_file: PathBuf,
}

#[derive(clap::Args)]
pub struct PlotArgs {
    /// Surface file (JSON).
    surface: PathBuf,
    /// Output SVG file, or - for standard output.
    #[arg(long, value_name = "FILE")]
    svg: PathBuf,
    /// Colour the surface by curvature.
    #[arg(long, value_enum)]
    curvature: Option<CurvatureArg>,
    /// Title of the picture (default: the file name).
    #[arg(long)]
    title: Option<String>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum CurvatureArg {
    Gaussian,
    Mean,
}

#[derive(clap::Args)]
pub struct PathArgs {
    /// Surface file (JSON, from `kinpost surface fit`).
    surface: PathBuf,
    /// The contact wheel: `wheel:radius=R,width=W` (mm).
    #[arg(long)]
    tool: String,
    /// Passes run along u (stepping across in v) or along v.
    #[arg(long, value_enum, default_value = "u")]
    direction: DirectionArg,
    /// Largest distance between neighbouring passes, mm (at most the wheel
    /// width). Default: the wheel width times (1 − overlap).
    #[arg(long, value_name = "MM", conflicts_with = "scallop")]
    stepover: Option<f64>,
    /// Largest scallop height between passes, mm: the step-over is the
    /// largest that keeps it (and at most the wheel width × (1 − overlap)).
    #[arg(long, value_name = "MM")]
    scallop: Option<f64>,
    /// Fraction of the wheel width neighbouring passes share.
    #[arg(long, default_value_t = 0.5)]
    overlap: f64,
    /// Largest deviation of a CL segment from the surface, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.01)]
    chordtol: f64,
    /// Largest turn of the tool axis between CL points, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 2.0)]
    max_angle: f64,
    /// Feed rate, mm/min.
    #[arg(long, default_value_t = 1000.0)]
    feed: f64,
    /// Grinding pressure written as `PRESSURE/H1,value`: `VALUE` or
    /// `WORD=VALUE` (e.g. `H1=3000`).
    #[arg(long, value_name = "[WORD=]VALUE")]
    pressure: Option<String>,
    /// Wheel on the side of r_u × r_v (+) or the other (-).
    #[arg(long, default_value = "+", allow_hyphen_values = true)]
    side: String,
    /// Lead-in / lead-out distance along the normal, mm.
    #[arg(long, value_name = "MM", default_value_t = 5.0)]
    lead: f64,
    /// Part of the surface to grind: U0,U1,V0,V1 as fractions of the
    /// parameter domain.
    #[arg(long, value_name = "U0,U1,V0,V1")]
    region: Option<String>,
    /// Place the surface in the part frame: rotate about a part axis
    /// through the origin, `x:DEG`, `y:DEG` or `z:DEG`; repeatable, applied
    /// in order, before --translate.
    #[arg(long, value_name = "AXIS:DEG", allow_hyphen_values = true)]
    rotate: Vec<String>,
    /// Place the surface in the part frame: translate by X,Y,Z mm (after
    /// the rotations): a work offset for the machine's travel.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    translate: Option<String>,
    /// Tool reference in the CL: the feed direction of the passes (nine-value
    /// GOTOs, for 6-axis machines) or none (six values).
    #[arg(long, value_enum, default_value = "feed")]
    reference: ReferenceArg,
    /// TOOL PATH name (default: the surface file's name).
    #[arg(long)]
    name: Option<String>,
    /// Output CL file, or - for standard output (the default).
    #[arg(short = 'o', long = "output-file", value_name = "FILE")]
    output_file: Option<PathBuf>,
    /// Also draw the passes on the surface as SVG (- for standard output,
    /// with the CL file in a file).
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Write the path report (passes, step-over, scallop per gap, …) as JSON
    /// (- for standard output, with the CL file in a file).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum DirectionArg {
    U,
    V,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum ReferenceArg {
    Feed,
    None,
}

fn numbers(text: &str, count: usize, what: &str) -> Result<Vec<f64>> {
    let values: Option<Vec<f64>> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect();
    values.filter(|v| v.len() == count).ok_or_else(|| {
        usage(format!(
            "{what} `{text}`: expected {count} numbers separated by commas"
        ))
    })
}

fn counts(text: &str, what: &str) -> Result<(usize, usize)> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [a, b] => a.parse().ok().zip(b.parse().ok()),
        _ => None,
    }
    .ok_or_else(|| {
        usage(format!(
            "{what} `{text}`: expected two whole numbers, e.g. 20,30"
        ))
    })
}

/// A file read whole as UTF-8 text: bytes that are not UTF-8 are an error
/// at the line and column of the first.
fn read_text(path: &Path, what: &str) -> Result<String> {
    let bytes =
        std::fs::read(path).with_context(|| format!("cannot read {what} {}", path.display()))?;
    kinpost_post::diag::decode_utf8(bytes, &path.to_string_lossy()).map_err(report)
}

/// Loads a surface file, with located diagnostics.
pub fn load_surface(path: &Path) -> Result<Surface> {
    let text = read_text(path, "surface file")?;
    from_json(&text, &path.to_string_lossy()).map_err(report)
}

pub fn surface(command: SurfaceCommand) -> Result<()> {
    match command {
        SurfaceCommand::Fit(a) => fit(a),
        SurfaceCommand::Eval(a) => eval(a),
        SurfaceCommand::Plot(a) => plot(a),
        SurfaceCommand::Place(a) => place(a),
    }
}

fn place(args: PlaceArgs) -> Result<()> {
    let mut sinks = open_outputs(
        &[("surface file", args.surface.as_path())],
        &[("-o", args.output_file.as_path())],
    )?;
    let placement = placement(&args.rotate, args.translate.as_deref())?;
    let surface = load_surface(&args.surface)?.transformed(&placement);
    sinks[0]
        .write_all(to_json(&surface).as_bytes())
        .with_context(|| format!("cannot write {}", args.output_file.display()))?;
    deliver(sinks)
}

fn fit(args: FitArgs) -> Result<()> {
    let mut outputs = vec![("-o", args.output_file.as_path())];
    if let Some(path) = &args.write_grid {
        outputs.push(("--write-grid", path.as_path()));
    }
    let mut sinks = open_outputs(&[("points file", args.points.as_path())], &outputs)?;
    let text = read_text(&args.points, "points file")?;
    let name = args.points.to_string_lossy();
    let grid = match args.blade_side {
        None => read_grid(&text, &name).map_err(report)?,
        Some(1) => read_blade_table(&text, &name, BladeSide::Theta1).map_err(report)?,
        Some(2) => read_blade_table(&text, &name, BladeSide::Theta2).map_err(report)?,
        Some(n) => {
            return Err(usage(format!(
                "--blade-side {n}: a blade table has sides 1 and 2"
            )));
        }
    };
    let grid = match &args.every {
        None => grid,
        Some(t) => {
            let (i, j) = counts(t, "--every")?;
            if i == 0 || j == 0 {
                return Err(usage(format!("--every {t}: steps start at 1")));
            }
            grid.reduced(i, j)
        }
    };
    let method = match &args.approx {
        None => Method::Interpolation(match args.ends {
            EndsArg::Natural => Ends::Natural,
            EndsArg::NotAKnot => Ends::NotAKnot,
            EndsArg::ClampedTangent => Ends::ClampedTangent,
        }),
        Some(t) => {
            let (rows, cols) = counts(t, "--approx")?;
            Method::Approximation { rows, cols }
        }
    };
    let options = FitOptions {
        method,
        parameterisation: match args.params {
            ParamsArg::Uniform => Parameterisation::Uniform,
            ParamsArg::ChordLength => Parameterisation::ChordLength,
            ParamsArg::Centripetal => Parameterisation::Centripetal,
        },
    };
    let surface = Surface::fit(&grid, &options)
        .map_err(|e| anyhow!("{name}: {} × {} grid: {e}", grid.rows, grid.cols))?;
    sinks[0]
        .write_all(to_json(&surface).as_bytes())
        .with_context(|| format!("cannot write {}", args.output_file.display()))?;
    if let Some(path) = &args.write_grid {
        sinks[1]
            .write_all(grid_csv(&grid).as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    deliver(sinks)?;
    let (rows, cols) = surface.net_size();
    let kind = match method {
        Method::Interpolation(e) => format!("interpolation, {} ends", e.name()),
        Method::Approximation { .. } => "least-squares approximation".to_string(),
    };
    let r = surface.residual().expect("a fitted surface keeps its data");
    note!(
        "{}: {} × {} points → {rows} × {cols} control points ({kind}, {} parameters); residual at the data points: max {:.3e} mm (row {}, col {}), rms {:.3e} mm",
        args.output_file.display(),
        grid.rows,
        grid.cols,
        options.parameterisation.name(),
        r.max,
        r.at.0,
        r.at.1,
        r.rms
    );
    Ok(())
}

fn grid_csv(grid: &Grid) -> String {
    let mut o = String::from("row,col,x,y,z\n");
    for i in 0..grid.rows {
        for j in 0..grid.cols {
            let p = grid.at(i, j);
            o.push_str(&format!("{i},{j},{},{},{}\n", p[0], p[1], p[2]));
        }
    }
    o
}

fn eval(args: EvalArgs) -> Result<()> {
    let mut sinks = open_outputs(
        &[("surface file", args.surface.as_path())],
        &[("-o", args.output_file.as_deref().unwrap_or(Path::new("-")))],
    )?;
    let surface = load_surface(&args.surface)?;
    let (u0, u1) = surface.u_range();
    let (v0, v1) = surface.v_range();
    let mut uv = Vec::new();
    if let Some(g) = &args.grid {
        let (nu, nv) = counts(g, "--grid")?;
        if nu < 2 || nv < 2 || nu * nv > 10_000_000 {
            return Err(usage(format!(
                "--grid {g}: between 2 and a few thousand values per direction"
            )));
        }
        for i in 0..nu {
            for j in 0..nv {
                uv.push((
                    u0 + (u1 - u0) * i as f64 / (nu - 1) as f64,
                    v0 + (v1 - v0) * j as f64 / (nv - 1) as f64,
                ));
            }
        }
    }
    for t in &args.uv {
        let v = numbers(t, 2, "--uv")?;
        let eps = 1e-12;
        if v[0] < u0 - eps || v[0] > u1 + eps || v[1] < v0 - eps || v[1] > v1 + eps {
            bail!("--uv {t}: outside the surface's domain u {u0}..{u1}, v {v0}..{v1}");
        }
        uv.push((v[0], v[1]));
    }
    if uv.is_empty() {
        return Err(usage("nothing to evaluate: give --uv U,V or --grid NU,NV"));
    }
    let mut out = String::from("u,v,x,y,z,nx,ny,nz,gaussian,mean\n");
    let mut degenerate = 0;
    for (u, v) in uv {
        let p = surface.point(u, v);
        match surface.geometry(u, v) {
            Ok(g) => out.push_str(&format!(
                "{u},{v},{},{},{},{},{},{},{:e},{:e}\n",
                p.x, p.y, p.z, g.normal.x, g.normal.y, g.normal.z, g.gaussian, g.mean
            )),
            Err(_) => {
                degenerate += 1;
                out.push_str(&format!(
                    "{u},{v},{},{},{},nan,nan,nan,nan,nan\n",
                    p.x, p.y, p.z
                ));
            }
        }
    }
    if degenerate > 0 {
        note!(
            "warning: the surface is degenerate (no normal) at {degenerate} of the points: written as nan"
        );
    }
    sinks[0]
        .write_all(out.as_bytes())
        .context("cannot write the evaluation")?;
    deliver(sinks)
}

fn plot(args: PlotArgs) -> Result<()> {
    let mut sinks = open_outputs(
        &[("surface file", args.surface.as_path())],
        &[("--svg", args.svg.as_path())],
    )?;
    let surface = load_surface(&args.surface)?;
    let title = args.title.unwrap_or_else(|| {
        args.surface
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    });
    let svg = plot_surface(
        &surface,
        args.curvature.map(|c| match c {
            CurvatureArg::Gaussian => Curvature::Gaussian,
            CurvatureArg::Mean => Curvature::Mean,
        }),
        &title,
    );
    sinks[0]
        .write_all(svg.as_bytes())
        .with_context(|| format!("cannot write {}", args.svg.display()))?;
    deliver(sinks)
}

/// `wheel:radius=R,width=W`.
fn parse_wheel(text: &str) -> Result<Wheel> {
    let malformed = || {
        usage(format!(
            "--tool `{text}`: expected wheel:radius=R,width=W (mm)"
        ))
    };
    let rest = text.strip_prefix("wheel:").ok_or_else(malformed)?;
    let (mut radius, mut width) = (None, None);
    for part in rest.split(',') {
        let (k, v) = part.split_once('=').ok_or_else(malformed)?;
        let v: f64 = v
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite() && *v > 0.0)
            .ok_or_else(|| {
                usage(format!(
                    "--tool `{text}`: `{}` must be a positive number of mm",
                    part.trim()
                ))
            })?;
        match k.trim() {
            "radius" | "r" => radius = Some(v),
            "width" | "w" => width = Some(v),
            other => {
                return Err(usage(format!(
                    "--tool `{text}`: unknown wheel setting `{other}` (radius, width)"
                )));
            }
        }
    }
    Ok(Wheel {
        radius: radius.ok_or_else(malformed)?,
        width: width.ok_or_else(malformed)?,
    })
}

/// The placement of the surface in the part frame.
fn placement(rotate: &[String], translate: Option<&str>) -> Result<Isometry3<f64>> {
    let mut rotation = UnitQuaternion::identity();
    for r in rotate {
        let (axis, deg) = r
            .split_once(':')
            .ok_or_else(|| usage(format!("--rotate `{r}`: expected AXIS:DEG, e.g. x:90")))?;
        let axis = match axis.trim().to_ascii_lowercase().as_str() {
            "x" => Vector3::x_axis(),
            "y" => Vector3::y_axis(),
            "z" => Vector3::z_axis(),
            _ => return Err(usage(format!("--rotate `{r}`: the axis is x, y or z"))),
        };
        let deg: f64 = deg
            .trim()
            .parse()
            .ok()
            .filter(|d: &f64| d.is_finite())
            .ok_or_else(|| {
                usage(format!(
                    "--rotate `{r}`: `{deg}` is not a number of degrees"
                ))
            })?;
        rotation = UnitQuaternion::from_axis_angle(&axis, deg.to_radians()) * rotation;
    }
    let t = match translate {
        None => Vector3::zeros(),
        Some(t) => Vector3::from_vec(numbers(t, 3, "--translate")?),
    };
    Ok(Isometry3::from_parts(Translation3::from(t), rotation))
}

pub fn path(args: PathArgs) -> Result<()> {
    let mut outputs = vec![(
        "the CL file (-o)",
        args.output_file.as_deref().unwrap_or(Path::new("-")),
    )];
    for (name, path) in [("--svg", &args.svg), ("--json", &args.json)] {
        if let Some(path) = path {
            outputs.push((name, path.as_path()));
        }
    }
    let mut sinks = open_outputs(&[("surface file", args.surface.as_path())], &outputs)?;
    let surface = load_surface(&args.surface)?;
    let wheel = parse_wheel(&args.tool)?;
    let spacing = match (args.stepover, args.scallop) {
        (Some(s), _) => Spacing::Stepover(s),
        (None, Some(h)) => Spacing::Scallop(h),
        (None, None) => Spacing::Overlap(args.overlap),
    };
    let side = parse_side(&args.side)?;
    let region = parse_region(args.region.as_deref())?;
    let pressure = parse_pressure(args.pressure.as_deref())?;
    if !(args.feed.is_finite() && args.feed > 0.0) {
        return Err(usage("--feed must be a positive number of mm/min"));
    }
    let options = PathOptions {
        wheel,
        direction: match args.direction {
            DirectionArg::U => Direction::U,
            DirectionArg::V => Direction::V,
        },
        side,
        spacing,
        overlap: args.overlap,
        chord_tolerance: args.chordtol,
        max_angle_deg: args.max_angle,
        lead: args.lead,
        region,
        placement: placement(&args.rotate, args.translate.as_deref())?,
    };
    let toolpath = plan(&surface, &options).map_err(|e| {
        let message = format!("{}: {e}", args.surface.display());
        // Options the path cannot be planned with are usage errors.
        match e {
            PathError::Options(_) => usage(message),
            _ => anyhow!(message),
        }
    })?;
    let r = &toolpath.report;
    let stem = args.surface.file_stem().map_or_else(
        || "GRIND".to_string(),
        |s| s.to_string_lossy().to_uppercase(),
    );
    let limit = scallop_limit_note(spacing);
    let cl = ClOptions {
        name: args.name.clone().unwrap_or(stem),
        feed: args.feed,
        pressure,
        reference: matches!(args.reference, ReferenceArg::Feed),
        comments: path_comments(&args, &options, r, &limit),
    };
    // The sinks in the order opened: the CL file, then the plot and the
    // report if asked for.
    let mut next = sinks.iter_mut();
    let mut sink = || next.next().expect("one sink per output");
    write_cl(&toolpath, &options, &cl, sink())?;
    if let Some(svg) = &args.svg {
        let title = format!("{}: grinding path", args.surface.display());
        sink()
            .write_all(plot_path(&surface, &toolpath, &options, &title).as_bytes())
            .with_context(|| format!("cannot write {}", svg.display()))?;
    }
    if let Some(json) = &args.json {
        let text = serde_json::to_string_pretty(&path_report_json(r, &options))
            .expect("plain data")
            + "\n";
        sink()
            .write_all(text.as_bytes())
            .with_context(|| format!("cannot write {}", json.display()))?;
    }
    deliver(sinks)?;
    note_path_summary(r, &options, &limit);
    Ok(())
}

/// `--side`: which side of the surface the wheel is on (`+` along the
/// normal, `-` against it).
fn parse_side(side: &str) -> Result<Side> {
    match side.trim() {
        "+" | "plus" => Ok(Side::Plus),
        "-" | "minus" => Ok(Side::Minus),
        s => Err(usage(format!("--side `{s}`: + or -"))),
    }
}

/// `--region U0,U1,V0,V1`: the parameter window to grind (the whole
/// surface without it).
fn parse_region(region: Option<&str>) -> Result<[f64; 4]> {
    match region {
        None => Ok([0.0, 1.0, 0.0, 1.0]),
        Some(r) => {
            let v = numbers(r, 4, "--region")?;
            Ok([v[0], v[1], v[2], v[3]])
        }
    }
}

/// `--pressure VALUE` or `WORD=VALUE`: the process pressure written on the
/// CL file (word `H1` unless named), a number ≥ 0 and a word of letters and
/// digits.
fn parse_pressure(pressure: Option<&str>) -> Result<Option<(String, f64)>> {
    let Some(p) = pressure else {
        return Ok(None);
    };
    let (word, value) = p.split_once('=').unwrap_or(("H1", p));
    let value: f64 = value
        .trim()
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| {
            usage(format!(
                "--pressure `{p}`: expected VALUE or WORD=VALUE, a number ≥ 0"
            ))
        })?;
    let word = word.trim();
    if word.is_empty() || !word.chars().all(|c| c.is_ascii_alphanumeric()) {
        return Err(usage(format!(
            "--pressure `{p}`: the word is letters and digits, e.g. H1"
        )));
    }
    Ok(Some((word.to_string(), value)))
}

/// ` (limit H)` after the largest scallop when the passes are spaced by a
/// scallop height, else nothing.
fn scallop_limit_note(spacing: Spacing) -> String {
    match spacing {
        Spacing::Scallop(h) => format!(" (limit {h})"),
        _ => String::new(),
    }
}

/// The comments at the top of the CL file: the surface, the wheel and its
/// orientation, and what the planned path achieves.
fn path_comments(args: &PathArgs, options: &PathOptions, r: &Report, limit: &str) -> Vec<String> {
    vec![
        format!("kinpost path on {}", args.surface.display()),
        format!(
            "wheel radius {} mm, width {} mm; tool axis = surface normal ({} side); reference = {}",
            options.wheel.radius,
            options.wheel.width,
            if options.side == Side::Plus { "+" } else { "-" },
            match args.reference {
                ReferenceArg::Feed => "feed direction of the passes",
                ReferenceArg::None => "none",
            }
        ),
        format!(
            "{} passes, step-over {:.4}-{:.4} mm, scallop max {:.5} mm{limit}, chord error max {:.5} mm",
            r.passes, r.stepover_min, r.stepover_max, r.scallop_max, r.chord_error_max
        ),
    ]
}

/// The `--json` report of a planned path: its figures, the limits asked
/// for, and every gap between passes.
fn path_report_json(r: &Report, options: &PathOptions) -> serde_json::Value {
    serde_json::json!({
        "passes": r.passes,
        "cl_points": r.points,
        "feed_length_mm": r.length_mm,
        "stepover_min_mm": r.stepover_min,
        "stepover_max_mm": r.stepover_max,
        "scallop_max_mm": r.scallop_max,
        "scallop_limit_mm": match options.spacing { Spacing::Scallop(h) => Some(h), _ => None },
        "wheel_edge_interference_max_mm": r.interference_max,
        "chord_error_max_mm": r.chord_error_max,
        "chord_tolerance_mm": options.chord_tolerance,
        "concave_feed_radius_min_mm": r.concave_feed_radius_min,
        "gaps": r.gaps.iter().map(|g| serde_json::json!({
            "stepover_mm": g.stepover, "scallop_mm": g.scallop, "interference_mm": g.interference
        })).collect::<Vec<_>>(),
    })
}

/// The summary on standard error, and a warning where the wheel cuts into
/// the surface: along the feed (a concave radius under the wheel's) or
/// with its edge between passes (beyond the chord tolerance).
fn note_path_summary(r: &Report, options: &PathOptions, limit: &str) {
    note!(
        "{} passes along {}, {} CL points, {:.1} mm of feed moves; step-over {:.4}–{:.4} mm; scallop max {:.5} mm{limit}; wheel-edge interference max {:.5} mm; chord error max {:.5} mm (tolerance {})",
        r.passes,
        if options.direction == Direction::U {
            "u"
        } else {
            "v"
        },
        r.points,
        r.length_mm,
        r.stepover_min,
        r.stepover_max,
        r.scallop_max,
        r.interference_max,
        r.chord_error_max,
        options.chord_tolerance
    );
    if let Some(rc) = r.concave_feed_radius_min
        && rc < options.wheel.radius
    {
        note!(
            "warning: the surface is concave along the feed with radius {rc:.3} mm, less than the wheel radius {} mm: the wheel cuts in there",
            options.wheel.radius
        );
    }
    if r.interference_max > options.chord_tolerance {
        note!(
            "warning: the wheel's edge reaches {:.4} mm under the surface between passes (a concave section across the pass): a narrower wheel or passes the other way reduce it",
            r.interference_max
        );
    }
}
