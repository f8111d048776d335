//! The simulation report, as VERICUT's AUTO-DIFF gives it.

use serde::{Deserialize, Serialize};

use crate::design::{Bin, Comparison, Region, Sample};
use crate::stock::Stock;

/// Where a move came from in the NC program.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct BlockRef {
    /// The block's number or label as written (N120), if any.
    pub block: Option<String>,
    /// 1-based line of the program.
    pub line: usize,
}

/// A region beyond tolerance, with its block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReportRegion {
    /// Largest deviation in the region (signed), mm.
    pub deviation_mm: f64,
    /// Design area of the region, mm².
    pub area_mm2: f64,
    /// Measured points in it.
    pub samples: usize,
    /// Where the largest deviation is.
    pub at: [f64; 3],
    /// The move that made it (`None`: the uncut stock).
    pub move_id: Option<u32>,
    /// The block of that move.
    pub block: Option<String>,
    /// The line of that move.
    pub line: Option<usize>,
}

/// The report of a simulation with comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// How the stock was made (`box 0,0,0 250,80,40`, `design+0.2`, a file).
    pub stock: String,
    /// Ray spacing, mm.
    pub resolution_mm: f64,
    /// Volume removed, mm³.
    pub removed_volume_mm3: f64,
    /// Comparison tolerance, mm.
    pub tolerance_mm: f64,
    /// Deepest gouge, mm (positive depth; 0 when none beyond tolerance).
    pub gouge_max_mm: f64,
    /// Largest residual, mm (0 when none beyond tolerance).
    pub residual_max_mm: f64,
    /// Where the deepest gouge is and what made it.
    pub gouge_max: Option<ReportRegion>,
    /// Where the largest residual is and what made it.
    pub residual_max: Option<ReportRegion>,
    /// Gouge regions, deepest first.
    pub gouge_regions: Vec<ReportRegion>,
    /// Residual regions, largest first.
    pub residual_regions: Vec<ReportRegion>,
    /// Histogram of the measured deviations.
    pub histogram: Vec<Bin>,
    /// The most negative and the most positive deviation measured, within
    /// the tolerance or not, mm: the deepest cut into the design and the
    /// most material left on it.
    pub deviation_range_mm: Option<[f64; 2]>,
    /// Design points measured.
    pub measured: u64,
    /// Material missing inside a closed design, mm³.
    pub gouge_volume_mm3: f64,
    /// Material outside a closed design, mm³.
    pub residual_volume_mm3: f64,
    /// The process model's prediction, when the program was ground with it.
    pub grinding: Option<GrindingSummary>,
}

impl Report {
    /// The report of a stock and its comparison; `blocks[move_id]` names
    /// the block of each move (moves beyond the slice get no block).
    pub fn new(
        stock_description: &str,
        stock: &Stock,
        cmp: &Comparison,
        blocks: &[BlockRef],
    ) -> Report {
        let named = |deviation_mm: f64,
                     area_mm2: f64,
                     samples: usize,
                     at: [f64; 3],
                     move_id: Option<u32>| {
            let b = move_id.and_then(|m| blocks.get(m as usize));
            ReportRegion {
                deviation_mm,
                area_mm2,
                samples,
                at,
                move_id,
                block: b.and_then(|b| b.block.clone()),
                line: b.map(|b| b.line),
            }
        };
        let region = |r: &Region| named(r.deviation_mm, r.area_mm2, r.samples, r.at, r.move_id);
        let sample = |s: &Sample| named(s.deviation_mm, s.area_mm2, 1, s.part_point, s.move_id);
        Report {
            stock: stock_description.to_string(),
            resolution_mm: stock.resolution_mm(),
            removed_volume_mm3: stock.removed_volume_mm3(),
            tolerance_mm: cmp.tolerance_mm,
            gouge_max_mm: cmp.gouge_max().map_or(0.0, |s| -s.deviation_mm),
            residual_max_mm: cmp.residual_max().map_or(0.0, |s| s.deviation_mm),
            gouge_max: cmp.gouge_max().map(sample),
            residual_max: cmp.residual_max().map(sample),
            gouge_regions: cmp.gouge_regions.iter().map(region).collect(),
            residual_regions: cmp.residual_regions.iter().map(region).collect(),
            histogram: cmp.histogram.clone(),
            deviation_range_mm: cmp.deviation_range_mm,
            measured: cmp.measured,
            gouge_volume_mm3: cmp.gouge_volume_mm3,
            residual_volume_mm3: cmp.residual_volume_mm3,
            grinding: None,
        }
    }
}

/// What the process model predicts a block grinds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GrindBlock {
    /// The move.
    pub move_id: u32,
    /// Its block, if named.
    pub block: Option<String>,
    /// Its line.
    pub line: Option<usize>,
    /// Normal force, N.
    pub force_n: f64,
    /// Peak contact pressure, N/mm².
    pub peak_pressure_mpa: f64,
    /// Depth of a full pass on a flat at this force and feed, mm.
    pub pass_depth_mm: f64,
    /// Smallest and largest depth removed at a ray, mm.
    pub depth_range_mm: [f64; 2],
}

/// The process model's prediction over a program.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GrindingSummary {
    /// Smallest and largest depth removed at a ray over all blocks, mm.
    pub depth_range_mm: [f64; 2],
    /// Volume ground away, mm³.
    #[serde(default)]
    pub removed_volume_mm3: f64,
    /// Per block that ground something.
    pub blocks: Vec<GrindBlock>,
}

impl GrindingSummary {
    /// Summarises the [`crate::GrindStats`] of the moves, in program order.
    pub fn new(moves: &[(u32, crate::GrindStats)], blocks: &[BlockRef]) -> GrindingSummary {
        let mut range = [f64::INFINITY, 0.0f64];
        let mut out = Vec::new();
        let removed_volume_mm3 = moves.iter().map(|(_, s)| s.removed_volume_mm3).sum();
        for (id, s) in moves {
            if s.rays == 0 {
                continue;
            }
            range = [
                range[0].min(s.depth_range_mm[0]),
                range[1].max(s.depth_range_mm[1]),
            ];
            let b = blocks.get(*id as usize);
            out.push(GrindBlock {
                move_id: *id,
                block: b.and_then(|b| b.block.clone()),
                line: b.map(|b| b.line),
                force_n: s.contact.force_n,
                peak_pressure_mpa: s.contact.peak_pressure_mpa,
                pass_depth_mm: s.pass_depth_mm,
                depth_range_mm: s.depth_range_mm,
            });
        }
        if out.is_empty() {
            range = [0.0, 0.0];
        }
        GrindingSummary {
            depth_range_mm: range,
            removed_volume_mm3,
            blocks: out,
        }
    }
}
