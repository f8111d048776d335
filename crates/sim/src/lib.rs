//! kinpost's virtual machine: an NC program, read by the interpreter of its
//! controller family (`kinpost_nc::interp`), replayed through the machine
//! file's kinematics as the controller moves it (joint-linear without
//! tool-centre-point control; under it the tool point along the programmed
//! line or arc, the linear axes solved at every sample), and checked as Qiao et al. 2022 (§4), Qi (thesis, §4.1) and
//! Zhang et al. (impeller) check their programs in VERICUT before they reach
//! the machine:
//!
//! - **overtravel**: every axis against its travel in machine coordinates
//!   (`machine_offset` applied), exactly along the block: joint-linear feed
//!   moves and rapids (each axis at its own rate) reach their extremes at
//!   their ends, arcs where they cross a quadrant; a locked axis a program
//!   moves is beyond its travel too;
//! - **run time** from the feeds (per minute, inverse time, per
//!   revolution), the rapid rates and the axes' velocity limits;
//! - **deviation from the CL** it was posted from (`--cl`): the replayed
//!   tool point and axis (forward kinematics, the wheel where the pressure
//!   word puts it on a machine with a `[pressure]` model) against the
//!   polyline of the CL's `GOTO`s, inside blocks too;
//! - **collisions** of the machine file's solids (`kinpost-collide`), swept
//!   between the block's ends, with near misses inside the warning
//!   clearance as warnings.
//!
//! ```
//! use kinpost_machine::builtin;
//! use kinpost_nc::interp::Family;
//! use kinpost_sim::{SimOptions, simulate};
//!
//! let machine = builtin::load("trunnion-ac").unwrap().unwrap();
//! let program = "G21 G90 G94\nG0 X0 Y0 Z100 A0 C0\nG1 X50 F1000\nG1 A30\nG1 A200\nM2\n";
//! let options = SimOptions { collisions: false, ..SimOptions::default() };
//! let report = simulate(program, Family::LinuxCnc, "p.ngc", &machine, &options, None, &mut |_| {}).unwrap();
//! assert_eq!(report.blocks, 4);
//! // X50 at 1000 mm/min takes 3 s.
//! assert!(report.duration_s >= 3.0);
//! // A200 is beyond the A travel of the trunnion, in line 5 only.
//! assert!(report.overtravel.iter().all(|o| o.axis == "A" && o.at.line == 5));
//! assert!(report.violated());
//! ```

#![deny(missing_docs)]

pub mod cl;
mod collide;
pub mod path;
mod removal;
mod replay;
pub mod report;
pub mod tolerance;

use kinpost_diag::Diagnostic;
use kinpost_machine::Machine;
use kinpost_nc::interp::{self, Family, Options, Step};

pub use cl::ClPath;
pub use removal::Cutting;
pub use replay::Replay;
pub use report::{
    At, ClComparison, Contact, Deviation, Overtravel, Removal, SimReport, SingularPassage,
};

/// Why a program cannot be replayed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// The program cannot be read (the interpreter's located diagnostic).
    #[error("{0}")]
    Program(Diagnostic),
    /// The CL file cannot be read.
    #[error("{0}")]
    Cl(Diagnostic),
    /// A `CIRCLE` of the CL that makes no arc from the point before it to
    /// the `GOTO` after it.
    #[error("CL line {line}: {source}")]
    ClArc {
        /// CL line of the `CIRCLE`.
        line: usize,
        /// Why.
        source: kinpost_cl::ArcError,
    },
    /// A `CIRCLE` of the CL too large to sample at the comparison's chord.
    #[error("CL line {line}: {source}")]
    ClArcSampling {
        /// CL line of the `CIRCLE`.
        line: usize,
        /// Why.
        source: kinpost_cl::SampleError,
    },
    /// A canned cycle of the CL whose holes cannot be expanded.
    #[error("CL line {line}: {source}")]
    ClCycle {
        /// CL line of the `CYCLE`.
        line: usize,
        /// Why.
        source: kinpost_post::cycle::CycleError,
    },
    /// A CL motion the comparison cannot follow (it would compare the
    /// program with a wrong path).
    #[error(
        "CL line {line}: {what}: the comparison with the CL follows GOTOs, CIRCLEs and canned cycles only (run without --cl to check travel and collisions)"
    )]
    ClNotCompared {
        /// CL line.
        line: usize,
        /// What the statement is.
        what: &'static str,
    },
    /// The CL file has no `GOTO`.
    #[error("the CL file {0} has no GOTO to compare the program with")]
    EmptyCl(String),
    /// The CL's path (its points, arcs as chords, holes as moves) is
    /// longer than the comparison holds in memory.
    #[error(
        "CL line {line}: the CL's path has more than {max} points (arcs as chords of 1e-5 mm, holes as their moves): too long to compare with"
    )]
    ClTooLong {
        /// The CL line that went past it.
        line: usize,
        /// [`cl::MAX_CL_PATH_POINTS`].
        max: usize,
    },
    /// The machine's solids cannot be built.
    #[error("the machine's solids: {0}")]
    Solids(#[from] kinpost_collide::BuildError),
    /// A block under tool-centre-point control on a machine without
    /// linear X, Y and Z axes to move the tool point.
    #[error(
        "line {line}: tool-centre-point control is on (TRAORI, G43.4, M128, …), but the machine has no free linear X, Y and Z axes to move the tool point"
    )]
    TcpAxes {
        /// NC line.
        line: usize,
    },
    /// A tool point under tool-centre-point control that the linear axes
    /// cannot reach at the block's rotary values (they do not span space).
    #[error(
        "line {line}: under tool-centre-point control the linear axes cannot put the tool point where the block asks at its rotary values"
    )]
    TcpUnsolvable {
        /// NC line.
        line: usize,
    },
    /// An arc in a plane whose linear axes the machine lacks.
    #[error("line {line}: an arc in a plane whose X, Y and Z axes the machine does not all have")]
    ArcPlane {
        /// NC line.
        line: usize,
    },
    /// The tool cannot cut the stock along a block (an invalid pose, a
    /// wheel without its reference direction, a move too long to sample).
    #[error("line {line}: material removal: {source}")]
    Cut {
        /// NC line.
        line: usize,
        /// Why.
        source: kinpost_stock::CutError,
    },
    /// The process model cannot grind a block.
    #[error("line {line}: the grinding process model: {source}")]
    Grind {
        /// NC line.
        line: usize,
        /// Why.
        source: kinpost_stock::ProcessError,
    },
    /// A feed block ground with the process model before any pressure
    /// word set the force.
    #[error(
        "line {line}: the grinding process model needs the force, and no `{word}` word has set it yet"
    )]
    NoPressure {
        /// NC line.
        line: usize,
        /// The pressure word.
        word: String,
    },
    /// More axes than the interpreter handles.
    #[error("the machine has {0} axes; the replay handles at most 12")]
    TooManyAxes(usize),
}

