//! Material removal during the replay: the tool's poses of every block,
//! sampled along the path the machine really takes (joint interpolation,
//! arcs, tool-centre-point control), are cut from a tri-dexel stock
//! (`kinpost-stock`); a rapid that removes material is reported, as
//! VERICUT reports a "fast feed cut". With a process model the contact
//! wheel grinds by Preston's law instead (`kinpost_stock::process`).

use kinpost_machine::Pose;
use kinpost_stock::{
    BlockRef, Comparison, Conditions, Design, DesignError, GrindStats, GrindingSummary, Move,
    ProcessModel, Stock, Tool, ToolPose, compare,
};
use nalgebra::{Point3, Unit};

use crate::SimError;
use crate::report::{At, Removal};

/// A stock to cut during a replay, the tool that cuts it, and what was cut.
#[derive(Debug, Clone)]
pub struct Cutting {
    stock: Stock,
    tool: Tool,
    /// The belt-grinding process model: feed blocks of the contact wheel
    /// remove Preston's depth instead of the rigid wheel's sweep.
    process: Option<ProcessModel>,
    /// The block of every move id: move `k` is the `k`-th block cut.
    blocks: Vec<BlockRef>,
    rapid_cuts: Vec<At>,
    /// Rapids whose tool enters the stock's box (warnings).
    rapids_in_box: Vec<At>,
    /// What each block ground with the process model.
    ground: Vec<(u32, GrindStats)>,
    /// Moves held back to be cut together ([`Stock::cut_moves`]: the same
    /// stock as one by one), and the line of each one's block.
    pending: Vec<Move>,
    pending_lines: Vec<usize>,
}

/// Moves held back before they are cut together: enough for the stock to
/// share a visit of its rays among many short blocks.
const PENDING_MOVES: usize = 256;

/// What the process model needs of a feed block besides its poses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BlockConditions {
    /// The pressure word in force (NaN: never programmed).
    pub pressure: f64,
    /// The spindle (belt drive) speed, rpm; 0 when the spindle is off.
    pub spindle_rpm: f64,
    /// The block's time, seconds.
    pub seconds: f64,
}

impl Cutting {
    /// `stock` (in the part frame) cut by `tool`.
    pub fn new(stock: Stock, tool: Tool) -> Cutting {
        Cutting {
            stock,
            tool,
            process: None,
            blocks: Vec::new(),
            rapid_cuts: Vec::new(),
            rapids_in_box: Vec::new(),
            ground: Vec::new(),
            pending: Vec::new(),
            pending_lines: Vec::new(),
        }
    }

    /// Feed blocks grind with `model` (the tool must be the contact wheel):
    /// the normal force from the pressure word through the model's force
    /// table, the belt speed from the spindle speed, the feed from the
    /// block's length and time; Preston's depth is removed along the tool
    /// axis under the contact patch ([`Stock::grind_move`]). Blocks with the
    /// spindle off, and rapids, cut as the rigid wheel.
    pub fn with_process(mut self, model: ProcessModel) -> Cutting {
        self.process = Some(model);
        self
    }

    /// The stock as cut so far. (During a replay the last blocks' moves
    /// may still be held back: [`crate::Replay::finish_cutting`] cuts them
    /// before it gives the cutting back.)
    pub fn stock(&self) -> &Stock {
        &self.stock
    }

