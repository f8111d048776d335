//! The pipeline put together: at the program's first point (which decides
//! whether the program gives reference directions) the stages after the
//! program stage are set up for the machine as the program drives it — the
//! planner, the motion stage, the closed-loop check and the NC writer — and
//! the header is written; at its end they are closed in order and the
//! footer written.

use kinpost_machine::{Kinematics, KinematicsAtPressure, Machine, OutputMode};
use kinpost_nc::{AxisSpec, Dialect, DialectKind, ProgramInfo, TemplateKind};
use kinpost_plan::{Costs, PathPoint, Planner, SingularStretch, Trellis};

use crate::check::{Check, CheckReport, CheckSettings, Tolerance};
use crate::command::Pending;
use crate::config::{Config, FeedMode};
use crate::error::{PointError, PostError, SetupError};
use crate::motion::{MotionReport, MotionStage};
use crate::pressure::pressure_spec;
use crate::program::ProgramSink;
use crate::sink::ProgramWriter;

/// The machine's axes as a dialect writes them, then its pressure word, if
/// it has a pressure axis.
pub fn axis_specs(machine: &Machine) -> Vec<AxisSpec> {
    machine
        .axes
        .iter()
        .map(|a| AxisSpec {
            name: a.name.clone(),
            rotary: a.is_rotary(),
            fixed: a.fixed.is_some(),
            endless: a.is_endless(),
            pressure: false,
        })
        .chain(pressure_spec(machine))
        .collect()
}

/// The stages after the program stage, for one program.
struct Chain<P> {
    kin: KinematicsAtPressure,
    planner: Planner<Pending>,
    motion: MotionStage<Check<P>>,
    tcp: bool,
}

/// What the pipeline's stages after the program did, for the summary.
pub(crate) struct Closed<F> {
    /// What the program writer handed back.
    pub written: F,
    pub blocks: u64,
    pub stretches: Vec<SingularStretch>,
    pub motion: MotionReport,
    pub check: CheckReport,
}

/// The program stage's sink: the rest of the pipeline, set up at the first
/// point, writing with `P`.
pub(crate) struct Pipeline<'a, P: ProgramWriter> {
    machine: &'a Machine,
    dialect: &'a Dialect,
    config: &'a Config,
    out: Option<P::Out>,
    /// Commands before the first point: written after the header.
    pending: Vec<Pending>,
    chain: Option<Chain<P>>,
}

impl<'a, P: ProgramWriter> Pipeline<'a, P> {
    /// The pipeline of a program for `machine` in `dialect`, writing to
    /// `out`.
    pub(crate) fn new(
        machine: &'a Machine,
        dialect: &'a Dialect,
        config: &'a Config,
        out: P::Out,
    ) -> Self {
        Pipeline {
            machine,
            dialect,
            config,
            out: Some(out),
            pending: Vec::new(),
            chain: None,
        }
    }

    /// Sets the stages up for the machine as the program drives it (with
    /// reference directions, axes marked `free_with_reference` are free)
    /// and writes the header and what waited for it.
    fn set_up(&mut self, info: &ProgramInfo, six_axis: bool) -> Result<(), PostError> {
        let config = self.config;
        let machine = if six_axis {
            self.machine.with_reference_axes_free()
        } else {
            self.machine.clone()
        };
        let axes = axis_specs(&machine);
        let resolution: Vec<f64> = axes
            .iter()
            .map(|a| 10f64.powi(-i32::from(self.dialect.word_format(a).number.decimals)))
            .collect();
        let tcp = match config.output {
            OutputMode::Joint => None,
            OutputMode::Tcp => Some(tcp_axes(&machine, self.dialect)?),
        };
        let derived = match tcp {
            None => Tolerance::from_resolution(&machine, |i| resolution[i]),
            Some(_) => Tolerance::for_tcp(&machine, |i| resolution[i]),
        };
        let tolerance = Tolerance {
            position_mm: config.tolerance_mm.unwrap_or(derived.position_mm),
            ..derived
        };
        let out = self.out.take().expect("the output is taken once, here");
        let writer = self.open_writer(&axes, info, tcp.is_some(), out)?;
        // (A modulo axis reaches every angle: the kinematics sees it
        // without limits, `Axis::travel`, and takes the turn nearest the
        // previous point.)
        let mut kin = Kinematics::new(&machine);
        if let Some(rad) = config.axis_rounding_rad {
            kin.set_axis_rounding(rad);
        }
        let cone = config.singular_cone_deg;
        let costs = Costs::new(&machine, cone, kin.singularity().map(|s| s.axis));
        let planner = Planner::new(
            &machine,
            &kin,
            Trellis::new(costs, config.planner_lag),
            cone,
            &config.cl_file,
        );
        let check = Check::new(
            &machine,
            CheckSettings {
                tolerance,
                tolerance_given: config.tolerance_mm.is_some(),
                tcp,
                resolution,
            },
            writer,
        );
        let motion = MotionStage::new(&machine, &kin, config, tcp, check);
        self.chain = Some(Chain {
            kin: KinematicsAtPressure::new(&machine, kin, config.compensate_pressure),
            planner,
            motion,
            tcp: tcp.is_some(),
        });
        Ok(())
    }

