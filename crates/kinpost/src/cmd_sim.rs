//! `kinpost sim`: the virtual machine (crate `kinpost-sim`) on the command
//! line: a program replayed on a machine, a summary on standard error, a
//! JSON report and a block table, exit code 3 when anything was violated.

use std::io::{self, BufReader, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use kinpost_nc::interp::{Event, Family, MotionKind, Options, Step};
use kinpost_sim::{ClPath, Cutting, SimOptions, SimReport, simulate_cutting};
use kinpost_stock::{Design, contour, write_ply, write_stl, write_svg};

use crate::sinks::{deliver, open_outputs};
use crate::{STDIN_NAME, dialect_of_machine, load_dialect, load_machine, report, usage};

/// Largest NC program read, bytes: a program is read whole (the
/// interpreter jumps back and forth in it); a gigabyte of NC code is tens
/// of millions of blocks.
const MAX_PROGRAM_BYTES: usize = 1 << 30;

/// The arguments of `kinpost sim`.
#[derive(clap::Args)]
pub struct SimArgs {
    /// NC program, or - for standard input.
    program: String,
    /// Built-in machine name or machine file.
    #[arg(long, short)]
    machine: String,
    /// The program's dialect (built-in name or dialect file); default: from
    /// the program's extension (.mpf/.spf Sinumerik, .nc/.tap/.iso Fanuc,
    /// .ngc LinuxCNC, .h Heidenhain, .csv kinpost's table), else the
    /// machine's.
    #[arg(long, short)]
    dialect: Option<String>,
    /// The CL file the program was posted from: the replayed tool point and
    /// axis are compared with it along the path.
    #[arg(long, value_name = "FILE")]
    cl: Option<PathBuf>,
    /// Text encoding of the --cl file: utf-8, or latin1 (ISO 8859-1).
    #[arg(long, value_enum, default_value = "utf-8", requires = "cl")]
    cl_encoding: crate::EncodingArg,
    /// A machine input or system variable the program reads, NAME=VALUE
    /// (`'$A_IN[5]=1'`, `_hal[pin]=1`, `M66[2]=1`, `#1000=1`); inputs not
    /// given read 0, and the run says so.
    #[arg(long = "input", value_name = "NAME=VALUE")]
    inputs: Vec<String>,
    /// Hold the wheel where it is at the reference pressure whatever the
    /// pressure word (H1) says, as the machine maker's post assumes.
    #[arg(long)]
    no_pressure_offset: bool,
    /// Do not check the machine file's solids for collisions.
    #[arg(long)]
    no_collisions: bool,
    /// Write the report as JSON to this file, or - for standard output.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Write every motion block read as a CSV row (NC line, motion, every
    /// axis value, feed, the pressure word) to this file, or - for standard
    /// output.
    #[arg(long, value_name = "FILE")]
    blocks: Option<PathBuf>,
    /// Remove material while replaying: the stock in the part frame,
    /// `box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX`, `design+ALLOWANCE` (the design
    /// grown by ALLOWANCE mm; needs --design; for a design surface
    /// `design+ALLOWANCE[,DEPTH]`, the shell from ALLOWANCE outside it to
    /// DEPTH inside, default 2 mm), or a closed STL file. Needs --tool. A
    /// rapid that removes material is an error (exit code 3).
    #[arg(long, value_name = "SPEC", requires = "tool")]
    stock: Option<String>,
    /// The tool that cuts the stock, mm and degrees: `flat:D[,FLUTE]`,
    /// `ball:D[,FLUTE]`, `bull:D,CORNER[,FLUTE]`,
    /// `drill:D[,POINT_ANGLE[,FLUTE]]`, `wheel:RADIUS,WIDTH[,EDGE]` (the
    /// belt's contact wheel; its poses need the machine's tool reference),
    /// `disc:RADIUS,THICKNESS`. A flute length not given is four diameters
    /// (at least 10 mm).
    #[arg(long, value_name = "SPEC", requires = "stock")]
    tool: Option<String>,
    /// Grind with the belt-grinding process model of this file (TOML:
    /// `[force]` the pressure word's force table, `[wheel]` Preston's
    /// coefficient and the wheel's stiffness; `kinpost calibrate` fits
    /// them): feed blocks of the contact wheel (--tool wheel:…) with the
    /// spindle on remove Preston's depth at the force the pressure word
    /// gives, the belt speed the spindle speed gives and the block's feed.
    #[arg(long, value_name = "FILE.toml", requires = "stock")]
    process: Option<PathBuf>,
    /// Ray spacing of the stock, mm (default: about 16 million rays for
    /// the stock's size).
    #[arg(long, value_name = "MM", requires = "stock")]
    resolution: Option<f64>,
    /// The design, in the part frame: a closed STL of the part, or one of
    /// its surfaces as a surface file (`.json`, from `kinpost surface fit`;
    /// `kinpost surface place` moves it where `kinpost path` placed its
    /// CL). The simulated part is compared with it along the rays, gouges
    /// (material removed below it: exit code 3) and residuals (material
    /// left above it) beyond --difftol, with the blocks that made them.
    #[arg(long, value_name = "FILE.stl|FILE.json", requires = "stock")]
    design: Option<PathBuf>,
    /// The outside of a design surface: `+` the side of its normal
    /// S_u × S_v (the default), `-` the other (as `kinpost path --side`).
    #[arg(long, value_enum, allow_hyphen_values = true, requires = "design")]
    design_side: Option<crate::sim_stock::DesignSide>,
    /// The part of a design surface that is compared (and that
    /// `design+ALLOWANCE` grows into the stock): U0,U1,V0,V1 as fractions
    /// of the parameter domain, as `kinpost path --region` takes the
    /// region it grinds (default: the whole surface).
    #[arg(long, value_name = "U0,U1,V0,V1", requires = "design")]
    design_region: Option<String>,
    /// Comparison tolerance, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.01, requires = "design")]
    difftol: f64,
    /// Write the simulated part as a binary STL (a watertight mesh of the
    /// stock as cut).
    #[arg(long, value_name = "FILE", requires = "stock")]
    stl_out: Option<PathBuf>,
    /// Write the simulated part as PLY coloured by its deviation from the
    /// design (blue residual, green within tolerance, red gouge).
    #[arg(long, value_name = "FILE", requires = "design")]
    ply_out: Option<PathBuf>,
    /// Write a map of the deviation from the design, seen along Z, as SVG.
    #[arg(long, value_name = "FILE", requires = "design")]
    svg_out: Option<PathBuf>,
    /// Print no summary on standard error.
    #[arg(long, short)]
    quiet: bool,
}

/// The run found overtravel or a collision: exit code 3 (the report was
/// written).
#[derive(Debug)]
pub struct Violated;

impl std::fmt::Display for Violated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the program violates the machine's travel or collides")
    }
}

