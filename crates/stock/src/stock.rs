//! The tri-dexel stock and material removal.

use nalgebra::{Point3, Unit, Vector3};
use rayon::prelude::*;

use crate::clip::{Aabb, piece_in_box, swept_in_box};
use crate::dexel::{Ray, Segment, UNCUT, remove_spans};
use crate::kernel::{Local, Span, capsule_span, cylinder_sweep_span, piece_span};
use crate::row::{Active, Capsule, RowFrame, RowSolid, RowSolids, Scratch, cut_tile};
use crate::tolerance::{
    DEFAULT_RAY_BUDGET, MAX_RAYS, NICE_RESOLUTIONS_MM, SAME_AXIS, SAMPLE_STEP_FRACTION,
};
use crate::tool::{Piece, PlacedTool, Tool, ToolError, ToolPose};

/// Why a stock cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StockError {
    /// The resolution is not a positive finite number.
    #[error("the resolution must be a positive number of mm, not {0}")]
    Resolution(f64),
    /// The box has a coordinate that is not finite or an empty extent.
    #[error("the stock box must have finite corners with min < max on every axis")]
    EmptyBox,
    /// Too many rays for the machine.
    #[error(
        "{rays} rays at {resolution_mm} mm is more than the {max} a stock may have: choose a coarser resolution"
    )]
    TooManyRays {
        /// Rays the resolution asks for.
        rays: u64,
        /// The resolution.
        resolution_mm: f64,
        /// The limit.
        max: u64,
    },
    /// The mesh has no triangle or a coordinate that is not finite.
    #[error("the mesh is empty or has a coordinate that is not a finite number")]
    BadMesh,
    /// Rays cross the mesh an odd number of times: it has holes.
    #[error("the mesh is not closed: {rays} rays cross it an odd number of times")]
    OpenMesh {
        /// How many rays did.
        rays: usize,
    },
    /// The allowance is not a finite number ≥ 0.
    #[error("the allowance must be a number of mm, 0 or more, not {0}")]
    Allowance(f64),
}

/// Why a move cannot be cut.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CutError {
    /// The tool or a pose is invalid.
    #[error(transparent)]
    Tool(#[from] ToolError),
    /// The tool axis (or reference) turns by half a turn within one move.
    #[error(
        "the tool axis turns by 180° within one move: the motion between the poses is undefined"
    )]
    HalfTurn,
    /// The move needs more samples than allowed.
    #[error("the move needs {0} samples at this resolution (more than 10 million): split it")]
    TooManySamples(u64),
}

/// The rays along one axis of the part frame.
#[derive(Debug, Clone)]
pub struct Family {
    /// The axis the rays run along (0 = X, 1 = Y, 2 = Z).
    pub axis: usize,
    /// The first of the other two axes (the faster-varying index).
    pub u: usize,
    /// The second of the other two axes.
    pub v: usize,
    /// Ray count along `u`.
    pub nu: usize,
    /// Ray count along `v`.
    pub nv: usize,
    /// Rays, row-major: ray (iu, iv) at `iv * nu + iu`.
    pub rays: Vec<Ray>,
}

impl Family {
    /// The ray at (iu, iv).
    pub fn ray(&self, iu: usize, iv: usize) -> &[Segment] {
        &self.rays[iv * self.nu + iu]
    }
}

/// A stock as three orthogonal grids of rays (tri-dexel), each ray a sorted
/// list of solid intervals exact along the ray.
///
/// The lattice: `origin` is the low corner; ray positions are cell centres,
/// coordinate `origin[i] + (n + 0.5)·resolution` for n in 0..counts[i].
/// The three families share this lattice: the ray along X at (y_j, z_k),
/// along Y at (x_i, z_k) and along Z at (x_i, y_j) all pass through the
/// lattice node (x_i, y_j, z_k).
#[derive(Debug, Clone)]
pub struct Stock {
    origin: [f64; 3],
    resolution: f64,
    counts: [usize; 3],
    families: [Family; 3],
    initial_volume: f64,
    /// Volume ground away by the process model, mm³: it removes along one
    /// family of rays only (`Stock::grind_move`).
    ground_volume: f64,
    last: Option<(Tool, ToolPose)>,
    removal: Removal,
}

/// One move of a batch ([`Stock::cut_moves`]): the tool from one pose to
/// the next, as move `id`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// The start pose.
    pub from: ToolPose,
    /// The end pose.
    pub to: ToolPose,
    /// The move's id: the interval ends it makes remember it.
    pub id: u32,
}

/// A move of a batch that could not be cut (the moves before it were).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("move {index} of the batch: {source}")]
pub struct BatchError {
    /// The move's place in the batch.
    pub index: usize,
    /// Why it could not be cut.
    #[source]
    pub source: CutError,
}

/// How a move was cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MoveCut {
    /// Poses cut (0 for an analytic sweep only).
    pub samples: u64,
    /// Whether the move was swept analytically (a pure translation).
    pub analytic: bool,
}

/// How a cut visits the rays. Both give the same stock, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Removal {
    /// Skips a solid where its span certainly changes nothing: it starts at
    /// or above the top of the ray's material, or above the start of a span
    /// already found that reaches the top (a test with products and sums
    /// only, every rounding bounded; ray by ray, or a whole row segment at
    /// once), and computes the other spans four rays at a time.
    #[default]
    Fast,
    /// Computes the span of every solid on every ray within its bounds: the
    /// straightforward path, the reference the fast one is tested against.
    Reference,
}

