//! What a replay found: the report `kinpost sim` prints and writes as JSON.

use serde::Serialize;

/// Where in the program something happened.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct At {
    /// 1-based motion block of the run (loops count every pass).
    pub block: u64,
    /// 1-based line of the NC program.
    pub line: usize,
    /// The block number of that line (`N120`), if it has one.
    pub number: Option<u64>,
}

/// An axis beyond its travel in one block.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Overtravel {
    /// Where.
    #[serde(flatten)]
    pub at: At,
    /// The axis name.
    pub axis: String,
    /// The farthest value the axis reaches in the block, machine
    /// coordinates (the machine file's `machine_offset` applied), mm or
    /// degrees.
    pub value: f64,
    /// The travel in machine coordinates `[min, max]` (a locked axis: its
    /// fixed value twice).
    pub limits: [f64; 2],
    /// How far beyond the limit it goes, mm or degrees (positive).
    pub excess: f64,
    /// Whether the largest excess lies inside the block, not at its end
    /// (an arc that bulges out, a rotary axis passing its limit).
    pub between_ends: bool,
}

/// Two solids too close along a stretch of blocks.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contact {
    /// The first block where they touch (or come within the clearance).
    #[serde(flatten)]
    pub at: At,
    /// The last block of the stretch (consecutive blocks with the same
    /// pair are one contact).
    pub last_block: u64,
    /// The two solids' names.
    pub solids: [String; 2],
    /// `collision`, `rapid_into_stock` or `near_miss`.
    pub kind: &'static str,
    /// Their smallest distance, mm (0 touching or overlapping): the
    /// nearest the pair comes in the blocks of the contact, from the first
    /// pose within the clearance on (sampled and refined; `collide.rs`).
    pub distance_mm: f64,
    /// The deepest overlap found, mm, where it is computed.
    pub penetration_mm: Option<f64>,
    /// Where in the first block (0 start, 1 end).
    pub fraction: f64,
    /// The pair's clearances, mm: warning, error.
    pub clearances_mm: [f64; 2],
}

/// The largest deviation from the CL.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Deviation {
    /// Where in the program.
    #[serde(flatten)]
    pub at: At,
    /// The CL line of the `GOTO` that starts the CL segment it was measured
    /// against.
    pub cl_line: usize,
    /// The deviation: mm for a position, radians for a tool axis.
    pub value: f64,
}

/// The comparison of the replayed path with the CL it was posted from.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ClComparison {
    /// `GOTO`s read from the CL.
    pub cl_points: usize,
    /// Tool points compared: the ends of feed blocks and points inside them
    /// (rapids do not cut and are not compared; their collisions are
    /// checked).
    pub samples: u64,
    /// Largest distance of a replayed tool point from the CL polyline, mm.
    pub position: Option<Deviation>,
    /// Largest angle between a replayed tool axis and the CL's (linearly
    /// interpolated between its `GOTO`s), radians.
    pub axis: Option<Deviation>,
    /// The same, at block ends only (what the output rounding bounds).
    pub position_at_block_ends: Option<Deviation>,
    /// The same, at block ends only.
    pub axis_at_block_ends: Option<Deviation>,
}

/// What a replay found.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct SimReport {
    /// Motion blocks replayed.
    pub blocks: u64,
    /// Blocks executed (lines interpreted; loops count every pass).
    pub executed_blocks: u64,
    /// Run time, seconds, from the feeds, rapid rates and velocity limits
    /// (no acceleration: a lower bound of the real time).
    pub duration_s: f64,
    /// Axes beyond their travel, block by block.
    pub overtravel: Vec<Overtravel>,
    /// Collisions and rapids into stock (errors).
    pub collisions: Vec<Contact>,
    /// Pairs within their warning clearance (warnings).
    pub near_misses: Vec<Contact>,
    /// Blocks that turn the tool axis through the cone around the
    /// machine's singular direction (warnings: a rotary axis may swing
    /// there), consecutive blocks as one.
    pub singular_passages: Vec<SingularPassage>,
    /// Rapid blocks into the stock, in program order: a rapid that touches
    /// a stock solid of the machine file (also among `collisions`), or
    /// that removes material from `--stock` (also among
    /// `removal.rapid_cuts`).
    pub rapid_into_stock: Vec<At>,
    /// Largest position deviation from the CL along the path, mm (with
    /// `--cl`).
    pub max_position_error_mm: Option<f64>,
    /// Largest tool-axis deviation from the CL along the path, radians
    /// (with `--cl`).
    pub max_axis_error_rad: Option<f64>,
    /// The CL comparison in full (with `--cl`).
    pub cl: Option<ClComparison>,
    /// What the run assumed, one sentence each (inputs read as 0, rapid
    /// rates, the start position).
    pub assumed: Vec<String>,
    /// Warnings with their place (`file:line:column: message`).
    pub warnings: Vec<String>,
    /// Material removal, when the replay cut a stock.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub removal: Option<Removal>,
}