    /// Cuts the moves held back.
    pub(crate) fn flush(&mut self) -> Result<(), SimError> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let result = self.stock.cut_moves(&self.tool, &self.pending);
        let lines = std::mem::take(&mut self.pending_lines);
        self.pending.clear();
        result.map(|_| ()).map_err(|e| SimError::Cut {
            line: lines[e.index],
            source: e.source,
        })
    }

    /// The block of every move id ([`kinpost_stock::Report::new`] takes it).
    pub fn blocks(&self) -> &[BlockRef] {
        &self.blocks
    }

    /// Rapid blocks that removed material, in program order.
    pub fn rapid_cuts(&self) -> &[At] {
        &self.rapid_cuts
    }

    /// The report's removal: `stock` says how the stock was made; with a
    /// design, its comparison at `tolerance_mm` (gouges and residuals
    /// named by their blocks).
    pub fn report(
        &self,
        stock: &str,
        design: Option<(&Design, f64)>,
    ) -> Result<(Removal, Option<Comparison>), DesignError> {
        let cmp = design
            .map(|(d, tolerance_mm)| compare(&self.stock, d, tolerance_mm))
            .transpose()?;
        let removal = Removal {
            stock: stock.to_string(),
            resolution_mm: self.stock.resolution_mm(),
            removed_volume_mm3: self.stock.removed_volume_mm3(),
            rapid_cuts: self.rapid_cuts.clone(),
            rapids_in_stock_box: self.rapids_in_box.clone(),
            design: cmp
                .as_ref()
                .map(|c| kinpost_stock::Report::new(stock, &self.stock, c, &self.blocks)),
            grinding: self
                .process
                .as_ref()
                .map(|_| GrindingSummary::new(&self.ground, &self.blocks)),
        };
        Ok((removal, cmp))
    }

    /// Cuts one block: the tool at `poses` (the block's start first, then
    /// samples along it, its end last; one pose when its start is not
    /// known), swept from each to the next.
    /// `conditions`: a feed block's, for the process model.
    pub(crate) fn cut(
        &mut self,
        poses: &[Pose],
        at: &At,
        rapid: bool,
        conditions: Option<BlockConditions>,
    ) -> Result<(), SimError> {
        let id = u32::try_from(self.blocks.len()).unwrap_or(u32::MAX);
        self.blocks.push(BlockRef {
            block: at.number.map(|n| format!("N{n}")),
            line: at.line,
        });
        let cut_error = |source| SimError::Cut {
            line: at.line,
            source,
        };
        let tool_poses: Vec<ToolPose> = poses.iter().map(tool_pose).collect();
        // (Only a rapid whose sweep reaches the stock's box can cut: the
        // volume is summed before and after it then.)
        let in_box = rapid && self.reaches_stock(&tool_poses).map_err(cut_error)?;
        if in_box {
            self.rapids_in_box.push(at.clone());
            self.flush()?;
        }
        let volume_before = in_box.then(|| self.stock.volume_mm3());
        if let Some(c) = conditions.filter(|_| !rapid)
            && let Some(grinding) = self.grinding_conditions(&tool_poses, &c, at)?
        {
            self.flush()?;
            return self.grind(&tool_poses, &grinding, id, at);
        }
        match tool_poses.as_slice() {
            [] => {}
            [only] => {
                self.flush()?;
                self.stock
                    .cut_pose(&self.tool, only, id)
                    .map_err(cut_error)?
            }
            many => {
                for w in many.windows(2) {
                    self.pending.push(Move {
                        from: w[0],
                        to: w[1],
                        id,
                    });
                    self.pending_lines.push(at.line);
                }
                if in_box || self.pending.len() >= PENDING_MOVES {
                    self.flush()?;
                }
            }
        }
        if let Some(before) = volume_before
            && self.stock.volume_mm3() < before
        {
            self.rapid_cuts.push(at.clone());
        }
        Ok(())
    }

    /// The process model's conditions of a feed block along `poses`, when
    /// it grinds with the model: a model, the spindle on, the block moving
    /// in time.
    fn grinding_conditions(
        &self,
        poses: &[ToolPose],
        c: &BlockConditions,
        at: &At,
    ) -> Result<Option<Conditions>, SimError> {
        let Some(model) = &self.process else {
            return Ok(None);
        };
        let travel_mm: f64 = poses
            .windows(2)
            .map(|w| (w[1].point - w[0].point).norm())
            .sum();
        if !(c.spindle_rpm > 0.0 && c.seconds > 0.0 && travel_mm > 0.0) {
            return Ok(None);
        }
        if !c.pressure.is_finite() {
            return Err(SimError::NoPressure {
                line: at.line,
                word: model.force.axis.clone(),
            });
        }
        Ok(Some(Conditions {
            force_n: model.force_n(c.pressure),
            spindle_rpm: c.spindle_rpm,
            feed_mm_min: travel_mm / c.seconds * 60.0,
            // (A pass's depth does not depend on the curvature: it shapes
            // the contact patch, not the pressure's integral.)
            curvature_per_mm: 0.0,
        }))
    }

    /// Grinds a feed block with the process model, piece by piece.
    fn grind(
        &mut self,
        poses: &[ToolPose],
        conditions: &Conditions,
        id: u32,
        at: &At,
    ) -> Result<(), SimError> {
        let Some(model) = &self.process else {
            return Ok(());
        };
        let mut total: Option<GrindStats> = None;
        for w in poses.windows(2) {
            let s = self
                .stock
                .grind_move(model, &self.tool, &w[0], &w[1], conditions, id)
                .map_err(|source| SimError::Grind {
                    line: at.line,
                    source,
                })?;
            total = Some(match total {
                None => s,
                Some(t) => GrindStats {
                    rays: t.rays + s.rays,
                    removed_volume_mm3: t.removed_volume_mm3 + s.removed_volume_mm3,
                    depth_range_mm: [
                        t.depth_range_mm[0].min(s.depth_range_mm[0]),
                        t.depth_range_mm[1].max(s.depth_range_mm[1]),
                    ],
                    ..t
                },
            });
        }
        if let Some(t) = total {
            self.ground.push((id, t));
        }
        Ok(())
    }

    /// Whether the tool's bounds at any of `poses`, or between two of them,
    /// meet the stock's box.
    fn reaches_stock(&self, poses: &[ToolPose]) -> Result<bool, kinpost_stock::CutError> {
        let (lo, hi) = (self.stock.origin(), self.stock.max_corner());
        let mut bounds: Option<(Point3<f64>, Point3<f64>)> = None;
        for p in poses {
            let placed = self.tool.place(p)?;
            let (a, b) = placed.bounds();
            bounds = Some(match bounds {
                None => (a, b),
                Some((l, h)) => (l.inf(&a), h.sup(&b)),
            });
        }
        Ok(bounds.is_some_and(|(a, b)| (0..3).all(|k| a[k] <= hi[k] && b[k] >= lo[k])))
    }
}