impl std::error::Error for Violated {}

/// `kinpost sim`.
pub fn sim(args: &SimArgs) -> Result<()> {
    let mut options = SimOptions {
        interp: Options::default(),
        pressure_offset: !args.no_pressure_offset,
        collisions: !args.no_collisions,
    };
    for i in &args.inputs {
        options
            .interp
            .parse_input(i)
            .map_err(|e| usage(format!("--input {e}")))?;
    }
    let mut sinks = open_sim_outputs(args)?;
    let machine = load_machine(&args.machine)?;
    let mut removal = RemovalSetup::load(args)?;
    let family = family(args, machine.post.dialect.as_deref())?;
    let (text, file) = read_program(&args.program)?;
    let cl = match &args.cl {
        None => None,
        Some(p) => {
            let f = std::fs::File::open(p)
                .with_context(|| format!("cannot open CL file {}", p.display()))?;
            let name = p.to_string_lossy();
            let text = args.cl_encoding.decode(f);
            Some(ClPath::read(BufReader::with_capacity(1 << 16, text), &name).map_err(sim_error)?)
        }
    };
    let names: Vec<String> = kinpost_post::axis_specs(&machine)
        .into_iter()
        .map(|a| a.name)
        .collect();
    let blocks_at = usize::from(args.json.is_some());
    let result = {
        let mut table = match (&args.blocks, sinks.get_mut(blocks_at)) {
            (Some(_), Some(sink)) => Some(BlockTable::new(&names, machine.axes.len(), sink)?),
            _ => None,
        };
        let bar = progress_bar(args.quiet, &text);
        let mut count = 0u32;
        let result = simulate_cutting(
            &text,
            family,
            &file,
            &machine,
            &options,
            cl,
            // (The stock moves into the replay and comes back cut: a
            // stock can be gigabytes.)
            removal.as_mut().and_then(|r| r.cutting.take()),
            &mut |s: &Step| {
                if let Some(t) = &mut table {
                    t.step(s);
                }
                count = count.wrapping_add(1);
                if count.is_multiple_of(65_536)
                    && let Some(b) = &bar
                {
                    b.set_position(s.line as u64);
                }
            },
        );
        if let Some(b) = &bar {
            b.finish_and_clear();
        }
        if let Some(e) = table.and_then(|t| t.error) {
            return Err(anyhow::Error::new(e).context("cannot write the block table"));
        }
        result
    };
    let (mut report_, cut) = result.map_err(sim_error)?;
    if let (Some(setup), Some(cut)) = (&removal, cut) {
        setup.finish(args, &cut, &mut report_, &mut sinks)?;
    }
    if let Some(json) = args.json.as_ref().and(sinks.get_mut(0)) {
        json.write_all(report_.to_json().as_bytes())
            .context("cannot write the JSON report")?;
    }
    deliver(sinks)?;
    for w in &report_.warnings {
        note!("{w}\n");
    }
    if !args.quiet {
        note!("{}", report_.summary());
    }
    if report_.violated() {
        return Err(anyhow::Error::new(Violated));
    }
    Ok(())
}

