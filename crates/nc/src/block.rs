//! The block model: one motion block of a program, the same type whether the
//! post is about to write it ([`Block<&[f64]>`](Block), axis values
//! borrowed from the planner), a reader has read it back
//! (`Block<Vec<Option<f64>>>`, an axis not programmed so far has no value),
//! or the interpreter resolved it for the virtual machine
//! (`Block<AxisValues>`, see [`crate::interp::Move::block`]).

/// How a block moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Motion {
    /// Positioning at rapid traverse (`G0`).
    Rapid,
    /// Interpolation at the programmed feed: linear (`G1`), or circular
    /// when the block has an [`ArcMotion`].
    Feed,
}

impl Motion {
    /// `rapid` or `feed` (the CSV spelling).
    pub fn as_str(self) -> &'static str {
        match self {
            Motion::Rapid => "rapid",
            Motion::Feed => "feed",
        }
    }
}

/// The plane of a circular block, in the program's X, Y, Z words.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ArcPlane {
    /// XY (`G17`), normal +Z.
    Xy,
    /// ZX (`G18`), normal +Y.
    Zx,
    /// YZ (`G19`), normal +X.
    Yz,
}

impl ArcPlane {
    /// 0, 1, 2 for XY, ZX, YZ (the order of [`crate::ArcWords::planes`]).
    pub fn index(self) -> usize {
        match self {
            ArcPlane::Xy => 0,
            ArcPlane::Zx => 1,
            ArcPlane::Yz => 2,
        }
    }

    /// The program axes (0 = X, 1 = Y, 2 = Z) of the plane, in the order
    /// that makes the normal positive (X Y for XY, Z X for ZX, Y Z for
    /// YZ), then the normal's.
    pub fn axes(self) -> [usize; 3] {
        match self {
            ArcPlane::Xy => [0, 1, 2],
            ArcPlane::Zx => [2, 0, 1],
            ArcPlane::Yz => [1, 2, 0],
        }
    }
}

/// The circle of a circular (or helical) block: its end point is the
/// block's axis values, its start the previous block's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcMotion {
    /// The plane.
    pub plane: ArcPlane,
    /// Clockwise looking against the plane's normal (`G2`), else `G3`.
    pub clockwise: bool,
    /// The centre minus the start point on the program's X, Y, Z (mm);
    /// the two of the plane are the ones written (`I J K`).
    pub centre_offset: [f64; 3],
}

/// One motion block. `A` holds the axis values in machine order: a borrowed
/// slice on the way to a writer, `Vec<Option<f64>>` out of a reader,
/// [`crate::interp::AxisValues`] out of the interpreter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block<A> {
    /// 1-based line of the CL record this block reaches (the CSV dialect's
    /// `line` column); `None` for a block the post inserted (retract,
    /// linearization) or one read from an NC program.
    pub cl_line: Option<usize>,
    /// 1-based line of the program that holds the block, once written or
    /// read; `None` for a block not yet written.
    pub line: Option<usize>,
    /// Block number of that line (`N120`, Heidenhain's leading number),
    /// once written or read; `None` for a block not yet written (the
    /// writer numbers it as its dialect says) or a line without one.
    pub number: Option<u64>,
    /// Rapid or feed.
    pub motion: Motion,
    /// NC values in machine order (one per axis of the writer or reader),
    /// mm and degrees, the pressure word in its place. A block to write
    /// holds them unrounded; NaN there means "no value" for the pressure
    /// word (nothing programmed).
    pub axes: A,
    /// Feed rate of a feed block (mm/min, or inverse time for a dialect
    /// with `inverse_time`); ignored on rapid blocks. `None` keeps the last
    /// one (a block to write) or is not known yet (a block read).
    pub feed: Option<f64>,
    /// The circle of a circular block (a feed block); `None` for a
    /// straight one.
    pub arc: Option<ArcMotion>,
}