    /// The NC writer, with the header and the commands that waited for it
    /// written, and tool-centre-point control on if asked for.
    fn open_writer(
        &mut self,
        axes: &[AxisSpec],
        info: &ProgramInfo,
        tcp: bool,
        out: P::Out,
    ) -> Result<P, PostError> {
        let inverse_time = self.config.feed_mode == FeedMode::InverseTime;
        let mut writer = P::open(self.dialect, axes, out);
        if inverse_time {
            writer.add_feed_mode_column();
        }
        writer.header(info, self.machine_template(&self.machine.post.header))?;
        for p in std::mem::take(&mut self.pending) {
            crate::check::BlockSink::command(&mut writer, p)?;
        }
        if tcp {
            writer.tcp(true)?;
        }
        // (Inverse time is switched on by the motion stage, at the first
        // feed block whose start is known.)
        if inverse_time
            && self.dialect.kind() != DialectKind::Csv
            && self.dialect.template(TemplateKind::InverseTimeOn).is_none()
        {
            return Err(SetupError::MissingTemplate {
                dialect: self.dialect.name().to_string(),
                template: "inverse_time_on",
                what: "write inverse-time feeds",
            }
            .into());
        }
        Ok(writer)
    }

    /// The machine's own header or footer: written for the machine's
    /// default dialect only (it is in that controller's language); other
    /// dialects use their own.
    fn machine_template<'t>(&self, template: &'t Option<String>) -> Option<&'t str> {
        match &self.machine.post.dialect {
            Some(d) if d.eq_ignore_ascii_case(self.dialect.name()) => template.as_deref(),
            _ => None,
        }
    }

    /// Decides and writes every point still waiting, closes the stages in
    /// order (inverse time off, tool-centre-point control off) and writes
    /// the footer with `info`.
    pub(crate) fn finish(self, info: &ProgramInfo) -> Result<Closed<P::Finished>, PostError> {
        let Some(mut c) = self.chain else {
            unreachable!("the program stage starts the pipeline before it ends")
        };
        c.planner.flush(&mut c.kin, &mut c.motion, true)?;
        let (check, motion) = c.motion.finish()?;
        let (mut writer, check) = check.finish();
        if c.tcp {
            writer.tcp(false)?;
        }
        let footer = match &self.machine.post.dialect {
            Some(d) if d.eq_ignore_ascii_case(self.dialect.name()) => {
                self.machine.post.footer.as_deref()
            }
            _ => None,
        };
        writer.footer(info, footer)?;
        let blocks = writer.blocks_written();
        Ok(Closed {
            written: writer.finish()?,
            blocks,
            stretches: c.planner.stretches().to_vec(),
            motion,
            check,
        })
    }
}

impl<P: ProgramWriter> ProgramSink for Pipeline<'_, P> {
    fn start(&mut self, info: &ProgramInfo, six_axis: bool) -> Result<(), PostError> {
        self.set_up(info, six_axis)
    }

    #[inline]
    fn point(&mut self, point: PathPoint, source: &[u8]) -> Result<(), PointError> {
        let Some(c) = &mut self.chain else {
            unreachable!("the program stage starts the pipeline at its first point")
        };
        c.planner
            .push_point(&mut c.kin, point, source)
            .map_err(PointError::Point)?;
        if c.planner.is_full() {
            c.planner.flush(&mut c.kin, &mut c.motion, false)?;
        }
        Ok(())
    }

    fn command(&mut self, pending: Pending) -> Result<(), PostError> {
        match &mut self.chain {
            Some(c) => c.planner.push_command(pending),
            None => self.pending.push(pending),
        }
        Ok(())
    }

    fn break_segment(&mut self) {
        if let Some(c) = &mut self.chain {
            c.planner.break_segment();
        }
    }
}

/// The linear axes named X, Y and Z, which carry the tool point in
/// tool-centre-point output; the dialect must be able to switch it on.
fn tcp_axes(machine: &Machine, dialect: &Dialect) -> Result<[usize; 3], SetupError> {
    let mut found = [usize::MAX; 3];
    for (k, name) in ["X", "Y", "Z"].into_iter().enumerate() {
        found[k] = machine
            .axes
            .iter()
            .position(|a| !a.is_rotary() && a.is_free() && a.name.eq_ignore_ascii_case(name))
            .ok_or_else(|| SetupError::TcpAxes {
                machine: machine.name.clone(),
                axis: name,
            })?;
    }
    if dialect.kind() != DialectKind::Csv && dialect.template(TemplateKind::TcpOn).is_none() {
        return Err(SetupError::MissingTemplate {
            dialect: dialect.name().to_string(),
            template: "tcp_on",
            what: "switch tool-centre-point control on",
        });
    }
    Ok(found)
}