/// Material removal as the options ask for it: the stock and tool, and the
/// design to compare with.
struct RemovalSetup {
    /// The stock and tool, until the replay takes them.
    cutting: Option<Cutting>,
    description: String,
    design: Option<Design>,
}

impl RemovalSetup {
    /// From `--stock`, `--tool`, `--resolution` and `--design`; `None`
    /// without `--stock`.
    fn load(args: &SimArgs) -> Result<Option<RemovalSetup>> {
        let (Some(stock), Some(tool)) = (&args.stock, &args.tool) else {
            return Ok(None);
        };
        if let Some(r) = args.resolution
            && !(r.is_finite() && r > 0.0)
        {
            return Err(usage(format!(
                "--resolution {r}: must be a positive number of mm"
            )));
        }
        if !(args.difftol.is_finite() && args.difftol > 0.0) {
            return Err(usage(format!(
                "--difftol {}: must be a positive number of mm",
                args.difftol
            )));
        }
        let tool = crate::sim_stock::parse_tool(tool)?;
        let process = match &args.process {
            None => None,
            Some(p) => {
                if !matches!(tool, kinpost_stock::Tool::ContactWheel { .. }) {
                    return Err(usage(format!(
                        "--process grinds with the belt's contact wheel: give --tool wheel:RADIUS,WIDTH (not the {})",
                        tool.name()
                    )));
                }
                Some(crate::sim_stock::read_process(p)?)
            }
        };
        // Triangles of a design surface stay a tenth of the tolerance (and
        // of the ray spacing) from it, so the tessellation is not measured.
        let chord = (args.difftol / 10.0).min(args.resolution.unwrap_or(f64::INFINITY) / 10.0);
        let source = args
            .design
            .as_deref()
            .map(|p| {
                crate::sim_stock::DesignSource::load(
                    p,
                    args.design_side,
                    args.design_region.as_deref(),
                    chord,
                )
            })
            .transpose()?;
        let (stock, description) =
            crate::sim_stock::load_stock(stock, args.resolution, source.as_ref())?;
        let design = source
            .map(crate::sim_stock::DesignSource::into_design)
            .transpose()?;
        let mut cutting = Cutting::new(stock, tool);
        if let Some(model) = process {
            cutting = cutting.with_process(model);
        }
        Ok(Some(RemovalSetup {
            cutting: Some(cutting),
            description,
            design,
        }))
    }