impl<A> Block<A> {
    /// A rapid block to `axes`.
    pub fn rapid(axes: A) -> Block<A> {
        Block {
            cl_line: None,
            line: None,
            number: None,
            motion: Motion::Rapid,
            axes,
            feed: None,
            arc: None,
        }
    }

    /// A straight feed block to `axes` at `feed`.
    pub fn feed(axes: A, feed: f64) -> Block<A> {
        Block {
            motion: Motion::Feed,
            feed: Some(feed),
            ..Block::rapid(axes)
        }
    }

    /// The same block, reaching the CL record at `cl_line`.
    pub fn with_cl_line(self, cl_line: usize) -> Block<A> {
        Block {
            cl_line: Some(cl_line),
            ..self
        }
    }

    /// The same block with its axis values seen through `f` (e.g. an owned
    /// block borrowed for a writer: `block.map_axes(Vec::as_slice)`).
    pub fn map_axes<'a, B>(&'a self, f: impl FnOnce(&'a A) -> B) -> Block<B> {
        Block {
            cl_line: self.cl_line,
            line: self.line,
            number: self.number,
            motion: self.motion,
            axes: f(&self.axes),
            feed: self.feed,
            arc: self.arc,
        }
    }
}

/// What the tool does in the hole of a canned drilling cycle, as the
/// controls of ISO 6983-1 name their cycles (LinuxCNC's G-code reference:
/// G81/G82, G83, G73, G84, G85/G89).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HoleKind {
    /// Feed to depth, rapid out (`G81`; `G82` with a dwell).
    Drill,
    /// Pecks of one length, out to the feed start after each (`G83`).
    Peck,
    /// Pecks with a short back-off after each (`G73`).
    ChipBreak,
    /// Tapping: feed in, spindle reversed, feed out (`G84`).
    Tap,
    /// Feed in, feed out (`G85`; `G89` with a dwell).
    Bore,
}

impl HoleKind {
    /// The name a dialect's `[cycle] kinds` and its `cycle` template use:
    /// `drill`, `peck`, `chip_break`, `tap`, `bore`.
    pub fn as_str(self) -> &'static str {
        match self {
            HoleKind::Drill => "drill",
            HoleKind::Peck => "peck",
            HoleKind::ChipBreak => "chip_break",
            HoleKind::Tap => "tap",
            HoleKind::Bore => "bore",
        }
    }

    /// Every kind, in the order of [`HoleKind::as_str`]'s list.
    pub const ALL: [HoleKind; 5] = [
        HoleKind::Drill,
        HoleKind::Peck,
        HoleKind::ChipBreak,
        HoleKind::Tap,
        HoleKind::Bore,
    ];
}

/// One hole of a canned drilling cycle on the program's X, Y, Z words, the
/// hole axis along −Z: the tool, standing at `start_z` (at or above the
/// feed start `r`), moves across to `x`, `y`, down to `r` in rapid, cuts
/// down to `bottom` as its kind says, and ends at `retract`. Values are in
/// mm as written (already rounded as the dialect writes them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hole {
    /// What the tool does in the hole.
    pub kind: HoleKind,
    /// The hole's X.
    pub x: f64,
    /// The hole's Y.
    pub y: f64,
    /// Z of the top of the hole (the CL's hole point).
    pub top: f64,
    /// Z of the feed start (the R plane).
    pub r: f64,
    /// Z of the bottom.
    pub bottom: f64,
    /// Z the tool leaves the hole to.
    pub retract: f64,
    /// Z of the tool before the hole.
    pub start_z: f64,
    /// Peck length of a peck or chip-breaking cycle, mm (0 for the others).
    pub peck: f64,
    /// Dwell at the bottom, seconds (0: none).
    pub dwell: f64,
    /// Feed of the cutting moves, mm/min.
    pub feed: f64,
    /// Spindle speed in force, rpm (0: unknown or off).
    pub rpm: f64,
    /// The spindle turns counter-clockwise (a left-hand tap).
    pub ccw: bool,
}