impl SimError {
    /// The located diagnostic, for an error in the program or the CL file.
    pub fn diagnostic(&self) -> Option<&Diagnostic> {
        match self {
            SimError::Program(d) | SimError::Cl(d) => Some(d),
            _ => None,
        }
    }
}

/// The M-codes that switch tool-centre-point control on and off in a
/// LinuxCNC program when the options give none (`Options::tcp_mcodes`).
pub const LINUXCNC_TCP_MCODES: (u32, u32) = (428, 429);

/// Options of a replay.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOptions {
    /// The interpreter's options (inputs, start position, work offsets).
    /// Without a start, the machine starts at its home (locked axes at
    /// their value, the others at 0).
    pub interp: Options,
    /// The pressure word moves the wheel as the machine's `[pressure]`
    /// model says (true), or the wheel stays where it is at the reference
    /// pressure (false: `--no-pressure-offset`, the machine maker's
    /// assumption).
    pub pressure_offset: bool,
    /// Check the machine file's solids for collisions.
    pub collisions: bool,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            interp: Options::default(),
            pressure_offset: true,
            collisions: true,
        }
    }
}

/// Replays the program `text` of `family` (`file` names it in
/// diagnostics) on `machine`, compared with `cl` when given; `on_step` sees
/// every step the interpreter produced (e.g. for a block table).
pub fn simulate(
    text: &str,
    family: Family,
    file: &str,
    machine: &Machine,
    options: &SimOptions,
    cl: Option<ClPath>,
    on_step: &mut dyn FnMut(&Step),
) -> Result<SimReport, SimError> {
    simulate_cutting(text, family, file, machine, options, cl, None, on_step).map(|(r, _)| r)
}

/// [`simulate`], removing material from `cutting`'s stock along the way
/// when given: the stock as cut comes back with the report (whose
/// `removal` the caller completes, e.g. with the comparison with the
/// design).
#[allow(clippy::too_many_arguments)]
pub fn simulate_cutting(
    text: &str,
    family: Family,
    file: &str,
    machine: &Machine,
    options: &SimOptions,
    cl: Option<ClPath>,
    cutting: Option<Cutting>,
    on_step: &mut dyn FnMut(&Step),
) -> Result<(SimReport, Option<Cutting>), SimError> {
    let axes = kinpost_post::axis_specs(machine);
    let mut options = options.clone();
    if options.interp.start.is_none() {
        let mut start = replay::start_joints(machine, &options);
        start.resize(axes.len(), 0.0);
        options.interp.start = Some(start);
    }
    // LinuxCNC has no TCP G-code of its own: its 5-axis sample
    // configurations remap M428/M429, and kinpost's linuxcnc dialect writes
    // them.
    let remapped_tcp = family == Family::LinuxCnc && options.interp.tcp_mcodes.is_none();
    if remapped_tcp {
        options.interp.tcp_mcodes = Some(LINUXCNC_TCP_MCODES);
    }
    let mut tcp_seen = false;
    let mut replay = Replay::new(machine, &options, cl)?;
    if let Some(c) = cutting {
        replay = replay.with_cutting(c);
    }
    let report = interp::run(
        text,
        family,
        &axes,
        &options.interp,
        file,
        &mut |s: &Step| {
            tcp_seen |= s.event == interp::Event::Tcp(true);
            on_step(s);
            replay.step(s);
        },
    )
    .map_err(SimError::Program)?;
    let (mut report, cutting) = replay.finish_cutting(&report)?;
    if remapped_tcp && tcp_seen {
        report.assumed.push(
            "M428 switches tool-centre-point control on and M429 off (the remap of LinuxCNC's 5-axis sample configurations, which kinpost's linuxcnc dialect writes)".to_string(),
        );
    }
    Ok((report, cutting))
}