/// A solid the cut removes, with its bounds.
#[derive(Debug, Clone)]
enum Solid {
    Piece {
        piece: Piece,
        origin: Vector3<f64>,
        axis: Vector3<f64>,
    },
    Capsule {
        c0: Vector3<f64>,
        v: Vector3<f64>,
        r: f64,
    },
    CylinderSweep {
        origin: Vector3<f64>,
        axis: Vector3<f64>,
        z0: f64,
        z1: f64,
        r: f64,
        v: Vector3<f64>,
    },
}

#[derive(Debug, Clone)]
struct Bounded {
    solid: Solid,
    lo: [f64; 3],
    hi: [f64; 3],
    /// The solid's move: its place in the batch being cut, from 1.
    seq: u32,
}

impl Bounded {
    #[inline]
    fn span(&self, o: &Vector3<f64>, d: &Vector3<f64>, kuv: (usize, usize, usize)) -> Option<Span> {
        match &self.solid {
            Solid::Piece {
                piece,
                origin,
                axis,
            } => {
                let (k, u, v) = kuv;
                piece_span(piece, &Local::along(k, u, v, o[u], o[v], origin, axis))
            }
            Solid::Capsule { c0, v, r } => capsule_span(o, d, c0, v, *r),
            Solid::CylinderSweep {
                origin,
                axis,
                z0,
                z1,
                r,
                v,
            } => cylinder_sweep_span(o, d, origin, axis, *z0, *z1, *r, v),
        }
    }

    /// The solid's batch kernel for rays along `d` (a unit axis).
    fn row_solid(&self, d: &Vector3<f64>) -> RowSolid {
        match self.solid {
            Solid::Piece {
                piece: Piece::Cylinder { z0, z1, r },
                origin,
                axis,
            } => RowSolid::Cylinder {
                origin: origin.into(),
                axis: axis.into(),
                z0,
                z1,
                r,
            },
            Solid::Piece {
                piece: Piece::Sphere { zc, r },
                origin,
                axis,
            } => RowSolid::Sphere {
                origin: origin.into(),
                axis: axis.into(),
                zc,
                r,
            },
            Solid::Capsule { c0, v, r } => RowSolid::Capsule(Capsule::new(&c0, &v, r, d)),
            _ => RowSolid::Other,
        }
    }
}

fn placed_solids(t: &PlacedTool, boxed: &Aabb, seq: u32, out: &mut Vec<Bounded>) {
    for p in &t.pieces {
        if let Some((lo, hi)) = piece_in_box(p, &t.origin, &t.axis, boxed) {
            out.push(Bounded {
                solid: Solid::Piece {
                    piece: *p,
                    origin: t.origin.coords,
                    axis: t.axis,
                },
                lo,
                hi,
                seq,
            });
        }
    }
}

/// The default resolution for a stock of this extent: the spacing that
/// gives about `DEFAULT_RAY_BUDGET` (16 million) rays, rounded up to the next
/// of 0.005, 0.01, 0.02, 0.025, 0.05, 0.1, 0.2, 0.25, 0.5, 1, 2, 5 mm.
/// (The three families hold (XY + YZ + ZX)/h² rays.)
pub fn default_resolution(min: Point3<f64>, max: Point3<f64>) -> f64 {
    let e = max - min;
    let area = e.x * e.y + e.y * e.z + e.z * e.x;
    let h = (area / DEFAULT_RAY_BUDGET).sqrt();
    NICE_RESOLUTIONS_MM
        .iter()
        .copied()
        .find(|&n| n >= h)
        .unwrap_or(NICE_RESOLUTIONS_MM[NICE_RESOLUTIONS_MM.len() - 1])
}