    /// The report's removal and the files of the part: `--stl-out` (output
    /// 2 on, after --json and --blocks), `--ply-out`, `--svg-out`.
    fn finish(
        &self,
        args: &SimArgs,
        cut: &Cutting,
        report: &mut SimReport,
        sinks: &mut [crate::sinks::Sink],
    ) -> Result<()> {
        let design = self.design.as_ref().map(|d| (d, args.difftol));
        let (removal, cmp) = cut.report(&self.description, design)?;
        report.removal = Some(removal);
        let mut at = usize::from(args.json.is_some()) + usize::from(args.blocks.is_some());
        let part = (args.stl_out.is_some() || args.ply_out.is_some()).then(|| contour(cut.stock()));
        if let (Some(_), Some(part)) = (&args.stl_out, &part) {
            write_stl(part, &mut sinks[at]).context("cannot write --stl-out")?;
            at += 1;
        }
        if let (Some(_), Some(part), Some(cmp)) = (&args.ply_out, &part, &cmp) {
            write_ply(part, cmp, cut.stock().resolution_mm(), &mut sinks[at])
                .context("cannot write --ply-out")?;
            at += 1;
        }
        if let (Some(_), Some(cmp)) = (&args.svg_out, &cmp) {
            write_svg(cut.stock(), cmp, &mut sinks[at]).context("cannot write --svg-out")?;
        }
        Ok(())
    }
}

/// A progress bar over the program's lines (the line being run; loops go
/// back), on a terminal only, never with `--quiet`, for programs large
/// enough to take a while (8 MiB, as `post`).
fn progress_bar(quiet: bool, text: &str) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if quiet || !io::stderr().is_terminal() || text.len() < 8 << 20 {
        return None;
    }
    let bar = indicatif::ProgressBar::new(text.lines().count() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("replaying {wide_bar} line {pos}/{len}").ok()?,
    );
    Some(bar)
}

/// A replay error: a located diagnostic is printed as it is.
fn sim_error(e: kinpost_sim::SimError) -> anyhow::Error {
    match e.diagnostic() {
        Some(d) => report(d),
        None => anyhow!("{e}"),
    }
}

/// The outputs: `--json`, then `--blocks`, as given.
fn open_sim_outputs(args: &SimArgs) -> Result<Vec<crate::sinks::Sink>> {
    let mut inputs: Vec<(&str, &Path)> = Vec::new();
    if args.program != "-" {
        inputs.push(("program", Path::new(&args.program)));
    }
    if let Some(cl) = &args.cl {
        inputs.push(("CL file", cl.as_path()));
    }
    if Path::new(&args.machine).is_file() {
        inputs.push(("machine file", Path::new(&args.machine)));
    }
    let mut outputs = Vec::new();
    if let Some(j) = &args.json {
        outputs.push(("--json", j.as_path()));
    }
    if let Some(b) = &args.blocks {
        outputs.push(("--blocks", b.as_path()));
    }
    for (name, file) in [
        ("--stl-out", &args.stl_out),
        ("--ply-out", &args.ply_out),
        ("--svg-out", &args.svg_out),
    ] {
        if let Some(f) = file {
            outputs.push((name, f.as_path()));
        }
    }
    if let Some(d) = &args.design {
        inputs.push(("design", d.as_path()));
    }
    if let Some(s) = args.stock.as_deref().filter(|s| Path::new(s).is_file()) {
        inputs.push(("stock", Path::new(s)));
    }
    if let Some(p) = &args.process {
        inputs.push(("process file", p.as_path()));
    }
    open_outputs(&inputs, &outputs)
}

/// The program's language: `--dialect`, else the program's extension,
/// else the machine's dialect.
fn family(args: &SimArgs, machine_dialect: Option<&str>) -> Result<Family> {
    if let Some(d) = &args.dialect {
        let dialect = load_dialect(d)?;
        return Family::of_dialect(&dialect).ok_or_else(|| {
            usage(format!(
                "dialect `{d}`: its program extension `.{}` names no controller family the interpreter reads (mpf, spf, nc, tap, iso, ngc, h, csv)",
                dialect.extension()
            ))
        });
    }
    let ext = Path::new(&args.program)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let by_ext = match ext.as_deref() {
        Some("mpf" | "spf") => Some(Family::Sinumerik),
        Some("nc" | "tap" | "iso") => Some(Family::Fanuc),
        Some("ngc") => Some(Family::LinuxCnc),
        Some("h") => Some(Family::Heidenhain),
        Some("csv") => Some(Family::Csv),
        _ => None,
    };
    if let Some(f) = by_ext {
        return Ok(f);
    }
    if let Some(d) = machine_dialect {
        let dialect = load_dialect(&dialect_of_machine(&args.machine, d))?;
        if let Some(f) = Family::of_dialect(&dialect) {
            return Ok(f);
        }
    }
    Err(usage(format!(
        "cannot tell the language of {}: give --dialect (sinumerik, fanuc, linuxcnc, heidenhain, csv)",
        args.program
    )))
}

