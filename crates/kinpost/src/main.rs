//! The `kinpost` command: a thin layer over the library.
//!
//! Exit codes: 0 success (warnings allowed), 1 bad input, 2 usage error,
//! 3 `sim` found overtravel or a collision.

use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, anyhow};
use clap::{Parser, Subcommand};
use kinpost_post::machine::{
    Kinematics, MAX_AXIS_ROUNDING_RAD, Machine, OutputMode, Pose, builtin, machine_from_toml,
};
use kinpost_post::nc::Dialect;
use kinpost_post::{Config, FeedMode, PlannerMode, PostOptions};
use nalgebra::Vector3;

/// `eprintln!` that does not panic when standard error is gone (its reader
/// closed the pipe): the message is lost, the run goes on and its exit code
/// stands.
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod cmd_calibrate;
mod cmd_sim;
mod cmd_surface;
mod cmd_wheel;
mod output;
mod sim_stock;
mod sinks;

use sinks::{Sink, deliver, open_outputs};

#[derive(Parser)]
#[command(
    name = "kinpost",
    version,
    about = "Multi-axis CNC post-processor: CL data to NC code through a machine's kinematic chain, checked in closed loop",
    after_help = "Exit codes: 0 success (warnings allowed), 1 bad input, 2 usage error, 3 `sim` found overtravel, a collision, a rapid into the stock or a gouge."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Post a CL file (NX CLSF / APT) to an NC program.
    Post(PostArgs),
    /// List the built-in machines.
    Machines,
    /// Show or check machine files.
    #[command(subcommand)]
    Machine(MachineCommand),
    /// List the built-in dialects.
    Dialects,
    /// Show a built-in dialect file.
    #[command(subcommand)]
    Dialect(DialectCommand),
    /// Forward kinematics: tool point and axis in the part frame for axis values.
    Fk {
        /// Built-in machine name or machine file.
        #[arg(long, short)]
        machine: String,
        /// Axis values as NAME=VALUE (mm, degrees); axes not given are 0.
        /// The machine's pressure word (H1=3000) sets the pressure.
        #[arg(value_name = "AXIS=VALUE")]
        values: Vec<String>,
        /// Pressure of the machine's pressure axis (default: its reference).
        #[arg(long, value_name = "VALUE")]
        pressure: Option<f64>,
    },
    /// Inverse kinematics: every solution for a tool point and axis.
    Ik {
        /// Built-in machine name or machine file.
        #[arg(long, short)]
        machine: String,
        /// Tool point in the part frame: x,y,z (mm).
        #[arg(long, allow_hyphen_values = true)]
        point: String,
        /// Tool axis in the part frame: i,j,k.
        #[arg(long, allow_hyphen_values = true)]
        axis: String,
        /// Reference direction u,v,w (machines with three free rotary axes;
        /// it frees the axes marked `free_with_reference`).
        #[arg(long, allow_hyphen_values = true)]
        reference: Option<String>,
        /// Pressure of the machine's pressure axis (default: its reference).
        #[arg(long, value_name = "VALUE")]
        pressure: Option<f64>,
        /// How far outside the directions the machine can point a tool axis
        /// may lie and be solved at the nearest one, radians: the rounding
        /// of the CL's tool axes (default 1e-6, 6 decimals or more; 1e-4 for
        /// 4 decimals; at most 1e-3).
        #[arg(long, value_name = "RAD", allow_hyphen_values = true)]
        axis_rounding: Option<f64>,
    },
    /// B-spline surfaces from measured points: fit, evaluate, plot.
    #[command(subcommand)]
    Surface(cmd_surface::SurfaceCommand),
    /// Belt-grinding path on a surface, as an NX-style CL file.
    Path(Box<cmd_surface::PathArgs>),
    /// Grinding-pressure axis: input-link angle, wheel offset and axis
    /// correction per pressure, and the wheel-centre trajectory as SVG.
    Wheel(WheelArgs),
    /// The virtual machine: replay an NC program on a machine, checking
    /// travel, collisions and (with --cl) the deviation from its CL; exit
    /// code 3 when anything is violated.
    Sim(Box<cmd_sim::SimArgs>),
    /// Belt grinding: fit Preston's coefficient and the contact wheel's
    /// stiffness to measured trace depths, and write them into a process
    /// file for `sim --process`.
    Calibrate(cmd_calibrate::CalibrateArgs),
}

#[derive(clap::Args)]
struct WheelArgs {
    /// Built-in machine name or machine file (with a [pressure] section).
    #[arg(long, short)]
    machine: String,
    /// Pressures to show (default: the calibration rows and the reference).
    #[arg(long, value_name = "VALUE", num_args = 1..)]
    pressure: Vec<f64>,
    /// Pressures FROM, FROM+STEP, ... up to TO, e.g. 3000:3600:100.
    #[arg(long, value_name = "FROM:TO:STEP")]
    table: Option<String>,
    /// Write the wheel-centre trajectory to this SVG file.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
}