impl Stock {
    /// An empty lattice over the box (every ray without material).
    pub(crate) fn empty(
        min: Point3<f64>,
        max: Point3<f64>,
        resolution_mm: f64,
    ) -> Result<Stock, StockError> {
        if !(resolution_mm.is_finite() && resolution_mm > 0.0) {
            return Err(StockError::Resolution(resolution_mm));
        }
        let ok = (0..3).all(|i| min[i].is_finite() && max[i].is_finite() && min[i] < max[i]);
        if !ok {
            return Err(StockError::EmptyBox);
        }
        let n = |i: usize| ((max[i] - min[i]) / resolution_mm).ceil().max(1.0);
        let (nx, ny, nz) = (n(0), n(1), n(2));
        let rays = nx * ny + ny * nz + nz * nx;
        if !(rays <= MAX_RAYS as f64) {
            return Err(StockError::TooManyRays {
                rays: if rays.is_finite() {
                    rays as u64
                } else {
                    u64::MAX
                },
                resolution_mm,
                max: MAX_RAYS,
            });
        }
        let counts = [nx as usize, ny as usize, nz as usize];
        let family = |axis: usize| {
            let (u, v) = match axis {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            Family {
                axis,
                u,
                v,
                nu: counts[u],
                nv: counts[v],
                rays: vec![Ray::new(); counts[u] * counts[v]],
            }
        };
        Ok(Stock {
            origin: [min.x, min.y, min.z],
            resolution: resolution_mm,
            counts,
            families: [family(0), family(1), family(2)],
            initial_volume: 0.0,
            ground_volume: 0.0,
            last: None,
            removal: Removal::Fast,
        })
    }

    /// A box stock from its low and high corners in the part frame (mm).
    pub fn from_box(
        min: Point3<f64>,
        max: Point3<f64>,
        resolution_mm: f64,
    ) -> Result<Stock, StockError> {
        let mut s = Stock::empty(min, max, resolution_mm)?;
        let (lo, hi) = ([min.x, min.y, min.z], [max.x, max.y, max.z]);
        let (origin, h) = (s.origin, s.resolution);
        for f in &mut s.families {
            let (k, u, v, nu) = (f.axis, f.u, f.v, f.nu);
            f.rays.par_chunks_mut(nu).enumerate().for_each(|(iv, row)| {
                let pv = origin[v] + (iv as f64 + 0.5) * h;
                for (iu, ray) in row.iter_mut().enumerate() {
                    let pu = origin[u] + (iu as f64 + 0.5) * h;
                    if pu <= hi[u] && pv <= hi[v] && pu >= lo[u] && pv >= lo[v] {
                        ray.push(Segment {
                            lo: lo[k],
                            hi: hi[k],
                            lo_move: UNCUT,
                            hi_move: UNCUT,
                        });
                    }
                }
            });
        }
        s.initial_volume = s.volume_mm3();
        Ok(s)
    }

    pub(crate) fn families_mut(&mut self) -> &mut [Family; 3] {
        &mut self.families
    }

    pub(crate) fn set_initial_volume(&mut self) {
        self.initial_volume = self.volume_mm3();
    }

    /// The box where material can be: the lattice's cells.
    fn lattice_box(&self) -> Aabb {
        (
            self.origin,
            std::array::from_fn(|i| self.origin[i] + self.counts[i] as f64 * self.resolution),
        )
    }

    /// How cuts visit the rays ([`Removal::Fast`] unless set).
    pub fn removal(&self) -> Removal {
        self.removal
    }

    /// Chooses how cuts visit the rays; both give the same stock.
    pub fn set_removal(&mut self, removal: Removal) {
        self.removal = removal;
    }

    /// The ray spacing, mm.
    pub fn resolution_mm(&self) -> f64 {
        self.resolution
    }

    /// The lattice's low corner.
    pub fn origin(&self) -> Point3<f64> {
        Point3::from(self.origin)
    }

    /// Lattice nodes along X, Y, Z.
    pub fn counts(&self) -> [usize; 3] {
        self.counts
    }

    /// The lattice's high corner.
    pub fn max_corner(&self) -> Point3<f64> {
        Point3::from(std::array::from_fn(|i| {
            self.origin[i] + self.counts[i] as f64 * self.resolution
        }))
    }

    /// The rays along axis `k` (0 = X, 1 = Y, 2 = Z).
    pub fn family(&self, k: usize) -> &Family {
        &self.families[k]
    }

    /// Coordinate of lattice index `n` along axis `i`.
    pub fn coordinate(&self, i: usize, n: usize) -> f64 {
        self.origin[i] + (n as f64 + 0.5) * self.resolution
    }

    /// Number of rays of the three families.
    pub fn ray_count(&self) -> usize {
        self.families.iter().map(|f| f.rays.len()).sum()
    }

    /// Number of solid intervals held.
    pub fn interval_count(&self) -> usize {
        self.families
            .iter()
            .map(|f| f.rays.iter().map(|r| r.len()).sum::<usize>())
            .sum()
    }

    /// Bytes of the interval storage.
    pub fn memory_bytes(&self) -> usize {
        self.families
            .iter()
            .map(|f| {
                f.rays.capacity() * std::mem::size_of::<Ray>()
                    + f.rays
                        .iter()
                        .filter(|r| r.spilled())
                        .map(|r| r.capacity() * std::mem::size_of::<Segment>())
                        .sum::<usize>()
            })
            .sum()
    }

    /// The material volume, mm³: the mean over the three families of the
    /// summed interval lengths times the cell area (each family alone
    /// integrates the volume by the midpoint rule), less two thirds of the
    /// volume ground by the process model: grinding removes its depths
    /// (often a fraction of the ray spacing) along the family nearest the
    /// tool axis only, which the other two families do not see.
    pub fn volume_mm3(&self) -> f64 {
        self.family_mean_volume() - 2.0 / 3.0 * self.ground_volume
    }

    /// The volume grinding removed so far ([`Stock::volume_mm3`]).
    pub(crate) fn note_ground(&mut self, volume_mm3: f64) {
        self.ground_volume += volume_mm3;
    }

    /// The mean over the three families of their integrated volumes.
    fn family_mean_volume(&self) -> f64 {
        let h2 = self.resolution * self.resolution;
        let sum: f64 = self
            .families
            .iter()
            .map(|f| {
                f.rays
                    .iter()
                    .map(|r| r.iter().map(|s| s.hi - s.lo).sum::<f64>())
                    .sum::<f64>()
            })
            .sum();
        sum * h2 / 3.0
    }

    /// Volume removed since the stock was made, mm³.
    pub fn removed_volume_mm3(&self) -> f64 {
        self.initial_volume - self.volume_mm3()
    }

    /// Removes the tool at one pose.
    pub fn cut_pose(&mut self, tool: &Tool, pose: &ToolPose, move_id: u32) -> Result<(), CutError> {
        let placed = tool.place(pose)?;
        let mut solids = Vec::new();
        placed_solids(&placed, &self.lattice_box(), 1, &mut solids);
        self.remove(&solids, &[UNCUT, move_id]);
        self.last = Some((*tool, *pose));
        Ok(())
    }

    /// Removes what the tool sweeps moving from one pose to the next.
    ///
    /// * A pure translation (same axis and reference, to `SAME_AXIS`) is
    ///   swept exactly for cylinders and spheres (see [`crate::kernel`]); cone
    ///   and rounded-disc pieces are sampled along it.
    ///   The solid translates when its axis of revolution stays (for the
    ///   contact wheel reference × tool axis: a lead-angle change turns the
    ///   wheel about its own axis); its frame origin then moves on the
    ///   chord between the poses' (for a wheel whose tool axis turns by θ,
    ///   R·θ²/8 from the arc the interpolated poses' centres follow).
    /// * Otherwise the pose is interpolated (point linearly, axis and
    ///   reference along great circles) at n + 1 samples, n the smallest
    ///   count with (|Δpoint| + ρ·(θ_axis + θ_reference)) / n ≤
    ///   `SAMPLE_STEP_FRACTION` · resolution, ρ the largest distance from
    ///   the tool point of a tool point that can reach the stock's box: no
    ///   such point moves more than one ray spacing between two samples.
    ///
    /// The start pose is not cut again when it is the last pose cut with
    /// the same tool (a continuous program).
    pub fn cut_move(
        &mut self,
        tool: &Tool,
        from: &ToolPose,
        to: &ToolPose,
        move_id: u32,
    ) -> Result<MoveCut, CutError> {
        let mut solids = Vec::new();
        let cut = self.move_solids(tool, from, to, &mut solids)?;
        self.remove(&solids, &[UNCUT, move_id]);
        self.last = Some((*tool, *to));
        Ok(cut)
    }

    /// Cuts the moves in order: the stock [`Stock::cut_move`] called on
    /// each would give, bit for bit (every interval end and the move that
    /// made it), in one visit of the rays instead of one a move. Consecutive
    /// moves over the same part of the stock are cut together: a ray's
    /// level is found once for all of them, and the threads share rows of a
    /// whole batch rather than of one short move. (Moves spread far apart
    /// are cut in several visits, so a visit's rows stay those the tools
    /// cover.)
    ///
    /// Returns how each move was cut. A move that cannot be cut is an
    /// error naming it; the moves before it are cut, as one by one.
    pub fn cut_moves(&mut self, tool: &Tool, moves: &[Move]) -> Result<Vec<MoveCut>, BatchError> {
        let mut cuts = Vec::with_capacity(moves.len());
        let mut solids: Vec<Bounded> = Vec::new();
        let mut fresh: Vec<Bounded> = Vec::new();
        let mut ids = vec![UNCUT];
        let mut spread = Spread::default();
        let h = self.resolution;
        for (index, m) in moves.iter().enumerate() {
            fresh.clear();
            let cut = match self.move_solids(tool, &m.from, &m.to, &mut fresh) {
                Ok(cut) => cut,
                Err(source) => {
                    self.remove(&solids, &ids);
                    return Err(BatchError { index, source });
                }
            };
            cuts.push(cut);
            // A visit holds at most MOVES_PER_VISIT moves, close together:
            // else what is gathered is cut and this move starts the next.
            let bounds = solids_bounds(&fresh);
            if ids.len() > MOVES_PER_VISIT || bounds.is_some_and(|b| !spread.admits(&b, h)) {
                self.remove(&solids, &ids);
                solids.clear();
                ids.truncate(1);
                spread = Spread::default();
                if let Some(b) = bounds {
                    spread.admits(&b, h);
                }
            }
            // (At most MOVES_PER_VISIT + 1 ids.)
            let seq = ids.len() as u32;
            for f in &mut fresh {
                f.seq = seq;
            }
            solids.append(&mut fresh);
            ids.push(m.id);
            self.last = Some((*tool, m.to));
        }
        self.remove(&solids, &ids);
        Ok(cuts)
    }

    /// The solids that sweep the tool from one pose to the next, as the
    /// first move of a batch (appended to `solids`); the start pose is left
    /// out when it is the last pose cut with the same tool.
    fn move_solids(
        &self,
        tool: &Tool,
        from: &ToolPose,
        to: &ToolPose,
        solids: &mut Vec<Bounded>,
    ) -> Result<MoveCut, CutError> {
        let seq = 1;
        let p0 = tool.place(from)?;
        let p1 = tool.place(to)?;
        let start_done = self
            .last
            .as_ref()
            .is_some_and(|(t, p)| t == tool && p == from);
        // The solid only translates when its axis of revolution stays: a
        // wheel whose tool axis turns about the wheel's own axis (a lead
        // angle change) still translates.
        let same_axis = (p0.axis - p1.axis).norm() <= SAME_AXIS;
        let step = SAMPLE_STEP_FRACTION * self.resolution;
        let mut samples = 0u64;
        let boxed = self.lattice_box();
        let result = if same_axis {
            let v = p1.origin - p0.origin;
            for piece in &p0.pieces {
                match *piece {
                    Piece::Sphere { zc, r } => {
                        let c0 = p0.origin.coords + zc * p0.axis;
                        if let Some((lo, hi)) =
                            swept_in_box(piece, &p0.origin, &p0.axis, &v, &boxed)
                        {
                            solids.push(Bounded {
                                solid: Solid::Capsule { c0, v, r },
                                lo,
                                hi,
                                seq,
                            });
                        }
                    }
                    Piece::Cylinder { z0, z1, r } => {
                        if let Some((lo, hi)) =
                            swept_in_box(piece, &p0.origin, &p0.axis, &v, &boxed)
                        {
                            solids.push(Bounded {
                                solid: Solid::CylinderSweep {
                                    origin: p0.origin.coords,
                                    axis: p0.axis,
                                    z0,
                                    z1,
                                    r,
                                    v,
                                },
                                lo,
                                hi,
                                seq,
                            });
                        }
                    }
                    Piece::Cone { .. } | Piece::RoundedDisc { .. } => {
                        let n = sample_count(v.norm(), step)?;
                        samples = samples.max(n + 1);
                        for i in 0..=n {
                            if i == 0 && start_done {
                                continue;
                            }
                            let o = p0.origin + v * (i as f64 / n as f64);
                            if let Some((lo, hi)) = piece_in_box(piece, &o, &p0.axis, &boxed) {
                                solids.push(Bounded {
                                    solid: Solid::Piece {
                                        piece: *piece,
                                        origin: o.coords,
                                        axis: p0.axis,
                                    },
                                    lo,
                                    hi,
                                    seq,
                                });
                            }
                        }
                    }
                }
            }
            MoveCut {
                samples,
                analytic: true,
            }
        } else {
            let angle = |a: &Unit<Vector3<f64>>, b: &Unit<Vector3<f64>>| a.angle(b);
            let theta = angle(&from.axis, &to.axis)
                + match (from.reference, to.reference) {
                    (Some(a), Some(b)) => angle(&a, &b),
                    _ => 0.0,
                };
            let travel = (to.point - from.point).norm();
            let naive = travel + (p0.reach() + (p0.origin - from.point).norm()) * theta;
            // Only tool points that can reach the stock's box matter: those
            // within the box grown by the naive bound at either end.
            let grown: Aabb = (boxed.0.map(|c| c - naive), boxed.1.map(|c| c + naive));
            let mut rho: f64 = 0.0;
            for (placed, pose) in [(&p0, from), (&p1, to)] {
                for piece in &placed.pieces {
                    if let Some((lo, hi)) =
                        piece_in_box(piece, &placed.origin, &placed.axis, &grown)
                    {
                        for c in 0..8 {
                            let corner =
                                Vector3::from_fn(
                                    |i, _| if c >> i & 1 == 0 { lo[i] } else { hi[i] },
                                );
                            rho = rho.max((corner - pose.point.coords).norm());
                        }
                    }
                }
            }
            let n = sample_count(travel + rho * theta, step)?;
            for i in 0..=n {
                if i == 0 && start_done {
                    continue;
                }
                let pose = interpolate(from, to, i as f64 / n as f64).ok_or(CutError::HalfTurn)?;
                placed_solids(&tool.place(&pose)?, &boxed, seq, solids);
            }
            MoveCut {
                samples: n + 1 - u64::from(start_done),
                analytic: false,
            }
        };
        Ok(result)
    }

    /// Cuts the poses of one move in order: each consecutive pair as
    /// [`Stock::cut_move`] (a single pose as [`Stock::cut_pose`]).
    pub fn cut(&mut self, tool: &Tool, poses: &[ToolPose], move_id: u32) -> Result<(), CutError> {
        match poses {
            [] => Ok(()),
            [p] => self.cut_pose(tool, p, move_id),
            _ => {
                let moves: Vec<Move> = poses
                    .windows(2)
                    .map(|w| Move {
                        from: w[0],
                        to: w[1],
                        id: move_id,
                    })
                    .collect();
                self.cut_moves(tool, &moves)
                    .map(|_| ())
                    .map_err(|e| e.source)
            }
        }
    }

    /// Subtracts the union of the solids from every ray that crosses their
    /// bounds, by the chosen [`Removal`].
    /// `ids[seq]` is the id of the batch's move `seq` (`ids[0]` unused).
    fn remove(&mut self, solids: &[Bounded], ids: &[u32]) {
        match self.removal {
            Removal::Fast => self.remove_fast(solids, ids),
            Removal::Reference => {
                // Move by move (a move's solids are consecutive).
                for group in solids.chunk_by(|a, b| a.seq == b.seq) {
                    self.remove_reference(group, ids[group[0].seq as usize]);
                }
            }
        }
    }

    /// The straightforward removal: every solid's span on every ray within
    /// the solid's bounds, united and subtracted. Rows of rays run in
    /// parallel; every ray is handled alone, so the result does not depend
    /// on the thread count.
    fn remove_reference(&mut self, solids: &[Bounded], id: u32) {
        if solids.is_empty() {
            return;
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for s in solids {
            for i in 0..3 {
                lo[i] = lo[i].min(s.lo[i]);
                hi[i] = hi[i].max(s.hi[i]);
            }
        }
        let (origin, h) = (self.origin, self.resolution);
        let counts = self.counts;
        // Index range of the rays whose coordinate along axis i is in [lo, hi].
        let range = |i: usize| -> Option<(usize, usize)> {
            let a = ((lo[i] - origin[i]) / h - 0.5).ceil().max(0.0);
            let b = ((hi[i] - origin[i]) / h - 0.5)
                .floor()
                .min(counts[i] as f64 - 1.0);
            (a <= b).then_some((a as usize, b as usize))
        };
        for f in &mut self.families {
            let (k, u, v, nu) = (f.axis, f.u, f.v, f.nu);
            let (Some((u0, u1)), Some((v0, v1))) = (range(u), range(v)) else {
                continue;
            };
            // Along the ray, only the solids' extent matters.
            if hi[k] < origin[k] || lo[k] > origin[k] + counts[k] as f64 * h {
                continue;
            }
            let mut d = Vector3::zeros();
            d[k] = 1.0;
            f.rays[v0 * nu..(v1 + 1) * nu]
                .par_chunks_mut(nu)
                .enumerate()
                .for_each(|(jv, row)| {
                    let pv = origin[v] + ((v0 + jv) as f64 + 0.5) * h;
                    let mut spans: Vec<Span> = Vec::with_capacity(8);
                    for (ju, ray) in row[u0..=u1].iter_mut().enumerate() {
                        if ray.is_empty() {
                            continue;
                        }
                        let pu = origin[u] + ((u0 + ju) as f64 + 0.5) * h;
                        let mut o = Vector3::zeros();
                        o[u] = pu;
                        o[v] = pv;
                        spans.clear();
                        let (first, last) = (ray[0].lo, ray[ray.len() - 1].hi);
                        for s in solids {
                            if pu < s.lo[u]
                                || pu > s.hi[u]
                                || pv < s.lo[v]
                                || pv > s.hi[v]
                                || s.hi[k] <= first
                                || s.lo[k] >= last
                            {
                                continue;
                            }
                            if let Some(sp) = s.span(&o, &d, (k, u, v)) {
                                spans.push(sp);
                            }
                        }
                        remove_spans(ray, &mut spans, id);
                    }
                });
        }
    }

    /// The fast removal: the stock [`Stock::remove_reference`] gives cutting
    /// the batch's moves one by one, bit for bit, computing far fewer spans.
    /// Each family's rows go to [`crate::row::cut_tile`] eight at a time
    /// (the three families at once, tiles in parallel): on each ray the
    /// solids are visited in [`visit_order`], and a solid is skipped where
    /// its span certainly starts at or above the ray's level (the top of its
    /// material, lowered to the start of every span found that reaches the
    /// top), ray by ray or a whole segment of a tile at once. The reasons,
    /// and why this changes no bit, are in the `row` module's doc.
    fn remove_fast(&mut self, solids: &[Bounded], ids: &[u32]) {
        let Some((lo, hi)) = solids_bounds(solids) else {
            return;
        };
        let order = visit_order(solids.len());
        let (origin, h, counts) = (self.origin, self.resolution, self.counts);
        // The three families at once (their rays are apart), each by rows.
        self.families.par_iter_mut().for_each(|f| {
            let (k, u, v, nu) = (f.axis, f.u, f.v, f.nu);
            let (Some((u0, u1)), Some((v0, v1))) = (
                index_range(origin[u], h, counts[u], lo[u], hi[u]),
                index_range(origin[v], h, counts[v], lo[v], hi[v]),
            ) else {
                return;
            };
            if hi[k] < origin[k] || lo[k] > origin[k] + counts[k] as f64 * h {
                return;
            }
            let mut d = Vector3::zeros();
            d[k] = 1.0;
            let kuv = (k, u, v);
            let prepared: Vec<RowSolid> = solids.iter().map(|s| s.row_solid(&d)).collect();
            let along: Vec<(f64, f64)> = solids.iter().map(|s| (s.lo[k], s.hi[k])).collect();
            let span = |i: usize, pu: f64, pv: f64| {
                let mut o = Vector3::zeros();
                o[u] = pu;
                o[v] = pv;
                solids[i].span(&o, &d, kuv)
            };
            let row_solids = RowSolids {
                prepared: &prepared,
                along: &along,
                span: &span,
            };
            // Tiles of rows, sixteen tasks a thread: tiles differ in work
            // (a tool's deepest rays against its rim), and a visit's work
            // is a few milliseconds.
            let rows = v1 + 1 - v0;
            let tiles = rows.div_ceil(TILE_ROWS);
            let per_task = tiles.div_ceil(16 * rayon::current_num_threads()).max(1);
            f.rays[v0 * nu..(v1 + 1) * nu]
                .par_chunks_mut(nu * TILE_ROWS)
                .with_min_len(per_task)
                .enumerate()
                .for_each(|(jt, tile)| {
                    SCRATCH.with_borrow_mut(|(active, pv, scratch)| {
                        let first_row = v0 + jt * TILE_ROWS;
                        pv.clear();
                        pv.extend(
                            (0..tile.len() / nu)
                                .map(|r| origin[v] + ((first_row + r) as f64 + 0.5) * h),
                        );
                        let pu_at = |iu: usize| origin[u] + (iu as f64 + 0.5) * h;
                        // The solids that meet this tile, in the visiting
                        // order, with the rays and the rows within their
                        // bounds (the reference's test lo ≤ p ≤ hi; p grows
                        // with the index).
                        active.clear();
                        for &si in &order {
                            let s = &solids[si];
                            let r0 = pv.partition_point(|&p| p < s.lo[v]);
                            let r1 = pv.partition_point(|&p| p <= s.hi[v]);
                            if r0 >= r1 {
                                continue;
                            }
                            if let Some((a, b)) = rays_within(&pu_at, u0, u1, s.lo[u], s.hi[u]) {
                                active.push(Active {
                                    solid: si,
                                    a,
                                    b,
                                    r0,
                                    r1: r1 - 1,
                                    seq: s.seq,
                                });
                            }
                        }
                        let frame = RowFrame {
                            k,
                            origin_u: origin[u],
                            h,
                            pv,
                            nu,
                        };
                        cut_tile(&frame, tile, active, &row_solids, ids, scratch);
                    })
                });
        });
    }
}

thread_local! {
    /// Each thread's buffers for the tiles it cuts, kept from batch to
    /// batch: the active solids, the rows' coordinates, the rays' levels.
    static SCRATCH: std::cell::RefCell<(Vec<Active>, Vec<f64>, Scratch)> = Default::default();
}

/// Moves a batch cuts in one visit of the rays at most. Longer visits share
/// their setup over more moves, but a ray then meets more solids near its
/// final level that its skip tests cannot tell apart from it (a ball's
/// passes over the same ray): 32 moves of the benchmarks' 0.1 mm do best
/// for the contact wheel and the ball alike (BENCHMARKS.md).
const MOVES_PER_VISIT: usize = 32;

/// Rows the fast removal cuts together: a solid's segments certainly above
/// the levels are found for all of them at once (a solid's bounds, and so
/// its rays, are the same on every row it meets).
const TILE_ROWS: usize = 8;

/// The order the fast removal visits `n` solids in: the last first (on most
/// rays it meets, the most advanced sample of a batch is the deepest), then
/// back through the batch halving the stride (the van der Corput order of
/// the distance from the last: n−1, n−1−2^k, n−1−2^(k−1), ...), so that
/// every ray soon meets a solid near its deepest and most later ones are
/// skipped, a whole row segment at once.
fn visit_order(n: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| ((n - 1 - i) as u64).reverse_bits());
    order
}

/// How far a batch of moves spreads: the union of its moves' bounds and
/// the sum of their areas as each family of rays sees them (the rays a
/// visit sets up against those the tools cover).
#[derive(Default)]
struct Spread {
    union: Option<([f64; 3], [f64; 3])>,
    areas: [f64; 3],
}

impl Spread {
    /// Rays a visit may set up per ray a tool covers, family by family,
    /// before a batch is cut in two visits.
    const MAX_RATIO: f64 = 4.0;

