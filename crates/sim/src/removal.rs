//! Material removal during the replay: the tool's poses of every block,
//! sampled along the path the machine really takes (joint interpolation,
//! arcs, tool-centre-point control), are cut from a tri-dexel stock
//! (`kinpost-stock`); a rapid that removes material is reported, as
//! VERICUT reports a "fast feed cut".

use kinpost_machine::Pose;
use kinpost_stock::{BlockRef, Comparison, Design, DesignError, Stock, Tool, ToolPose, compare};
use nalgebra::{Point3, Unit};

use crate::SimError;
use crate::report::{At, Removal};

/// A stock to cut during a replay, the tool that cuts it, and what was cut.
#[derive(Debug, Clone)]
pub struct Cutting {
    stock: Stock,
    tool: Tool,
    /// The block of every move id: move `k` is the `k`-th block cut.
    blocks: Vec<BlockRef>,
    rapid_cuts: Vec<At>,
}

impl Cutting {
    /// `stock` (in the part frame) cut by `tool`.
    pub fn new(stock: Stock, tool: Tool) -> Cutting {
        Cutting {
            stock,
            tool,
            blocks: Vec::new(),
            rapid_cuts: Vec::new(),
        }
    }

    /// The stock as cut so far.
    pub fn stock(&self) -> &Stock {
        &self.stock
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
            design: cmp
                .as_ref()
                .map(|c| kinpost_stock::Report::new(stock, &self.stock, c, &self.blocks)),
        };
        Ok((removal, cmp))
    }

    /// Cuts one block: the tool at `poses` (the block's start first, then
    /// samples along it, its end last; one pose when its start is not
    /// known), swept from each to the next.
    pub(crate) fn cut(&mut self, poses: &[Pose], at: &At, rapid: bool) -> Result<(), SimError> {
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
        let volume_before = (rapid && self.reaches_stock(&tool_poses).map_err(cut_error)?)
            .then(|| self.stock.volume_mm3());
        match tool_poses.as_slice() {
            [] => {}
            [only] => self
                .stock
                .cut_pose(&self.tool, only, id)
                .map_err(cut_error)?,
            many => {
                for w in many.windows(2) {
                    self.stock
                        .cut_move(&self.tool, &w[0], &w[1], id)
                        .map_err(cut_error)?;
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