#[derive(clap::Args)]
// `--lintol -1` is a value for the check below, not an unknown option.
#[command(allow_negative_numbers = true)]
struct PostArgs {
    /// CL file, or - for standard input.
    input: String,
    /// Built-in machine name (see `kinpost machines`) or machine file (TOML).
    #[arg(long, short)]
    machine: String,
    /// Built-in dialect name or dialect file; default: the machine's.
    #[arg(long, short)]
    dialect: Option<String>,
    /// Output NC file, or - for standard output (the default).
    #[arg(short = 'o', long = "output-file", value_name = "FILE")]
    output_file: Option<PathBuf>,
    /// Write the run summary as JSON to this file, or - for standard output
    /// (with -o FILE).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Closed-loop position tolerance in mm (default: derived from the
    /// output decimals and the machine's largest pivot distance).
    #[arg(long)]
    tolerance: Option<f64>,
    /// Program name for the header (default: PARTNO, TOOL PATH name or file name).
    #[arg(long)]
    program: Option<String>,
    /// Date for the header: a text, or `today`. Default: none, so that the
    /// same input gives the same output bytes.
    #[arg(long)]
    date: Option<String>,
    /// Joint output (machine axis values) or tool-centre-point output (tool
    /// point and rotary axes; the controller does the kinematics). Default:
    /// the machine's `[post] output`, else joint.
    #[arg(long, value_enum, value_name = "MODE")]
    output: Option<Output>,
    /// Feed words: `tip` (the CL feed at the tool point, mm/min),
    /// `inverse-time` (G93: F = 1 / block time in minutes; fanuc, linuxcnc,
    /// sinumerik) or `dpm` (F = length of the vector of all axis changes, mm
    /// and degrees, per minute, so that the block time is the CL segment
    /// length over the CL feed). Default: the dialect's `[feed] mode`, else
    /// tip. Every mode slows blocks down to the axes' `max_velocity`.
    #[arg(long, value_enum)]
    feed_mode: Option<FeedModeArg>,
    /// Choose the configurations over the whole path (`global`: dynamic
    /// programming, no flips or unwinding inside a cut where the travel
    /// allows) or point by point (`nearest`).
    #[arg(long, value_enum, default_value = "global")]
    planner: PlannerArg,
    /// Linearization tolerance in mm: blocks are inserted until the contact
    /// point, moved linearly in joint space, stays this close to the straight
    /// CL segment. 0 turns linearization off. Joint output only.
    #[arg(long, value_name = "MM", default_value_t = kinpost_post::DEFAULT_LINTOL_MM)]
    lintol: f64,
    /// Half-angle in degrees of the cone around a singular tool-axis
    /// direction inside which the free rotary angle is held where the exact
    /// one would swing (default: the machine's `[post] singular_cone`, else
    /// 0.5).
    #[arg(long, value_name = "DEG")]
    singular_cone: Option<f64>,
    /// Retract distance along the tool axis for a reconfiguration, mm
    /// (default: the machine's `[post] retract`, else 50).
    #[arg(long, value_name = "MM")]
    retract: Option<f64>,
    /// Fail where the path needs a retract and reconfiguration, naming the
    /// CL line, instead of inserting one.
    #[arg(long)]
    no_reconfigure: bool,
    /// Tool axis i,j,k for GOTOs before any axis is given (3-axis APT files).
    #[arg(long, allow_hyphen_values = true)]
    default_axis: Option<String>,
    /// Length units of a CL file that declares none (NX writes no UNITS):
    /// inch or mm. An inch feed in a file without either is an error.
    #[arg(long, value_enum)]
    units: Option<UnitsArg>,
    /// Text encoding of the CL file: utf-8, or latin1 (ISO 8859-1, the
    /// accented comments CATIA V5 writes on Western European systems).
    #[arg(long, value_enum, default_value = "utf-8")]
    encoding: EncodingArg,
    /// What a CL INSERT becomes: verbatim code (the APT meaning; a line
    /// that moves an axis or changes a tool is warned about), a comment
    /// (SOLIDWORKS CAM writes tool and stock notes as INSERT), or nothing.
    #[arg(long, value_enum, default_value = "verbatim")]
    insert: InsertArg,
    /// How CL CIRCLE arcs are written: native G2/G3 (Heidenhain CC and C
    /// in the X/Y working plane) where the arc lies in a plane of the
    /// machine at constant rotary axes in joint output, lines within
    /// --lintol elsewhere; or lines everywhere.
    #[arg(long, value_enum, default_value = "native")]
    arcs: ArcsArg,
    /// How the holes of CL CYCLE statements are written: native, as the
    /// dialect's canned cycle (G81…G89 with G98/G99, Sinumerik MCALL
    /// CYCLE81…, Heidenhain CYCL DEF 200…) where the checked moves of a
    /// hole are exactly the cycle's on the program's Z; or expand, the
    /// moves of every hole.
    #[arg(long, value_enum, default_value = "native")]
    cycles: CyclesArg,
    /// The frame the points are posted in: mcs, as written in the machine
    /// coordinate system of the CL's MSYS (the work offset locates it on
    /// the machine; a later MSYS that moves it is an error), or absolute,
    /// every point mapped out of the MSYS in force into the CAM model's
    /// absolute frame (files of several setups in one program).
    #[arg(long, value_enum, default_value = "mcs")]
    frame: FrameArg,
    /// Grinding pressure (machines with a [pressure] axis, e.g. H1) for CL
    /// points before any PRESSURE statement. Without it and without
    /// PRESSURE, no pressure word is written and the wheel is where it is
    /// at the machine's reference pressure.
    #[arg(long, value_name = "VALUE")]
    pressure: Option<f64>,
    /// Write the pressure words but solve every block at the reference
    /// pressure, as the machine maker's post does (for comparison).
    #[arg(long)]
    no_pressure_compensation: bool,
    /// How far outside the directions the machine can point a tool axis
    /// may lie and be solved at the nearest one, radians: the rounding
    /// of the CL's tool axes (default 1e-6, 6 decimals or more; 1e-4 for
    /// 4 decimals; at most 1e-3).
    #[arg(long, value_name = "RAD")]
    axis_rounding: Option<f64>,
    /// Print no summary on standard error.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum FeedModeArg {
    Tip,
    InverseTime,
    Dpm,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum ArcsArg {
    Native,
    Linear,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum CyclesArg {
    Native,
    Expand,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum FrameArg {
    Mcs,
    Absolute,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum InsertArg {
    Verbatim,
    Comment,
    Drop,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum UnitsArg {
    Inch,
    Mm,
}

/// The text encoding of a CL file (`--encoding`).
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EncodingArg {
    /// UTF-8 (and so ASCII).
    #[value(name = "utf-8", alias = "utf8")]
    Utf8,
    /// ISO 8859-1.
    #[value(name = "latin1", alias = "iso-8859-1")]
    Latin1,
}

impl EncodingArg {
    /// `input` as the UTF-8 text the CL reader takes.
    pub fn decode<'a>(self, input: impl Read + 'a) -> Box<dyn Read + 'a> {
        match self {
            EncodingArg::Utf8 => Box::new(input),
            EncodingArg::Latin1 => Box::new(kinpost_post::cl::encoding::Latin1::new(input)),
        }
    }
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum PlannerArg {
    Global,
    Nearest,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum Output {
    Joint,
    Tcp,
}

#[derive(Subcommand)]
enum MachineCommand {
    /// Print a built-in machine file.
    Show { name: String },
    /// Validate a machine file.
    Check {
        /// Machine file, built-in machine name, or - for standard input.
        file: PathBuf,
    },
}

#[derive(Subcommand)]
enum DialectCommand {
    /// Print a built-in dialect file.
    Show { name: String },
    /// Validate a dialect file: its settings, and every template rendered
    /// once with sample values within the template limits.
    Check {
        /// Dialect file, built-in dialect name, or - for standard input.
        file: PathBuf,
    },
}

/// An error already reported to the user (diagnostics printed).
#[derive(Debug)]
struct Reported;

impl std::fmt::Display for Reported {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("reported")
    }
}

impl std::error::Error for Reported {}

/// A command-line value that cannot be used: exit 2, like clap's own usage
/// errors (exit 1 is for bad input files).
#[derive(Debug)]
struct Usage(String);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Usage {}

/// A [`Usage`] error.
fn usage(message: impl Into<String>) -> anyhow::Error {
    anyhow::Error::new(Usage(message.into()))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // An interrupted run leaves no temporary file behind.
    if let Err(e) = crate::output::remove_staged_files_on_signals() {
        note!(
            "warning: cannot watch for signals ({e}): an interrupted run may leave a .kinpost-*.tmp file"
        );
    }
    // (Text still buffered is flushed here, where its error can be seen.)
    match run(cli).and_then(|()| Ok(io::stdout().flush()?)) {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that closed the pipe (`| head`) wants no more: stop
        // quietly, as Unix tools do.
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            if e.downcast_ref::<cmd_sim::Violated>().is_some() {
                return ExitCode::from(3);
            }
            if e.downcast_ref::<Reported>().is_none() {
                note!("error: {e:#}");
            }
            if e.downcast_ref::<Usage>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

/// Whether writing to standard output failed because its reader is gone.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<io::Error>()
            .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe)
    })
}

fn run(cli: Cli) -> Result<()> {
    // Standard output through `?`: `print!` panics on a closed pipe.
    let mut out = io::stdout().lock();
    match cli.command {
        Command::Post(args) => post(args),
        Command::Machines => {
            for name in builtin::names() {
                let m = builtin::load(name).expect("listed").map_err(report)?;
                writeln!(out, "{name:<16} {}", m.description)?;
            }
            Ok(())
        }
        Command::Machine(MachineCommand::Show { name }) => {
            let src = builtin::source(&name).ok_or_else(|| unknown_machine(&name))?;
            Ok(out.write_all(src.as_bytes())?)
        }
        Command::Machine(MachineCommand::Check { file }) => machine_check(&file, &mut out),
        Command::Dialects => {
            for name in Dialect::builtin_names() {
                let d = Dialect::builtin(name).expect("listed");
                writeln!(out, "{name:<12} .{:<5} {}", d.extension(), d.description())?;
            }
            Ok(())
        }
        Command::Dialect(DialectCommand::Check { file }) => dialect_check(&file, &mut out),
        Command::Dialect(DialectCommand::Show { name }) => {
            let src = Dialect::builtin_source(&name).ok_or_else(|| {
                anyhow!(
                    "no built-in dialect `{name}` (built in: {})",
                    Dialect::builtin_names().join(", ")
                )
            })?;
            Ok(out.write_all(src.as_bytes())?)
        }
        Command::Fk {
            machine,
            values,
            pressure,
        } => fk(&machine, &values, pressure, &mut out),
        Command::Ik {
            machine,
            point,
            axis,
            reference,
            pressure,
            axis_rounding,
        } => ik(
            &machine,
            &point,
            &axis,
            reference.as_deref(),
            pressure,
            axis_rounding,
            &mut out,
        ),
        Command::Wheel(args) => wheel(&args),
        Command::Surface(c) => cmd_surface::surface(c),
        Command::Path(a) => cmd_surface::path(*a),
        Command::Sim(a) => cmd_sim::sim(&a),
        Command::Calibrate(a) => {
            // (With the process file on standard output, the fit goes to
            // standard error.)
            if a.writes_stdout() {
                cmd_calibrate::calibrate_command(&a, &mut io::stderr().lock())
            } else {
                cmd_calibrate::calibrate_command(&a, &mut out)
            }
        }
    }
}

/// `kinpost machine check FILE` (`-`: standard input).
fn machine_check(file: &Path, out: &mut impl Write) -> Result<()> {
    let (name, m) = if file == Path::new("-") {
        let mut src = Vec::new();
        io::stdin()
            .read_to_end(&mut src)
            .context("cannot read the machine file from standard input")?;
        let src = kinpost_post::diag::decode_utf8(src, STDIN_NAME).map_err(report)?;
        (
            STDIN_NAME.to_string(),
            machine_from_source(&src, STDIN_NAME)?,
        )
    } else {
        let name = file.to_string_lossy();
        (name.to_string(), load_machine(&name)?)
    };
    let free: Vec<&str> = m
        .axes
        .iter()
        .filter(|a| a.is_free())
        .map(|a| a.name.as_str())
        .collect();
    let pressure = m.pressure.as_ref().map_or(String::new(), |p| {
        let [lo, hi] = p.range();
        format!(
            "; pressure {} (reference {}, calibration {lo} .. {hi}; `kinpost wheel` shows it)",
            p.name, p.reference
        )
    });
    writeln!(
        out,
        "{name}: machine `{}` is valid: {} axes ({} free: {}){pressure}",
        m.name,
        m.axes.len(),
        free.len(),
        free.join(" ")
    )?;
    for a in m.axes.iter().filter(|a| a.is_endless()) {
        let limits = a.limits.map_or(String::new(), |[lo, hi]| {
            format!("; its limits [{lo}, {hi}] are not applied")
        });
        writeln!(
            out,
            "  {} turns without end (wrap = \"modulo\"){limits}",
            a.name
        )?;
    }
    if let Some(folds) = Kinematics::new(&m).folds() {
        // Two rotary axes at another angle than the tool makes with
        // the inner one: say which tool axes exist at all, from the
        // end of the singular direction the band lies nearer.
        let [lo, hi] = folds.edges.map(|e| e.to_degrees());
        let (lo, hi) = (
            if lo.is_nan() { 0.0 } else { lo },
            if hi.is_nan() { 180.0 } else { hi },
        );
        let flip = lo + hi > 180.0;
        let (lo, hi, d) = if flip {
            (180.0 - hi, 180.0 - lo, -folds.direction)
        } else {
            (lo, hi, folds.direction)
        };
        // (+ 0.0: no "-0.0000000".)
        let d = d.map(|v| v + 0.0);
        writeln!(
            out,
            "  the tool axis reaches only the directions {lo:.4}° to {hi:.4}° from ({:.7}, {:.7}, {:.7}); at an edge that is not 0° or 180° the two solutions meet (a fold)",
            d.x, d.y, d.z
        )?;
    }
    Ok(())
}

/// `kinpost dialect check FILE` (`-`: standard input): the dialect loads
/// (every template compiled, its variables known, and rendered once with
/// sample values within the template limits).
fn dialect_check(file: &Path, out: &mut impl Write) -> Result<()> {
    let (name, d) = if file == Path::new("-") {
        let mut src = Vec::new();
        io::stdin()
            .read_to_end(&mut src)
            .context("cannot read the dialect file from standard input")?;
        let src = kinpost_post::diag::decode_utf8(src, STDIN_NAME).map_err(report)?;
        let d = Dialect::from_toml(&src, STDIN_NAME).map_err(report)?;
        (STDIN_NAME.to_string(), d)
    } else {
        let name = file.to_string_lossy().into_owned();
        let d = load_dialect(&name)?;
        (name, d)
    };
    writeln!(
        out,
        "{name}: dialect `{}` is valid (templates within {} fuel and {} bytes of output)",
        d.name(),
        kinpost_post::nc::TEMPLATE_FUEL,
        kinpost_post::nc::MAX_TEMPLATE_OUTPUT_BYTES
    )?;
    Ok(())
}

/// The name diagnostics give standard input, as `post -` does.
const STDIN_NAME: &str = "<stdin>";

/// Prints diagnostics and turns them into a [`Reported`] error.
fn report(d: impl std::fmt::Display) -> anyhow::Error {
    note!("{d}");
    anyhow::Error::new(Reported)
}

fn unknown_machine(name: &str) -> anyhow::Error {
    anyhow!(
        "no built-in machine `{name}` and no such file (built in: {})",
        builtin::names().collect::<Vec<_>>().join(", ")
    )
}

/// Whether `name` names a built-in (machine or dialect) rather than a
/// file: no path separator and no extension. Only such a name may be a
/// built-in; any other is a file.
fn is_plain_name(name: &str) -> bool {
    !name.contains('/')
        && !name.contains(std::path::MAIN_SEPARATOR)
        && Path::new(name).extension().is_none()
}

/// Says on standard error that the built-in `name` was taken although a
/// file of that name exists here (`./NAME` reads the file).
fn note_builtin_over_file(what: &str, name: &str) {
    if is_file_to_read(Path::new(name)) {
        note!(
            "note: `{name}` is the built-in {what}; the file {name} here is not read (give ./{name} to read it)"
        );
    }
}

/// A file read whole as UTF-8 text: an error names the file, and for bytes
/// that are not UTF-8 the line and column of the first.
/// At most `limit` bytes and one more are read: the loader refuses a
/// larger file by its size, and a file of gigabytes is not read whole.
fn read_text(path: &Path, what: &str, limit: usize) -> Result<String> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(limit as u64 + 1).read_to_end(&mut bytes))
        .with_context(|| format!("cannot read {what} {}", path.display()))?;
    if bytes.len() > limit {
        // (Cut at the limit, perhaps inside a character: the loader
        // refuses it by its size.)
        return Ok(String::from_utf8_lossy(&bytes).into_owned());
    }
    kinpost_post::diag::decode_utf8(bytes, &path.to_string_lossy()).map_err(report)
}