/// A passage of the tool axis near the machine's singular direction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SingularPassage {
    /// The first block of the passage.
    #[serde(flatten)]
    pub at: At,
    /// Its last block.
    pub last_block: u64,
    /// The axis whose angle is free at the singular direction.
    pub axis: String,
    /// The least angle between the tool axis and the singular direction,
    /// degrees.
    pub angle_deg: f64,
    /// The cone reported, degrees (the machine's `singular_cone`).
    pub cone_deg: f64,
    /// How far the free axis turns in the passage, degrees.
    pub turn_deg: f64,
}

/// What the tool removed from the stock, and how the part compares with
/// the design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Removal {
    /// How the stock was made (`box:0,0,0,250,80,40`, `design+0.2`, a
    /// file).
    pub stock: String,
    /// Ray spacing, mm.
    pub resolution_mm: f64,
    /// Volume removed, mm³.
    pub removed_volume_mm3: f64,
    /// Rapid blocks that removed material (errors: a rapid into the
    /// stock).
    pub rapid_cuts: Vec<At>,
    /// Rapid blocks whose tool enters the stock's bounding box (warnings:
    /// a rapid that close to the material, cutting or not).
    pub rapids_in_stock_box: Vec<At>,
    /// The comparison with the design (`--design`): gouges and residuals
    /// with their blocks, regions, histogram.
    pub design: Option<kinpost_stock::Report>,
    /// What the belt-grinding process model predicts (`--process`): the
    /// force, contact pressure, pass depth and the depth range removed,
    /// block by block.
    pub grinding: Option<kinpost_stock::GrindingSummary>,
}

impl Removal {
    /// Whether the program gouges the design or cuts at rapid traverse.
    pub fn violated(&self) -> bool {
        !self.rapid_cuts.is_empty() || self.design.as_ref().is_some_and(|d| d.gouge_max_mm > 0.0)
    }
}

impl SimReport {
    /// Whether anything was violated (overtravel, a collision, a rapid into
    /// stock): `kinpost sim` exits with 3.
    pub fn violated(&self) -> bool {
        !self.overtravel.is_empty()
            || !self.collisions.is_empty()
            || self.removal.as_ref().is_some_and(Removal::violated)
    }

    /// The report as pretty JSON, with a final newline.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }

    /// One line per finding and a closing summary, for standard error.
    pub fn summary(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        for o in self.overtravel.iter().take(SUMMARY_LINES) {
            let _ = writeln!(
                s,
                "error: line {}{}: {} reaches {} outside its travel [{}, {}] by {:.6}{}",
                o.at.line,
                number(o.at.number),
                o.axis,
                o.value,
                o.limits[0],
                o.limits[1],
                o.excess,
                if o.between_ends {
                    " (between the block's ends)"
                } else {
                    ""
                }
            );
        }
        more(&mut s, self.overtravel.len(), "overtravel findings");
        let collisions = self.collisions.iter().take(SUMMARY_LINES);
        let near = self.near_misses.iter().take(SUMMARY_LINES);
        for (c, what) in collisions
            .map(|c| (c, "error"))
            .chain(near.map(|c| (c, "warning")))
        {
            let depth = c
                .penetration_mm
                .map_or(String::new(), |p| format!(", {p:.3} mm deep"));
            let _ = writeln!(
                s,
                "{what}: line {}{}: {} between `{}` and `{}` (distance {:.3} mm{depth}; clearances {} / {} mm){}",
                c.at.line,
                number(c.at.number),
                c.kind.replace('_', " "),
                c.solids[0],
                c.solids[1],
                c.distance_mm,
                c.clearances_mm[0],
                c.clearances_mm[1],
                if c.last_block > c.at.block {
                    format!(" through block {}", c.last_block)
                } else {
                    String::new()
                }
            );
        }
        more(&mut s, self.collisions.len(), "collisions");
        more(&mut s, self.near_misses.len(), "near misses");
        for p in self.singular_passages.iter().take(SUMMARY_LINES) {
            let _ = writeln!(
                s,
                "warning: line {}{}: the tool axis passes {:.4}° from the singular direction (within the {}° cone), where {} is free; {} turns {:.3}° in the passage{}",
                p.at.line,
                number(p.at.number),
                p.angle_deg,
                p.cone_deg,
                p.axis,
                p.axis,
                p.turn_deg,
                if p.last_block > p.at.block {
                    format!(" (through block {})", p.last_block)
                } else {
                    String::new()
                }
            );
        }
        more(&mut s, self.singular_passages.len(), "singular passages");
        if let Some(r) = &self.removal {
            r.findings(&mut s);
        }
        for a in &self.assumed {
            let _ = writeln!(s, "note: assumed {a}");
        }
        let _ = write!(
            s,
            "{} blocks, {}, {} overtravel, {} collisions, {} near misses",
            self.blocks,
            duration(self.duration_s),
            self.overtravel.len(),
            self.collisions.len(),
            self.near_misses.len()
        );
        if let Some(cl) = &self.cl {
            if let Some(p) = &cl.position {
                let _ = write!(
                    s,
                    "; CL deviation {:.6} mm (line {}, CL line {})",
                    p.value, p.at.line, p.cl_line
                );
            }
            if let Some(a) = &cl.axis {
                let _ = write!(
                    s,
                    ", tool axis {:.3e} rad (line {}, CL line {})",
                    a.value, a.at.line, a.cl_line
                );
            }
        }
        if let Some(r) = &self.removal {
            let _ = write!(
                s,
                "; {:.3} mm³ removed from {} at {} mm",
                r.removed_volume_mm3, r.stock, r.resolution_mm
            );
            if let Some(d) = &r.design {
                let _ = write!(
                    s,
                    ", gouge {:.4} mm, residual {:.4} mm beyond {} mm",
                    d.gouge_max_mm, d.residual_max_mm, d.tolerance_mm
                );
                if let Some([lo, hi]) = d.deviation_range_mm {
                    let _ = write!(s, " (deviation {lo:+.4} to {hi:+.4} mm)");
                }
            }
            if let Some(g) = &r.grinding {
                let _ = write!(
                    s,
                    "; the process model ground {:.3} mm³ in {} blocks ({:.4} to {:.4} mm a block)",
                    g.removed_volume_mm3,
                    g.blocks.len(),
                    g.depth_range_mm[0],
                    g.depth_range_mm[1]
                );
            }
        }
        s
    }
}

