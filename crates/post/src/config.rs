//! What a caller asks of a post run ([`PostOptions`]) and what the run does
//! ([`Config`]): every setting resolved in one place, the option first, then
//! the machine file's `[post]`, then the dialect, then the default, and
//! every value out of range an error here.

use kinpost_machine::{MAX_AXIS_ROUNDING_RAD, Machine, OutputMode};
use kinpost_nc::Dialect;

use crate::error::ConfigError;
use kinpost_machine::tolerance::{
    DEFAULT_LINTOL_MM, DEFAULT_RETRACT_MM, DEFAULT_SINGULAR_CONE_DEG,
};

/// Points the whole-path planner looks ahead at most before it decides.
pub const PLANNER_LAG: usize = 1 << 15;

/// Settings of one post run, as a caller (the command line) gives them:
/// `None` takes the machine's, the dialect's or the default value.
#[derive(Debug, Clone, Default)]
pub struct PostOptions {
    /// Name of the CL input, for diagnostics and the header (`-` for stdin).
    pub cl_file: String,
    /// Program name for the header; default: the CL `PARTNO`, else the first
    /// `TOOL PATH` name, else the CL file stem.
    pub program_name: Option<String>,
    /// Date written by the header template; empty by default so that the same
    /// input gives the same bytes.
    pub date: String,
    /// Closed-loop tolerance in mm replacing the derived one.
    pub tolerance_mm: Option<f64>,
    /// Tool axis for `GOTO/x,y,z` before any axis is given (3-axis APT).
    pub default_axis: Option<[f64; 3]>,
    /// The CL file's length units when it does not say (`--units`).
    pub units: Option<kinpost_cl::Units>,
    /// What a CL `INSERT` becomes (`--insert`).
    pub insert: InsertMode,
    /// How a CL `CIRCLE`'s arc is written (`--arcs`).
    pub arcs: ArcMode,
    /// How the holes of a CL `CYCLE` are written (`--cycles`).
    pub cycles: CycleMode,
    /// The frame the points are posted in (`--frame`).
    pub frame: FrameMode,
    /// Joint or tool-centre-point output; default: the machine's (`[post]
    /// output`), else joint.
    pub output: Option<OutputMode>,
    /// How feed words are written; default: the dialect's.
    pub feed_mode: Option<FeedMode>,
    /// Whole-path or point-by-point choice of configurations.
    pub planner: PlannerMode,
    /// Linearization tolerance, mm (default [`DEFAULT_LINTOL_MM`]; 0: off).
    pub lintol_mm: Option<f64>,
    /// Singular cone half-angle, degrees (default: the machine's, else
    /// [`DEFAULT_SINGULAR_CONE_DEG`]).
    pub singular_cone_deg: Option<f64>,
    /// Retract distance of a reconfiguration, mm (default: the machine's,
    /// else [`DEFAULT_RETRACT_MM`]).
    pub retract_mm: Option<f64>,
    /// Fail instead of retracting and reconfiguring.
    pub no_reconfigure: bool,
    /// The pressure for CL points before any `PRESSURE` statement (machines
    /// with a pressure axis); without it and without `PRESSURE`, none is
    /// written and the reference pressure applies.
    pub pressure: Option<f64>,
    /// Write the pressure words but solve every block at the reference
    /// pressure, as the machine maker's post does (for comparison).
    pub no_pressure_compensation: bool,
    /// How far outside the directions the machine can point a CL tool axis
    /// may lie and be solved at the nearest one, radians (default
    /// [`AXIS_ROUNDING_RAD`](kinpost_machine::AXIS_ROUNDING_RAD), the
    /// rounding of 6 decimals; at most [`MAX_AXIS_ROUNDING_RAD`]): for a CL
    /// that writes its tool axes with fewer decimals.
    pub axis_rounding_rad: Option<f64>,
}

/// How the configuration of each point is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlannerMode {
    /// Over the whole path (dynamic programming over up to
    /// [`PLANNER_LAG`] points at a time).
    #[default]
    Global,
    /// Point by point: least motion from the previous block.
    Nearest,
}

/// What the post writes for a CL `INSERT`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InsertMode {
    /// The text as code, as the APT standard says (a line that would move
    /// an axis or change a tool gives a warning naming its CL line).
    #[default]
    Verbatim,
    /// The text as a comment (SOLIDWORKS CAM writes tool and stock notes as
    /// `INSERT`).
    Comment,
    /// Nothing (the user's choice).
    Drop,
}

/// How the arc of a CL `CIRCLE` is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ArcMode {
    /// One circular block (G2/G3) where the arc lies in a plane of the
    /// machine at constant rotary axes, the dialect has `[arc]` words and
    /// the output is joint output; lines within `--lintol` elsewhere.
    #[default]
    Native,
    /// Lines within `--lintol` everywhere.
    Linear,
}

/// How the holes of a CL `CYCLE` are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CycleMode {
    /// The dialect's canned cycle (`G81`…, `MCALL CYCLE81`, `CYCL DEF
    /// 200`) where the checked moves of a hole are exactly what the cycle
    /// does on the program's Z (see [`crate::native_cycle`]) and the
    /// dialect writes the kind (`[cycle]`); the moves elsewhere.
    #[default]
    Native,
    /// The moves of every hole (rapids, feeds, dwells, spindle reversals).
    Expand,
}