/// A built-in machine by name, or a machine file. A plain name (no path
/// separator, no extension) of a built-in machine is the built-in one, with
/// a note when a file of that name exists here too.
fn load_machine(name: &str) -> Result<Machine> {
    let path = Path::new(name);
    if is_plain_name(name)
        && let Some(m) = builtin::load(name)
    {
        note_builtin_over_file("machine", name);
        return m.map_err(report);
    }
    if is_file_to_read(path) {
        let src = read_text(
            path,
            "machine file",
            kinpost_post::machine::MAX_MACHINE_FILE_BYTES,
        )?;
        return machine_from_source(&src, name);
    }
    match builtin::load(name) {
        Some(m) => m.map_err(report),
        None if path.is_dir() => Err(anyhow!("machine file {name} is a directory")),
        None => Err(unknown_machine(name)),
    }
}

/// Whether `path` names something to read as a file: a file, or a named
/// pipe or device (`-m <(…)` in a shell), not a directory.
fn is_file_to_read(path: &Path) -> bool {
    path.metadata().is_ok_and(|m| !m.is_dir())
}

/// A machine file's machine, its `[post]` templates checked too.
fn machine_from_source(src: &str, name: &str) -> Result<Machine> {
    let machine = machine_from_toml(src, name).map_err(report)?;
    kinpost_post::check_machine_templates(src, name).map_err(report)?;
    Ok(machine)
}