/// The program's text and the name diagnostics give it.
fn read_program(program: &str) -> Result<(String, String)> {
    if program == "-" {
        let mut bytes = Vec::new();
        io::stdin()
            .take(MAX_PROGRAM_BYTES as u64 + 1)
            .read_to_end(&mut bytes)
            .context("cannot read the program from standard input")?;
        if bytes.len() > MAX_PROGRAM_BYTES {
            return Err(anyhow!(
                "the program on standard input is larger than {MAX_PROGRAM_BYTES} bytes"
            ));
        }
        let text = kinpost_post::diag::decode_utf8(bytes, STDIN_NAME).map_err(report)?;
        return Ok((text, STDIN_NAME.to_string()));
    }
    let path = Path::new(program);
    if path.is_dir() {
        return Err(anyhow!("program {program} is a directory"));
    }
    let text = crate::read_text(path, "program", MAX_PROGRAM_BYTES)?;
    if text.len() > MAX_PROGRAM_BYTES {
        return Err(anyhow!(
            "program {program} is larger than {MAX_PROGRAM_BYTES} bytes"
        ));
    }
    Ok((text, program.to_string()))
}

/// The `--blocks` table: the csv dialect's columns (`line` here is the NC
/// line), one row per motion block, written as the blocks come; `motion`
/// is `rapid`, `feed`, `cw` or `ccw` (arcs: their end values).
struct BlockTable<'w> {
    out: &'w mut dyn Write,
    axes: usize,
    pressure: Option<f64>,
    has_pressure: bool,
    row: String,
    /// The first write error (the interpreter's sink cannot return one).
    error: Option<io::Error>,
}

impl<'w> BlockTable<'w> {
    fn new(names: &[String], axes: usize, out: &'w mut dyn Write) -> Result<BlockTable<'w>> {
        let mut head = String::from("line,motion");
        for n in &names[..axes] {
            head.push(',');
            head.push_str(n);
        }
        head.push_str(",feed");
        for n in &names[axes..] {
            head.push(',');
            head.push_str(n);
        }
        head.push('\n');
        out.write_all(head.as_bytes())
            .context("cannot write the block table")?;
        Ok(BlockTable {
            out,
            axes,
            pressure: None,
            has_pressure: names.len() > axes,
            row: String::new(),
            error: None,
        })
    }

    fn step(&mut self, s: &Step) {
        use std::fmt::Write as _;
        if self.error.is_some() {
            return;
        }
        let m = match &s.event {
            Event::Pressure { value, .. } => {
                self.pressure = Some(*value);
                return;
            }
            Event::Move(m) => m,
            _ => return,
        };
        let t = &mut self.row;
        t.clear();
        let motion = match &m.kind {
            MotionKind::Rapid => "rapid",
            MotionKind::Linear => "feed",
            MotionKind::Arc(a) if a.clockwise => "cw",
            MotionKind::Arc(_) => "ccw",
        };
        let _ = write!(t, "{},{motion}", s.line);
        for v in &m.axes()[..self.axes] {
            let _ = write!(t, ",{}", crate::fixed(*v, 6));
        }
        if m.kind == MotionKind::Rapid {
            t.push(',');
        } else {
            let _ = write!(t, ",{}", crate::fixed(m.feed, 6));
        }
        if self.has_pressure {
            t.push(',');
            if let Some(p) = self.pressure {
                let _ = write!(t, "{}", crate::fixed(p, 3));
            }
        }
        t.push('\n');
        if let Err(e) = self.out.write_all(t.as_bytes()) {
            self.error = Some(e);
        }
    }
}