    /// Adds a move's bounds when the batch then stays compact (or is
    /// empty); `false` (nothing added) when it would spread too thin.
    fn admits(&mut self, b: &([f64; 3], [f64; 3]), h: f64) -> bool {
        // Each family's area (across its rays), with a ray's spacing added
        // so that a flat box counts the rays it meets.
        let area = |lo: &[f64; 3], hi: &[f64; 3]| -> [f64; 3] {
            std::array::from_fn(|k| {
                let (u, v) = ((k + 1) % 3, (k + 2) % 3);
                (hi[u] - lo[u] + h) * (hi[v] - lo[v] + h)
            })
        };
        let mine = area(&b.0, &b.1);
        let Some(u) = self.union else {
            self.union = Some(*b);
            self.areas = mine;
            return true;
        };
        let joined: ([f64; 3], [f64; 3]) = (
            std::array::from_fn(|i| u.0[i].min(b.0[i])),
            std::array::from_fn(|i| u.1[i].max(b.1[i])),
        );
        let whole = area(&joined.0, &joined.1);
        let sums: [f64; 3] = std::array::from_fn(|k| self.areas[k] + mine[k]);
        if (0..3).any(|k| !(whole[k] <= Self::MAX_RATIO * sums[k])) {
            return false;
        }
        self.union = Some(joined);
        self.areas = sums;
        true
    }
}

/// The union of the solids' bounds.
fn solids_bounds(solids: &[Bounded]) -> Option<([f64; 3], [f64; 3])> {
    if solids.is_empty() {
        return None;
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for s in solids {
        for i in 0..3 {
            lo[i] = lo[i].min(s.lo[i]);
            hi[i] = hi[i].max(s.hi[i]);
        }
    }
    Some((lo, hi))
}

/// The first and last index in [a, b] whose coordinate `at(i)` (growing
/// with i) is within [lo, hi]: a guess from the spacing, then corrected by
/// the comparisons themselves.
fn rays_within(
    at: &impl Fn(usize) -> f64,
    a: usize,
    b: usize,
    lo: f64,
    hi: f64,
) -> Option<(usize, usize)> {
    // Binary searches for the first index with at(i) ≥ lo and the last with
    // at(i) ≤ hi.
    let first = {
        let (mut l, mut r) = (a, b + 1);
        while l < r {
            let mid = l + (r - l) / 2;
            if at(mid) >= lo { r = mid } else { l = mid + 1 }
        }
        l
    };
    let last = {
        let (mut l, mut r) = (a, b + 1);
        while l < r {
            let mid = l + (r - l) / 2;
            if at(mid) <= hi { l = mid + 1 } else { r = mid }
        }
        l.checked_sub(1)?
    };
    (first <= b && last >= first && last >= a).then_some((first, last))
}

/// Index range of the rays of a lattice axis (origin `o`, spacing `h`,
/// `n` rays) whose coordinate is in [lo, hi].
fn index_range(o: f64, h: f64, n: usize, lo: f64, hi: f64) -> Option<(usize, usize)> {
    let a = ((lo - o) / h - 0.5).ceil().max(0.0);
    let b = ((hi - o) / h - 0.5).floor().min(n as f64 - 1.0);
    (a <= b).then_some((a as usize, b as usize))
}

fn sample_count(distance: f64, step: f64) -> Result<u64, CutError> {
    let n = (distance / step).ceil().max(1.0);
    if !(n <= 1.0e7) {
        return Err(CutError::TooManySamples(if n.is_finite() {
            n as u64
        } else {
            u64::MAX
        }));
    }
    Ok(n as u64)
}

/// The pose a fraction `s` of the way: point linearly, axis and reference
/// along great circles; `None` for a half turn.
fn interpolate(a: &ToolPose, b: &ToolPose, s: f64) -> Option<ToolPose> {
    let slerp = |x: &Unit<Vector3<f64>>, y: &Unit<Vector3<f64>>| -> Option<Unit<Vector3<f64>>> {
        if (x.into_inner() - y.into_inner()).norm() <= SAME_AXIS {
            return Some(*x);
        }
        x.try_slerp(y, s, 1e-9)
    };
    let axis = slerp(&a.axis, &b.axis)?;
    let reference = match (a.reference, b.reference) {
        (Some(x), Some(y)) => Some(slerp(&x, &y)?),
        (x, _) => x,
    };
    Some(ToolPose {
        point: a.point + (b.point - a.point) * s,
        axis,
        reference,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bytes(s: &Stock) -> Vec<u8> {
        let mut out = Vec::new();
        for f in &s.families {
            for ray in &f.rays {
                out.extend((ray.len() as u32).to_le_bytes());
                for seg in ray {
                    out.extend(seg.lo.to_bits().to_le_bytes());
                    out.extend(seg.hi.to_bits().to_le_bytes());
                    out.extend(seg.lo_move.to_le_bytes());
                    out.extend(seg.hi_move.to_le_bytes());
                }
            }
        }
        out
    }

    /// Wheel (sampled, cylinders), ball (capsules), bull nose and drill
    /// (no lane kernel) on a stock across the origin.
    fn cut_all(removal: Removal) -> Vec<u8> {
        let mut s = Stock::from_box(
            Point3::new(-6.0, -4.0, -3.0),
            Point3::new(6.0, 4.0, 1.0),
            0.1,
        )
        .unwrap();
        s.set_removal(removal);
        let tools = [
            Tool::ContactWheel {
                radius: 15.0,
                width: 5.0,
                edge_radius: 0.0,
            },
            Tool::BallEnd {
                diameter: 2.0,
                flute_length: 6.0,
                shank: None,
            },
            Tool::BullNose {
                diameter: 3.0,
                corner_radius: 0.5,
                flute_length: 6.0,
                shank: None,
            },
            Tool::Drill {
                diameter: 1.5,
                point_angle_deg: 118.0,
                flute_length: 5.0,
            },
        ];
        let mut id = 0;
        for (t, tool) in tools.iter().enumerate() {
            let y = -3.0 + 2.0 * t as f64;
            for i in 0..40 {
                let x = -5.0 + 0.25 * i as f64;
                let tilt = 0.05 * (i as f64).sin();
                let pose = |x: f64, tilt: f64| {
                    ToolPose::new(Point3::new(x, y, 0.7), Vector3::new(0.0, -tilt, 1.0))
                        .with_reference(Vector3::x())
                };
                s.cut_move(tool, &pose(x, tilt), &pose(x + 0.25, -tilt), id)
                    .unwrap();
                id += 1;
            }
        }
        bytes(&s)
    }

    #[test]
    fn the_portable_and_the_avx2_paths_give_the_reference_stock() {
        let reference = cut_all(Removal::Reference);
        crate::row::FORCE_PORTABLE.store(true, std::sync::atomic::Ordering::Relaxed);
        let portable = cut_all(Removal::Fast);
        crate::row::FORCE_PORTABLE.store(false, std::sync::atomic::Ordering::Relaxed);
        let dispatched = cut_all(Removal::Fast);
        assert!(portable == reference, "the portable path differs");
        assert!(dispatched == reference, "the dispatched path differs");
    }
}