/// The dialect a machine file names in `[post] dialect`, as a path from
/// the folder of that machine file when it is a relative file name (not a
/// plain built-in name): the same command gives the same program from any
/// folder.
fn dialect_of_machine(machine_arg: &str, dialect: &str) -> String {
    let machine_path = Path::new(machine_arg);
    let from_file = !(is_plain_name(machine_arg) && builtin::load(machine_arg).is_some())
        && is_file_to_read(machine_path);
    if is_plain_name(dialect) || Path::new(dialect).is_absolute() || !from_file {
        return dialect.to_string();
    }
    match machine_path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => {
            dir.join(dialect).to_string_lossy().into_owned()
        }
        _ => dialect.to_string(),
    }
}

/// A built-in dialect by name, or a dialect file (the same rule as
/// [`load_machine`]).
fn load_dialect(name: &str) -> Result<Dialect> {
    let path = Path::new(name);
    if is_plain_name(name)
        && let Some(d) = Dialect::builtin(name)
    {
        note_builtin_over_file("dialect", name);
        return Ok(d);
    }
    if is_file_to_read(path) {
        let src = read_text(
            path,
            "dialect file",
            kinpost_post::nc::MAX_DIALECT_FILE_BYTES,
        )?;
        return Dialect::from_toml(&src, name).map_err(report);
    }
    if let Some(d) = Dialect::builtin(name) {
        return Ok(d);
    }
    if path.is_dir() {
        return Err(anyhow!("dialect file {name} is a directory"));
    }
    Err(anyhow!(
        "no built-in dialect `{name}` and no such file (built in: {})",
        Dialect::builtin_names().join(", ")
    ))
}