/// The frame the CL's points are posted in: what an NX `MSYS` means for
/// the program (ICAM's MSYS vocabulary: the `GOTO`s that follow are given
/// in the machine coordinate system it places in the part's absolute
/// frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FrameMode {
    /// As written, in the MCS: the machine file's part frame is the MCS,
    /// which the shop's work offset (G54…) locates on the machine. A
    /// later `MSYS` that moves the MCS is an error (a program per setup).
    #[default]
    Mcs,
    /// In the CAM model's absolute frame: every point, axis and circle
    /// after an `MSYS` is mapped out of its MCS, so that a file of several
    /// setups posts in one frame (the machine file's part frame is then the
    /// absolute one).
    Absolute,
}

/// What the feed word of a feed block means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FeedMode {
    /// The CL feed rate, mm/min at the tool (contact) point.
    #[default]
    Tip,
    /// Inverse time (`G93`): F = 1 / block time in minutes, the block time
    /// being the CL segment length over the CL feed rate. A block that does
    /// not move the tool point but turns rotary axes takes its largest
    /// rotary change in degrees over the feed rate (degrees per minute).
    InverseTime,
    /// Degrees per minute, the combined feed of a controller without
    /// inverse time: F = length of the vector of every axis change (mm and
    /// degrees together) / block time.
    Dpm,
}

impl FeedMode {
    /// `tip`, `inverse-time` or `dpm`.
    pub fn parse(name: &str) -> Option<FeedMode> {
        match name {
            "tip" => Some(FeedMode::Tip),
            "inverse-time" => Some(FeedMode::InverseTime),
            "dpm" => Some(FeedMode::Dpm),
            _ => None,
        }
    }
}

/// The settings of a post run, resolved and checked.
#[derive(Debug, Clone)]
pub struct Config {
    /// Name of the CL input.
    pub cl_file: String,
    /// Program name given by the caller (else the CL names it).
    pub program_name: Option<String>,
    /// Date for the header.
    pub date: String,
    /// Closed-loop position tolerance given by the caller, mm (else
    /// derived from the output decimals).
    pub tolerance_mm: Option<f64>,
    /// Tool axis of `GOTO/x,y,z` before any axis is given.
    pub default_axis: Option<[f64; 3]>,
    /// The CL file's length units when it does not say.
    pub units: Option<kinpost_cl::Units>,
    /// What a CL `INSERT` becomes.
    pub insert: InsertMode,
    /// How arcs are written.
    pub arcs: ArcMode,
    /// How the holes of canned cycles are written.
    pub cycles: CycleMode,
    /// The frame the points are posted in.
    pub frame: FrameMode,
    /// Joint or tool-centre-point output.
    pub output: OutputMode,
    /// What the feed words mean.
    pub feed_mode: FeedMode,
    /// Points the planner looks ahead (1: point by point).
    pub planner_lag: usize,
    /// Linearization tolerance, mm (0: off).
    pub lintol_mm: f64,
    /// Singular cone half-angle, degrees.
    pub singular_cone_deg: f64,
    /// Retract distance of a reconfiguration, mm.
    pub retract_mm: f64,
    /// Retract and reconfigure where the travel forces a flip (else fail).
    pub reconfigure: bool,
    /// Pressure before the first `PRESSURE`, if any.
    pub pressure: Option<f64>,
    /// Solve every block with the wheel at its pressure.
    pub compensate_pressure: bool,
    /// Axis rounding, radians, if given.
    pub axis_rounding_rad: Option<f64>,
}

/// A value that must be finite and within `ok`, or the error.
fn checked(
    value: Option<f64>,
    ok: impl Fn(f64) -> bool,
    option: &'static str,
    must: &'static str,
) -> Result<Option<f64>, ConfigError> {
    match value {
        Some(v) if !(v.is_finite() && ok(v)) => Err(ConfigError::OutOfRange { option, must }),
        v => Ok(v),
    }
}