/// The stock's pose of the machine's tool pose (part frame).
fn tool_pose(p: &Pose) -> ToolPose {
    ToolPose {
        point: Point3::from(p.point),
        axis: Unit::new_normalize(p.axis),
        reference: p.reference.map(Unit::new_normalize),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn at(line: usize) -> At {
        At {
            block: line as u64,
            line,
            number: None,
        }
    }

    fn pose(x: f64, axis: Vector3<f64>) -> Pose {
        Pose {
            point: Vector3::new(x, 5.0, 9.0),
            axis,
            reference: None,
        }
    }

    /// Blocks are cut together, later: a block that cannot be cut is still
    /// named by its own line, and the blocks before it are cut.
    #[test]
    fn a_block_held_back_that_cannot_be_cut_is_named_by_its_line() {
        let stock = Stock::from_box(Point3::origin(), Point3::new(20.0, 10.0, 10.0), 0.2).unwrap();
        let ball = Tool::BallEnd {
            diameter: 4.0,
            flute_length: 10.0,
            shank: None,
        };
        let mut c = Cutting::new(stock, ball);
        let z = Vector3::z();
        c.cut(&[pose(2.0, z), pose(8.0, z)], &at(10), false, None)
            .unwrap();
        // The axis turns half a turn within the block.
        c.cut(&[pose(8.0, z), pose(12.0, -z)], &at(20), false, None)
            .unwrap();
        assert_eq!(c.stock().removed_volume_mm3(), 0.0, "held back");
        match c.flush() {
            Err(SimError::Cut { line, .. }) => assert_eq!(line, 20),
            other => panic!("{other:?}"),
        }
        assert!(c.stock().removed_volume_mm3() > 0.0, "line 10 is cut");
    }
}