fn parse_vector(text: &str, what: &str) -> Result<[f64; 3]> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let values: Vec<f64> = parts
        .iter()
        .map(|p| p.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| {
            usage(format!(
                "{what} `{text}`: expected three numbers separated by commas"
            ))
        })?;
    <[f64; 3]>::try_from(values).map_err(|_| {
        usage(format!(
            "{what} `{text}`: expected three numbers separated by commas"
        ))
    })
}

fn unit_vector(text: &str, what: &str) -> Result<Vector3<f64>> {
    let v = Vector3::from(parse_vector(text, what)?);
    let n = v.norm();
    if n < 1e-12 {
        return Err(usage(format!("{what} `{text}` is a zero vector")));
    }
    Ok(v / n)
}

fn post(args: PostArgs) -> Result<()> {
    // Both outputs exist (as temporary files) before the run, so that one
    // that cannot be created leaves the other unwritten too.
    let machine = load_machine(&args.machine)?;
    let dialect_name = match (&args.dialect, &machine.post.dialect) {
        (Some(d), _) => d.clone(),
        (None, Some(d)) => dialect_of_machine(&args.machine, d),
        (None, None) => "csv".to_string(),
    };
    let mut sinks = open_post_outputs(&args, &dialect_name)?;
    let dialect = load_dialect(&dialect_name)?;
    let options = PostOptions {
        cl_file: if args.input == "-" {
            STDIN_NAME.to_string()
        } else {
            args.input.clone()
        },
        program_name: args.program.clone(),
        date: match args.date.as_deref() {
            Some("today") => today(),
            Some(d) => d.to_string(),
            None => String::new(),
        },
        tolerance_mm: args.tolerance,
        output: args.output.map(|o| match o {
            Output::Joint => OutputMode::Joint,
            Output::Tcp => OutputMode::Tcp,
        }),
        feed_mode: args.feed_mode.map(|m| match m {
            FeedModeArg::Tip => FeedMode::Tip,
            FeedModeArg::InverseTime => FeedMode::InverseTime,
            FeedModeArg::Dpm => FeedMode::Dpm,
        }),
        planner: match args.planner {
            PlannerArg::Global => PlannerMode::Global,
            PlannerArg::Nearest => PlannerMode::Nearest,
        },
        lintol_mm: Some(args.lintol),
        singular_cone_deg: args.singular_cone,
        retract_mm: args.retract,
        no_reconfigure: args.no_reconfigure,
        default_axis: args
            .default_axis
            .as_deref()
            .map(|t| unit_vector(t, "default axis").map(|v| [v.x, v.y, v.z]))
            .transpose()?,
        frame: match args.frame {
            FrameArg::Mcs => kinpost_post::FrameMode::Mcs,
            FrameArg::Absolute => kinpost_post::FrameMode::Absolute,
        },
        arcs: match args.arcs {
            ArcsArg::Native => kinpost_post::ArcMode::Native,
            ArcsArg::Linear => kinpost_post::ArcMode::Linear,
        },
        cycles: match args.cycles {
            CyclesArg::Native => kinpost_post::CycleMode::Native,
            CyclesArg::Expand => kinpost_post::CycleMode::Expand,
        },
        insert: match args.insert {
            InsertArg::Verbatim => kinpost_post::InsertMode::Verbatim,
            InsertArg::Comment => kinpost_post::InsertMode::Comment,
            InsertArg::Drop => kinpost_post::InsertMode::Drop,
        },
        units: args.units.map(|u| match u {
            UnitsArg::Inch => kinpost_post::cl::Units::Inch,
            UnitsArg::Mm => kinpost_post::cl::Units::Mm,
        }),
        pressure: args.pressure,
        no_pressure_compensation: args.no_pressure_compensation,
        axis_rounding_rad: args.axis_rounding,
    };
    // Every option value checked in one place, the library's: a bad one is
    // a usage error.
    let config = Config::resolve(&options, &machine, &dialect).map_err(|e| usage(e.to_string()))?;
    let progress = progress_bar(&args);
    let input: Box<dyn BufRead> = if args.input == "-" {
        Box::new(BufReader::with_capacity(
            1 << 16,
            args.encoding.decode(io::stdin().lock()),
        ))
    } else {
        let f = std::fs::File::open(&args.input)
            .with_context(|| format!("cannot open CL file {}", args.input))?;
        // Opening a directory succeeds; its first read would fail as if
        // line 1 of a file were bad.
        if f.metadata().is_ok_and(|m| m.is_dir()) {
            return Err(anyhow!("CL file {} is a directory", args.input));
        }
        if let (Some(bar), Ok(meta)) = (&progress, f.metadata()) {
            bar.set_length(meta.len());
        }
        Box::new(BufReader::with_capacity(
            1 << 16,
            args.encoding.decode(Progress {
                inner: f,
                bar: progress.clone(),
            }),
        ))
    };

    let result = kinpost_post::post_with(input, &machine, &dialect, &mut sinks[0], &config);
    if let Some(bar) = &progress {
        bar.finish_and_clear();
    }
    let summary = match result {
        Ok(s) => s,
        Err(e) => match e.diagnostic() {
            Some(d) => return Err(report(d)),
            None => return Err(e.into()),
        },
    };
    if let Some(json) = sinks.get_mut(1) {
        json.write_all(summary.to_json().as_bytes())
            .context("cannot write the JSON summary")?;
    }
    deliver(sinks)?;
    for w in &summary.warnings {
        note!("{w}\n");
    }
    if !args.quiet {
        note!("{}", summary.one_line());
    }
    Ok(())
}

