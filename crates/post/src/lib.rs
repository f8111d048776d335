//! kinpost's post-processor as a library: CL data (NX CLSF / APT) to an NC
//! program for one machine, through one-way stages, every block proven by
//! the forward kinematics before it is written.
//!
//! # The stages
//!
//! Each stage hands its output to the next through a sink trait that the
//! next stage implements (the model is ripgrep's `Sink` between searcher
//! and printer); no stage knows the one after it.
//!
//! 1. **CL reader** ([`cl`]): the file as statements, one at a time.
//! 2. **Program** ([`program::Program`] → [`program::ProgramSink`]): the
//!    CL's modal state (units, feed, spindle, tool, pressure); every `GOTO`
//!    becomes a tool pose in the part frame with its feed and pressure
//!    (a `CIRCLE` arc or a `NURBS` the poses along it within the
//!    linearization tolerance, a hole of a canned cycle the moves of
//!    [`cycle`]), every other statement that speaks to the controller a
//!    [`Command`] (stops, dwells, cutter compensation among them).
//! 3. **Planner** ([`plan::Planner`] → [`plan::PlanSink`]): every
//!    inverse-kinematics solution of every point, the configuration of each
//!    decided over the whole path (branches, turns, singular runs, folds).
//! 4. **Motion** ([`motion::MotionStage`] → [`motion::MotionSink`]): blocks
//!    inserted for linearization, retract-and-reconfigure, the pressure
//!    re-approach, feed words.
//! 5. **Closed-loop check** ([`check::Check`] → [`check::BlockSink`]):
//!    every block rounded as the sink writes it, run through the forward
//!    kinematics and compared with its target; only a block that passes is
//!    handed on. The blocks of a CL arc are held back and written as one
//!    circular block where the machine can and the block as written lies on
//!    the CL arc ([`native_arc`], `--arcs`), else as they are; so are the
//!    blocks of a hole of a canned cycle, written as the dialect's cycle
//!    where they are exactly its moves ([`native_cycle`], `--cycles`).
//! 6. **Block sink**: the NC writer of a dialect ([`nc`]), or a
//!    [`Recorded`] list in tests; [`ReadBack`] re-reads what a writer wrote
//!    and compares it with what it was given.
//!
//! [`post`] runs them all; [`Config::resolve`] settles every setting in one
//! place first (option, machine file, dialect, default).
//!
//! ```
//! use kinpost_post::{post, PostOptions};
//! let machine = kinpost_post::machine::builtin::load("mts1600").unwrap().unwrap();
//! let dialect = kinpost_post::nc::Dialect::builtin("csv").unwrap();
//! let cl = "RAPID\nGOTO/-416,70.5,16.53,0,0,1\nFEDRAT/MMPM,250\nGOTO/-416,70.3931,11.3684\n";
//! let mut nc = Vec::new();
//! let options = PostOptions { cl_file: "flat.cls".into(), ..Default::default() };
//! let summary = post(cl.as_bytes(), &machine, &dialect, &mut nc, &options).unwrap();
//! assert_eq!(summary.blocks, 2);
//! assert!(summary.max_position_error_mm < summary.tolerance_mm);
//! ```

#![deny(missing_docs)]

pub mod check;
mod command;
pub mod config;
pub mod cycle;
mod error;
mod machine_templates;
pub mod motion;
pub mod native_arc;
pub mod native_cycle;
mod pressure;
pub mod program;
mod readback;
mod setup;
mod sink;
pub mod summary;

use std::io::{BufRead, Write};
use std::time::Instant;

use kinpost_cl::ClReader;
use kinpost_diag::Diagnostic;
use kinpost_machine::Machine;
use kinpost_nc::{Dialect, NcWriter};

pub use command::{Command, Pending};
pub use config::{
    ArcMode, Config, CycleMode, FeedMode, FrameMode, InsertMode, PLANNER_LAG, PlannerMode,
    PostOptions,
};
pub use error::{
    CheckError, ConfigError, LinearizationFailure, MotionError, MotionWarning, PointError,
    PostError, PressureError, PressureWarning, ProgramError, SetupError,
};
pub use kinpost_cl as cl;
pub use kinpost_diag as diag;
pub use kinpost_machine as machine;
pub use kinpost_machine::tolerance::{
    DEFAULT_LINTOL_MM, DEFAULT_RETRACT_MM, DEFAULT_SINGULAR_CONE_DEG,
};
pub use kinpost_nc as nc;
pub use kinpost_plan as plan;
pub use machine_templates::check_machine_templates;
pub use readback::{ReadBack, ReadBackError, compare_read_back};
pub use setup::axis_specs;
pub use sink::{Event, Recorded};
pub use summary::Summary;

