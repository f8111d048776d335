//! Feed words: the block time from the CL segment and the CL feed rate,
//! slowed down where an axis would exceed its maximum velocity, and said in
//! the feed mode's terms (at the tool point, inverse time, or the combined
//! feed of every axis).

use kinpost_machine::tolerance::{FAST_TURN_DEG_PER_MIN, NO_MOVE, PURE_TURN_MM, VMAX_SLACK};
use kinpost_machine::{Joints, Machine};
use kinpost_plan::Node;
use serde::Serialize;

use crate::config::FeedMode;
use crate::error::MotionWarning;

/// At most this many feed clamps are listed (all are counted).
const MAX_CLAMPS_LISTED: usize = 1000;

/// A feed block slowed down by an axis's maximum velocity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeedClamp {
    /// CL line of the block (an inserted block gives the line it leads to).
    pub line: usize,
    /// The axis that limits the block.
    pub axis: String,
    /// Block time as programmed, minutes.
    pub programmed_min: f64,
    /// Block time as written, minutes.
    pub written_min: f64,
}

/// The block a feed word is for: where it goes, from where.
pub(crate) struct FeedMove<'a> {
    /// The node it reaches and the values written for it.
    pub node: &'a Node,
    pub values: &'a Joints,
    /// The node and values of the block before.
    pub from: &'a Node,
    pub from_values: &'a Joints,
    /// Its CL line.
    pub line: usize,
}

/// The feed words of a program.
pub(crate) struct Feeds {
    pub(crate) mode: FeedMode,
    n: usize,
    /// Free rotary axes.
    rotary: Vec<usize>,
    /// Axes with a maximum velocity (index, units per minute).
    vmax: Vec<(usize, f64)>,
    names: Vec<String>,
    /// Rotary axes without a maximum velocity already warned about.
    fast_warned: Vec<usize>,
    /// Blocks slowed down to a maximum velocity (the first
    /// [`MAX_CLAMPS_LISTED`]), and how many there were.
    pub(crate) clamps: Vec<FeedClamp>,
    pub(crate) clamp_count: u64,
}

impl Feeds {
    /// The feed words of `machine`'s programs in `mode`.
    pub(crate) fn new(machine: &Machine, mode: FeedMode) -> Feeds {
        let axes = &machine.axes;
        Feeds {
            mode,
            n: axes.len(),
            rotary: machine.free_rotary_axes().collect(),
            vmax: (0..axes.len())
                .filter(|&i| axes[i].is_free())
                .filter_map(|i| axes[i].max_velocity.map(|v| (i, v)))
                .collect(),
            names: axes.iter().map(|a| a.name.clone()).collect(),
            fast_warned: Vec::new(),
            clamps: Vec::new(),
            clamp_count: 0,
        }
    }

    /// Whether the feed word is the CL feed rate whatever the block (at the
    /// tool point, with no maximum velocity to hold a block to).
    #[inline]
    pub(crate) fn is_cl_feed(&self) -> bool {
        self.mode == FeedMode::Tip && self.vmax.is_empty()
    }

    /// The feed word of a feed block at CL feed rate `feed` (mm/min): the
    /// block time is the CL segment length over the feed rate (a block that
    /// only turns rotary axes takes its largest rotary change in degrees
    /// over the feed rate), slowed down where an axis would exceed its
    /// maximum velocity; the word says that time in the feed mode's terms.
    /// A rotary axis asked to turn implausibly fast is a warning (once per
    /// axis), returned with the word.
    pub(crate) fn word(&mut self, feed: f64, m: &FeedMove) -> (f64, Option<MotionWarning>) {
        let length = (m.node.pose.point - m.from.pose.point).norm();
        let turn = self
            .rotary
            .iter()
            .map(|&i| (m.node.joints[i] - m.from.joints[i]).abs())
            .fold(0.0, f64::max);
        // A tool point that moves less than 1 µm (for every dialect alike)
        // does not move: the block only turns, and takes its largest rotary
        // change in degrees over the feed rate taken as degrees per minute.
        // (Its length instead would make the block an instant: F without
        // bound where F is the block time.)
        let distance = if length >= PURE_TURN_MM { length } else { turn };
        if distance <= NO_MOVE || feed <= 0.0 {
            return (feed, None);
        }
        let programmed = distance / feed;
        let time = self.slowed(programmed, m);
        let warning = if self.mode != FeedMode::Tip {
            self.fast_turn(time, m)
        } else {
            None
        };
        let word = match self.mode {
            FeedMode::Tip => feed * programmed / time,
            FeedMode::InverseTime => 1.0 / time,
            FeedMode::Dpm => {
                // The controller moves the vector of every axis (mm and
                // degrees together) at F: F = its length / block time.
                let d2: f64 = (0..self.n)
                    .map(|i| (m.values[i] - m.from_values[i]).powi(2))
                    .sum();
                if d2 > 0.0 { d2.sqrt() / time } else { feed }
            }
        };
        (word, warning)
    }

    /// The block time, minutes: `programmed`, or longer where an axis with
    /// a maximum velocity needs longer (the clamp is recorded).
    fn slowed(&mut self, programmed: f64, m: &FeedMove) -> f64 {
        let mut time = programmed;
        let mut limiting = None;
        for &(i, v) in &self.vmax {
            let need = (m.values[i] - m.from_values[i]).abs() / v;
            if need > time * (1.0 + VMAX_SLACK) {
                time = need;
                limiting = Some(i);
            }
        }
        if let Some(i) = limiting {
            self.clamp_count += 1;
            if self.clamps.len() < MAX_CLAMPS_LISTED {
                self.clamps.push(FeedClamp {
                    line: m.line,
                    axis: self.names[i].clone(),
                    programmed_min: programmed,
                    written_min: time,
                });
            }
        }
        time
    }

    /// The block time is what the program says: a rotary axis with no
    /// maximum velocity to hold it to may be asked to turn faster than any
    /// machine does (a reorientation about the tool point while it hardly
    /// moves). Warned about once per axis.
    fn fast_turn(&mut self, time: f64, m: &FeedMove) -> Option<MotionWarning> {
        let mut warning = None;
        for &i in &self.rotary {
            let turned = (m.values[i] - m.from_values[i]).abs();
            let speed = turned / time;
            if speed > FAST_TURN_DEG_PER_MIN
                && !self.vmax.iter().any(|&(j, _)| j == i)
                && !self.fast_warned.contains(&i)
            {
                self.fast_warned.push(i);
                warning = Some(MotionWarning::FastTurn {
                    axis: self.names[i].clone(),
                    turned_deg: turned,
                    minutes: time,
                    speed_deg_per_min: speed,
                });
            }
        }
        warning
    }
}