/// The sinks of `kinpost post`: the program (`-o`, standard output unless
/// given), then the JSON summary (`--json`) if asked for; never both on
/// standard output, never onto an input file (the CL, machine or dialect
/// file) or each other.
fn open_post_outputs(args: &PostArgs, dialect: &String) -> Result<Vec<Sink>> {
    let mut inputs = Vec::new();
    if args.input != "-" {
        inputs.push(("CL file", Path::new(&args.input)));
    }
    for (what, name) in [
        ("machine file", Some(&args.machine)),
        ("dialect file", Some(dialect)),
    ] {
        if let Some(name) = name.filter(|n| Path::new(n).is_file()) {
            inputs.push((what, Path::new(name)));
        }
    }
    let mut outputs = vec![(
        "the program (-o)",
        args.output_file.as_deref().unwrap_or(Path::new("-")),
    )];
    if let Some(json) = &args.json {
        outputs.push(("--json", json.as_path()));
    }
    open_outputs(&inputs, &outputs)
}

/// A progress bar over the bytes of the CL file, on a terminal only (never
/// in pipes, never with `--quiet`), for files large enough to take a while.
fn progress_bar(args: &PostArgs) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if args.quiet || args.input == "-" || !io::stderr().is_terminal() {
        return None;
    }
    let size = std::fs::metadata(&args.input).map(|m| m.len()).ok()?;
    if size < 8 << 20 {
        return None;
    }
    let bar = indicatif::ProgressBar::new(size);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "posting {wide_bar} {bytes}/{total_bytes} ({eta} left)",
        )
        .ok()?,
    );
    Some(bar)
}