use pressure::check_pressure;
use program::Program;
use setup::Pipeline;
use sink::ProgramWriter;
use summary::Planning;

/// Posts the CL text read from `input` for `machine` in `dialect`, writing
/// the program to `out`. Returns the summary; on error nothing more is
/// written and the caller discards `out`. `options` are resolved first
/// ([`Config::resolve`]): a value out of range is [`PostError::Config`].
pub fn post<R: BufRead, W: Write>(
    input: R,
    machine: &Machine,
    dialect: &Dialect,
    out: W,
    options: &PostOptions,
) -> Result<Summary, PostError> {
    let config = Config::resolve(options, machine, dialect)?;
    post_with(input, machine, dialect, out, &config)
}

/// [`post`] with the settings resolved already.
pub fn post_with<R: BufRead, W: Write>(
    input: R,
    machine: &Machine,
    dialect: &Dialect,
    out: W,
    config: &Config,
) -> Result<Summary, PostError> {
    run::<R, NcWriter<W>>(input, machine, dialect, out, config).map(|(summary, _)| summary)
}

/// [`post`], the program read back as written with the dialect's reader at
/// its end ([`ReadBack`]): the output and the summary, or why the program
/// does not read back as it was written.
pub fn post_read_back<R: BufRead, W: Write>(
    input: R,
    machine: &Machine,
    dialect: &Dialect,
    out: W,
    options: &PostOptions,
) -> Result<(Result<W, ReadBackError>, Summary), PostError> {
    let config = Config::resolve(options, machine, dialect)?;
    run::<R, ReadBack<W>>(input, machine, dialect, out, &config)
        .map(|(summary, written)| (written, summary))
}

/// The pipeline, writing with `P`.
fn run<R: BufRead, P: ProgramWriter>(
    input: R,
    machine: &Machine,
    dialect: &Dialect,
    out: P::Out,
    config: &Config,
) -> Result<(Summary, P::Finished), PostError> {
    let started = Instant::now();
    let mut reader = ClReader::new(input, config.cl_file.clone()).with_units(config.units);
    if let Some(axis) = config.default_axis {
        reader = reader.with_default_axis(axis);
    }
    let (warnings, uncompensated) = option_pressure(machine, dialect, config)?;
    let mut program = Program::new(machine, dialect, config, warnings);
    if let Some(p) = config.pressure {
        program.note_option_pressure(p, uncompensated);
    }
    let mut pipeline = Pipeline::<P>::new(machine, dialect, config, out);
    let read = program.run(&mut reader, &mut pipeline)?;
    let mut closed = pipeline.finish(&read.info)?;
    let mut warnings = read.warnings;
    warnings.append(&mut closed.motion.warnings);
    if read.cl_points == 0 {
        warnings.push(Diagnostic::warning(
            &config.cl_file,
            0,
            0,
            0,
            "",
            "the CL file has no motion (no GOTO): the program is its header and footer only"
                .to_string(),
        ));
    }
    warnings.extend(reader.take_warnings());
    warnings.sort_by_key(|w| (w.line, w.column));
    let check = closed.check;
    let summary = Summary {
        cl_points: read.cl_points,
        blocks: closed.blocks,
        warnings,
        max_position_error_mm: check.stats.max_position_error_mm,
        max_position_error_line: check.stats.worst_line,
        max_axis_error_rad: check.stats.max_axis_error_rad,
        tolerance_mm: check.tolerance.position_mm,
        tolerance_rad: check.tolerance.axis_rad,
        seconds: started.elapsed().as_secs_f64(),
        planning: Planning::of(closed.stretches, closed.motion, &check),
    };
    Ok((summary, closed.written))
}

/// The warnings of `--pressure`, and whether it is uncompensated; an error
/// where it cannot be programmed at all.
fn option_pressure(
    machine: &Machine,
    dialect: &Dialect,
    config: &Config,
) -> Result<(Vec<Diagnostic>, bool), PostError> {
    let Some(value) = config.pressure else {
        return Ok((Vec::new(), false));
    };
    let check = check_pressure(
        machine,
        dialect,
        config.output,
        config.compensate_pressure,
        value,
    )
    .map_err(error::SetupError::from)?;
    let warnings = check
        .warnings
        .into_iter()
        .map(|w| Diagnostic::warning(&config.cl_file, 0, 0, 0, "", format!("--pressure: {w}")))
        .collect();
    Ok((warnings, check.uncompensated))
}