impl Config {
    /// `options` resolved against the machine's `[post]` settings and the
    /// dialect: an option given wins, then the machine file, then the
    /// dialect, then the default. Every value out of range is an error.
    pub fn resolve(
        options: &PostOptions,
        machine: &Machine,
        dialect: &Dialect,
    ) -> Result<Config, ConfigError> {
        let pressure = checked(
            options.pressure,
            |v| v >= 0.0,
            "--pressure",
            "a number not below 0",
        )?;
        if let Some(r) = options.axis_rounding_rad
            && !(r.is_finite() && (0.0..=MAX_AXIS_ROUNDING_RAD).contains(&r))
        {
            return Err(ConfigError::AxisRounding {
                max_rad: MAX_AXIS_ROUNDING_RAD,
            });
        }
        let lintol = checked(
            options.lintol_mm,
            |v| v >= 0.0,
            "--lintol",
            "a distance of 0 or more (mm)",
        )?;
        let cone = checked(
            options.singular_cone_deg,
            |v| (0.0..45.0).contains(&v),
            "--singular-cone",
            "an angle from 0 to less than 45 degrees",
        )?;
        let retract = checked(
            options.retract_mm,
            |v| v > 0.0,
            "--retract",
            "a distance greater than zero (mm)",
        )?;
        let tolerance = checked(
            options.tolerance_mm,
            |v| v > 0.0,
            "--tolerance",
            "a positive number of mm",
        )?;
        Ok(Config {
            cl_file: options.cl_file.clone(),
            program_name: options.program_name.clone(),
            date: options.date.clone(),
            tolerance_mm: tolerance,
            default_axis: options.default_axis,
            units: options.units,
            insert: options.insert,
            arcs: options.arcs,
            cycles: options.cycles,
            frame: options.frame,
            output: options.output.or(machine.post.output).unwrap_or_default(),
            feed_mode: options
                .feed_mode
                .or(dialect.default_feed_mode().and_then(FeedMode::parse))
                .unwrap_or_default(),
            planner_lag: match options.planner {
                PlannerMode::Global => PLANNER_LAG,
                PlannerMode::Nearest => 1,
            },
            lintol_mm: lintol.unwrap_or(DEFAULT_LINTOL_MM),
            singular_cone_deg: cone
                .or(machine.post.singular_cone_deg)
                .unwrap_or(DEFAULT_SINGULAR_CONE_DEG),
            retract_mm: retract
                .or(machine.post.retract)
                .unwrap_or(DEFAULT_RETRACT_MM),
            reconfigure: !options.no_reconfigure,
            pressure,
            compensate_pressure: !options.no_pressure_compensation,
            axis_rounding_rad: options.axis_rounding_rad,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinpost_machine::builtin;

    fn resolve(options: PostOptions) -> Result<Config, ConfigError> {
        let m = builtin::load("mts1600").unwrap().unwrap();
        Config::resolve(&options, &m, &Dialect::builtin("sinumerik").unwrap())
    }

    #[test]
    fn an_option_wins_over_the_default() {
        let c = resolve(PostOptions::default()).unwrap();
        assert_eq!(c.lintol_mm, DEFAULT_LINTOL_MM);
        assert_eq!(c.retract_mm, DEFAULT_RETRACT_MM);
        assert_eq!(c.singular_cone_deg, DEFAULT_SINGULAR_CONE_DEG);
        let c = resolve(PostOptions {
            lintol_mm: Some(0.01),
            retract_mm: Some(20.0),
            singular_cone_deg: Some(2.0),
            planner: PlannerMode::Nearest,
            ..Default::default()
        })
        .unwrap();
        assert_eq!(
            (c.lintol_mm, c.retract_mm, c.singular_cone_deg),
            (0.01, 20.0, 2.0)
        );
        assert_eq!(c.planner_lag, 1);
    }

    #[test]
    fn the_machine_wins_over_the_default_and_the_dialect_gives_the_feed_mode() {
        let mut m = builtin::load("mts1600").unwrap().unwrap();
        m.post.retract = Some(12.0);
        m.post.output = Some(OutputMode::Tcp);
        let mut d = Dialect::builtin("linuxcnc").unwrap();
        let c = Config::resolve(&PostOptions::default(), &m, &d).unwrap();
        assert_eq!((c.retract_mm, c.output), (12.0, OutputMode::Tcp));
        let given = PostOptions {
            output: Some(OutputMode::Joint),
            ..Default::default()
        };
        assert_eq!(
            Config::resolve(&given, &m, &d).unwrap().output,
            OutputMode::Joint
        );
        d = Dialect::builtin("csv").unwrap();
        assert_eq!(
            Config::resolve(&given, &m, &d).unwrap().feed_mode,
            FeedMode::Tip
        );
    }

    #[test]
    fn values_out_of_range_are_errors() {
        for (options, option) in [
            (
                PostOptions {
                    lintol_mm: Some(-1.0),
                    ..Default::default()
                },
                "--lintol",
            ),
            (
                PostOptions {
                    lintol_mm: Some(f64::NAN),
                    ..Default::default()
                },
                "--lintol",
            ),
            (
                PostOptions {
                    singular_cone_deg: Some(45.0),
                    ..Default::default()
                },
                "--singular-cone",
            ),
            (
                PostOptions {
                    retract_mm: Some(0.0),
                    ..Default::default()
                },
                "--retract",
            ),
            (
                PostOptions {
                    tolerance_mm: Some(0.0),
                    ..Default::default()
                },
                "--tolerance",
            ),
            (
                PostOptions {
                    pressure: Some(-3.0),
                    ..Default::default()
                },
                "--pressure",
            ),
        ] {
            match resolve(options) {
                Err(ConfigError::OutOfRange { option: o, .. }) => assert_eq!(o, option),
                other => panic!("{option}: {other:?}"),
            }
        }
        let coarse = PostOptions {
            axis_rounding_rad: Some(1e-2),
            ..Default::default()
        };
        assert!(matches!(
            resolve(coarse),
            Err(ConfigError::AxisRounding { .. })
        ));
    }
}