/// The CL file, reporting how much of it has been read.
struct Progress<R> {
    inner: R,
    bar: Option<indicatif::ProgressBar>,
}

impl<R: io::Read> io::Read for Progress<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        if let Some(bar) = &self.bar {
            bar.inc(n as u64);
        }
        Ok(n)
    }
}

/// An axis rounding from the command line: an angle from 0 to
/// [`MAX_AXIS_ROUNDING_RAD`].
fn check_axis_rounding(v: f64) -> Result<f64> {
    if v.is_finite() && (0.0..=MAX_AXIS_ROUNDING_RAD).contains(&v) {
        Ok(v)
    } else {
        Err(usage(format!(
            "--axis-rounding must be an angle from 0 to {MAX_AXIS_ROUNDING_RAD:e} rad (the rounding of a CL tool axis; 1e-4 for 4 decimals)"
        )))
    }
}

/// A pressure from the command line: a number not below 0.
fn check_pressure_value(v: f64) -> Result<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(usage("--pressure must be a number not below 0"))
    }
}

/// The machine with its wheel at `pressure` (given: the machine must have a
/// pressure axis; a value outside the calibration is clamped, with a warning).
fn machine_at_pressure(m: &Machine, pressure: Option<f64>) -> Result<Machine> {
    let Some(h) = pressure else {
        return Ok(m.clone());
    };
    let h = check_pressure_value(h)?;
    let p = cmd_wheel::pressure_axis(m).map_err(|e| anyhow!("{e}"))?;
    if p.clamp(h) != kinpost_post::machine::Clamp::Inside {
        let [lo, hi] = p.range();
        note!(
            "warning: {} = {h} is outside the calibration ({lo} .. {hi}): the wheel sits on its stop",
            p.name
        );
    }
    Ok(m.at_pressure(h))
}

fn fk(machine: &str, values: &[String], pressure: Option<f64>, out: &mut impl Write) -> Result<()> {
    let mut m = load_machine(machine)?;
    let mut q = m.home_joints();
    let mut pressure = pressure;
    for v in values {
        let (name, value) = v
            .split_once('=')
            .ok_or_else(|| usage(format!("`{v}`: expected AXIS=VALUE, e.g. X=459")))?;
        let value: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite())
            .ok_or_else(|| usage(format!("`{v}`: `{value}` is not a number")))?;
        if let Some(p) = &m.pressure
            && p.name.eq_ignore_ascii_case(name.trim())
        {
            pressure = Some(value);
            continue;
        }
        let i = m
            .axis_index(name.trim())
            .ok_or_else(|| anyhow!("machine `{}` has no axis `{name}`", m.name))?;
        if !m.axes[i].accepts(value) {
            note!("warning: {name}={value} is outside the axis limits");
        }
        set_axis(&mut m, i, value);
        q[i] = value;
    }
    let pose = Kinematics::new(&machine_at_pressure(&m, pressure)?).fk(&q);
    let p = pose.point;
    let a = pose.axis;
    let v =
        |v: &Vector3<f64>, d: usize| v.iter().map(|&x| fixed(x, d)).collect::<Vec<_>>().join(" ");
    writeln!(out, "point     {}", v(&p, 6))?;
    writeln!(out, "axis      {}", v(&a, 9))?;
    if let Some(r) = pose.reference {
        writeln!(out, "reference {}", v(&r, 9))?;
    }
    Ok(())
}