impl Removal {
    /// The rapid cuts and the deepest gouge and largest residual, a line
    /// each, for the summary.
    fn findings(&self, s: &mut String) {
        use std::fmt::Write as _;
        for at in self.rapid_cuts.iter().take(SUMMARY_LINES) {
            let _ = writeln!(
                s,
                "error: line {}{}: a rapid removes material (fast feed cut)",
                at.line,
                number(at.number)
            );
        }
        more(s, self.rapid_cuts.len(), "rapid cuts");
        let cut: Vec<u64> = self.rapid_cuts.iter().map(|a| a.block).collect();
        let boxed: Vec<&At> = self
            .rapids_in_stock_box
            .iter()
            .filter(|a| !cut.contains(&a.block))
            .collect();
        for at in boxed.iter().take(SUMMARY_LINES) {
            let _ = writeln!(
                s,
                "warning: line {}{}: a rapid enters the stock's bounding box",
                at.line,
                number(at.number)
            );
        }
        more(s, boxed.len(), "rapids in the stock's box");
        let Some(d) = &self.design else {
            return;
        };
        for (region, what, kind) in [
            (&d.gouge_max, "error", "gouge"),
            (&d.residual_max, "note", "residual"),
        ] {
            if let Some(r) = region {
                let _ = writeln!(
                    s,
                    "{what}: {}{kind} of {:.4} mm at ({:.3}, {:.3}, {:.3}){}",
                    r.line.map_or(String::new(), |l| format!(
                        "line {l}{}: ",
                        r.block
                            .as_ref()
                            .map_or(String::new(), |b| format!(" ({b})"))
                    )),
                    r.deviation_mm.abs(),
                    r.at[0],
                    r.at[1],
                    r.at[2],
                    match (r.line, kind) {
                        (Some(_), _) => "",
                        (None, "gouge") => " (no material left along the ray)",
                        (None, _) => " (uncut stock)",
                    }
                );
            }
        }
    }
}

/// Findings of one kind the summary lists line by line; the rest are
/// counted (the JSON report has them all).
const SUMMARY_LINES: usize = 20;

/// "… and N more" when `count` findings exceed the summary's lines.
fn more(s: &mut String, count: usize, what: &str) {
    use std::fmt::Write as _;
    if count > SUMMARY_LINES {
        let _ = writeln!(
            s,
            "  … and {} more {what} (--json lists them all)",
            count - SUMMARY_LINES
        );
    }
}

fn number(n: Option<u64>) -> String {
    n.map_or(String::new(), |n| format!(" (N{n})"))
}

/// A duration as h:mm:ss.s.
fn duration(s: f64) -> String {
    let h = (s / 3600.0).floor();
    let m = ((s - h * 3600.0) / 60.0).floor();
    format!(
        "run time {}:{:02}:{:04.1}",
        h as u64,
        m as u64,
        s - h * 3600.0 - m * 60.0
    )
}