/// `value` with `decimals` decimals, without the sign of a value that
/// rounds to zero ("0.000000", not "-0.000000").
fn fixed(value: f64, decimals: usize) -> String {
    let s = format!("{value:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => s,
    }
}

/// Puts axis `i` of the machine `fk` turns at `value`. The kinematics
/// build a locked axis into the chain at its `fixed` value, so a value given
/// for one must change the machine, not only the joint vector: an axis free
/// with a reference direction is unlocked (as for 6-axis CL points); any
/// other locked axis is locked at the value given, with a warning.
fn set_axis(m: &mut Machine, i: usize, value: f64) {
    let axis = &mut m.axes[i];
    match axis.fixed {
        Some(_) if axis.free_with_reference => axis.fixed = None,
        Some(f) if f != value => {
            note!(
                "warning: axis {} is fixed at {f} in this machine file; using {value}",
                axis.name
            );
            axis.fixed = Some(value);
        }
        _ => {}
    }
}

fn ik(
    machine: &str,
    point: &str,
    axis: &str,
    reference: Option<&str>,
    pressure: Option<f64>,
    axis_rounding: Option<f64>,
    out: &mut impl Write,
) -> Result<()> {
    let axis_rounding = axis_rounding.map(check_axis_rounding).transpose()?;
    let m = load_machine(machine)?;
    let pose = Pose {
        point: Vector3::from(parse_vector(point, "point")?),
        axis: unit_vector(axis, "axis")?,
        reference: reference.map(|r| unit_vector(r, "reference")).transpose()?,
    };
    // A reference direction frees the axes locked only without one, as it
    // does for 6-axis CL points in `post`.
    let m = if pose.reference.is_some() {
        m.with_reference_axes_free()
    } else {
        m
    };
    let mut kin = Kinematics::new(&machine_at_pressure(&m, pressure)?);
    if let Some(rad) = axis_rounding {
        kin.set_axis_rounding(rad);
    }
    let mut sols = Vec::new();
    kin.ik_all_branches(&pose, None, &mut sols)
        .map_err(|e| anyhow!("no solution: {}", kin.ik_failure(e, &pose.axis)))?;
    let names: Vec<String> = m.axes.iter().map(|a| format!("{:>12}", a.name)).collect();
    writeln!(out, "branch {}  status", names.join(""))?;
    for s in &sols {
        let values: Vec<String> = (0..m.axes.len())
            .map(|i| format!("{:>12}", fixed(s.joints[i], 6)))
            .collect();
        let status = match s.violation {
            None if s.singular => "ok (singular: a free angle kept at 0)".to_string(),
            None if s.nearest_axis => format!(
                "ok (the nearest axis the machine can point, {:.1e} rad off: CL rounding)",
                kin.axis_reach(&pose.axis).0
            ),
            None => "ok".to_string(),
            Some(v) => format!("outside travel: {}", m.axes[v.axis].name),
        };
        writeln!(out, "{:>6} {}  {status}", s.branch, values.join(""))?;
    }
    Ok(())
}

fn wheel(args: &WheelArgs) -> Result<()> {
    let mut outputs = vec![("the table", Path::new("-"))];
    if let Some(svg) = &args.svg {
        outputs.push(("--svg", svg.as_path()));
    }
    let machine_file = Path::new(&args.machine);
    let inputs: &[(&str, &Path)] = if machine_file.is_file() {
        &[("machine file", machine_file)]
    } else {
        &[]
    };
    let mut sinks = open_outputs(inputs, &outputs)?;
    let m = load_machine(&args.machine)?;
    let p = cmd_wheel::pressure_axis(&m).map_err(|e| anyhow!("{e}"))?;
    let mut pressures = args
        .pressure
        .iter()
        .map(|&v| check_pressure_value(v))
        .collect::<Result<Vec<f64>>>()?;
    if let Some(t) = &args.table {
        pressures.extend(cmd_wheel::parse_table(t).map_err(usage)?);
    }
    if pressures.is_empty() {
        pressures = cmd_wheel::default_pressures(p);
    }
    let rows = cmd_wheel::rows(&m, &pressures).map_err(|e| anyhow!("{e}"))?;
    let table = cmd_wheel::table_text(&m, &rows).map_err(|e| anyhow!("{e}"))?;
    sinks[0].write_all(table.as_bytes())?;
    if let Some(path) = &args.svg {
        let svg = cmd_wheel::svg(&m, &rows).map_err(|e| anyhow!("{e}"))?;
        sinks[1]
            .write_all(svg.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    deliver(sinks)
}

/// Today's date (UTC) as YYYY-MM-DD, from the civil-from-days algorithm
/// (H. Hinnant, "chrono-Compatible Low-Level Date Algorithms").
fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}
