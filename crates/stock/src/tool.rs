//! Tools as solids of revolution, placed by a pose in the part frame.
//!
//! Every tool is a union of convex *pieces*, each a solid of revolution
//! about the tool's own axis line: a cylinder, a sphere, a cone frustum, or
//! a rounded disc (a flat disc grown by a ball: the corner of a bull-nose
//! mill, the rounded edge of a wheel). A [`PlacedTool`] is a tool at one
//! pose: the origin of its axial coordinate and its unit axis in the part
//! frame.

use nalgebra::{Point3, Unit, Vector3};
use serde::{Deserialize, Serialize};

/// Where a tool is, in the part frame (mm).
///
/// * `point`: the tool point. For end mills and drills the tip centre; for
///   the belt's contact wheel the contact point on the rim; for the disc
///   wheel the contact point on the rim of its grinding face.
/// * `axis`: unit tool axis. For end mills and drills it points from the tip
///   towards the spindle (APT). For the contact wheel it points from the
///   contact point towards the wheel centre; for the disc wheel it is the
///   grinding-face normal, pointing from the part into the wheel.
/// * `reference`: for the contact wheel the feed direction (kinpost's CL
///   convention: the wheel's rotation axis is reference × axis); for the
///   disc wheel the direction, in the face, from the contact point towards
///   the face centre. Milling tools ignore it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolPose {
    /// The tool point, mm.
    pub point: Point3<f64>,
    /// The unit tool axis.
    pub axis: Unit<Vector3<f64>>,
    /// The reference direction, when the tool needs one.
    pub reference: Option<Unit<Vector3<f64>>>,
}

impl ToolPose {
    /// A pose from a point and an axis, without reference.
    pub fn new(point: Point3<f64>, axis: Vector3<f64>) -> Self {
        Self {
            point,
            axis: Unit::new_normalize(axis),
            reference: None,
        }
    }

    /// The same pose with a reference direction.
    pub fn with_reference(mut self, reference: Vector3<f64>) -> Self {
        self.reference = Some(Unit::new_normalize(reference));
        self
    }
}

/// A tool's shape. All lengths in mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Tool {
    /// Flat end mill: cutting diameter, flute length; an optional shank.
    FlatEnd {
        /// Cutting diameter, mm.
        diameter: f64,
        /// Flute length from the tip, mm.
        flute_length: f64,
        /// Optional shank above the flutes.
        #[serde(default)]
        shank: Option<Shank>,
    },
    /// Ball end mill.
    BallEnd {
        /// Cutting diameter, mm.
        diameter: f64,
        /// Flute length from the tip, mm.
        flute_length: f64,
        /// Optional shank above the flutes.
        #[serde(default)]
        shank: Option<Shank>,
    },
    /// Bull-nose (torus) end mill.
    BullNose {
        /// Cutting diameter, mm.
        diameter: f64,
        /// Corner radius, mm (0 < corner_radius ≤ diameter / 2).
        corner_radius: f64,
        /// Flute length from the tip, mm.
        flute_length: f64,
        /// Optional shank above the flutes.
        #[serde(default)]
        shank: Option<Shank>,
    },
    /// Twist drill: a cone of the given point angle, then the body.
    Drill {
        /// Diameter, mm.
        diameter: f64,
        /// Included point angle, degrees (118 for a standard drill).
        point_angle_deg: f64,
        /// Flute length from the tip, mm.
        flute_length: f64,
    },
    /// The belt's contact wheel (belt grinding): a cylinder of the given
    /// radius and width, its edges optionally rounded.
    ContactWheel {
        /// Wheel radius including the belt, mm.
        radius: f64,
        /// Wheel (belt) width, mm.
        width: f64,
        /// Edge radius, mm (0 for sharp edges; at most half the width).
        #[serde(default)]
        edge_radius: f64,
    },
    /// The disc wheel of an A/C tool grinder (Li (B-spline grinding), §5):
    /// it grinds with the rim of its flat face.
    DiscWheel {
        /// Radius of the grinding face, mm.
        radius: f64,
        /// Thickness of the disc behind the face, mm.
        thickness: f64,
    },
}

/// A plain cylindrical shank above the flutes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shank {
    /// Shank diameter, mm.
    pub diameter: f64,
    /// Shank length above the flutes, mm.
    pub length: f64,
}

/// A convex solid of revolution about the tool's axis line, in the tool's
/// axial coordinate z (mm along the axis from the frame origin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Piece {
    /// Radius `r` for z in [z0, z1].
    Cylinder {
        /// Lower axial end.
        z0: f64,
        /// Upper axial end.
        z1: f64,
        /// Radius.
        r: f64,
    },
    /// Sphere of radius `r` centred on the axis at `zc`.
    Sphere {
        /// Axial position of the centre.
        zc: f64,
        /// Radius.
        r: f64,
    },
    /// Cone frustum: radius r0 at z0 growing linearly to r1 at z1 (z0 < z1).
    Cone {
        /// Lower axial end.
        z0: f64,
        /// Radius at z0.
        r0: f64,
        /// Upper axial end.
        z1: f64,
        /// Radius at z1.
        r1: f64,
    },
    /// The points within `r` of the flat disc of radius `disc` at `zc`
    /// (disc ⊕ ball: a torus with its hole filled).
    RoundedDisc {
        /// Axial position of the disc.
        zc: f64,
        /// Radius of the disc.
        disc: f64,
        /// Radius of the ball grown around it.
        r: f64,
    },
}

/// Why a tool or a pose cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ToolError {
    /// A dimension is not a positive finite number (or out of its range).
    #[error("tool dimension `{name}` = {value} mm: {why}")]
    Dimension {
        /// The dimension's name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// A wheel pose lacks the reference direction it needs.
    #[error(
        "the {tool} needs a reference direction in its poses (the feed direction for the contact wheel, the direction to the face centre for the disc wheel)"
    )]
    MissingReference {
        /// The tool's name.
        tool: &'static str,
    },
    /// The reference is (nearly) parallel to the tool axis.
    #[error(
        "the reference direction is parallel to the tool axis: the {tool}'s orientation is undefined"
    )]
    ReferenceAlongAxis {
        /// The tool's name.
        tool: &'static str,
    },
    /// A pose has a coordinate that is not finite.
    #[error("a tool pose has a coordinate that is not a finite number")]
    NotFinite,
}

fn positive(name: &'static str, value: f64) -> Result<f64, ToolError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ToolError::Dimension {
            name,
            value,
            why: "must be a positive number",
        })
    }
}

impl Tool {
    /// The tool's name, for messages.
    pub fn name(&self) -> &'static str {
        match self {
            Tool::FlatEnd { .. } => "flat end mill",
            Tool::BallEnd { .. } => "ball end mill",
            Tool::BullNose { .. } => "bull-nose end mill",
            Tool::Drill { .. } => "drill",
            Tool::ContactWheel { .. } => "contact wheel",
            Tool::DiscWheel { .. } => "disc wheel",
        }
    }

    /// Checks the dimensions and returns the pieces in the tool's own
    /// axial coordinate (see [`PlacedTool`] for where z = 0 is).
    pub fn pieces(&self) -> Result<Vec<Piece>, ToolError> {
        let shank =
            |pieces: &mut Vec<Piece>, flute: f64, s: &Option<Shank>| -> Result<(), ToolError> {
                if let Some(s) = s {
                    let r = positive("shank diameter", s.diameter)? / 2.0;
                    let len = positive("shank length", s.length)?;
                    pieces.push(Piece::Cylinder {
                        z0: flute,
                        z1: flute + len,
                        r,
                    });
                }
                Ok(())
            };
        let mut p = Vec::new();
        match *self {
            Tool::FlatEnd {
                diameter,
                flute_length,
                shank: ref s,
            } => {
                let r = positive("diameter", diameter)? / 2.0;
                let l = positive("flute length", flute_length)?;
                p.push(Piece::Cylinder { z0: 0.0, z1: l, r });
                shank(&mut p, l, s)?;
            }
            Tool::BallEnd {
                diameter,
                flute_length,
                shank: ref s,
            } => {
                let r = positive("diameter", diameter)? / 2.0;
                let l = positive("flute length", flute_length)?;
                p.push(Piece::Sphere { zc: r, r });
                if l > r {
                    p.push(Piece::Cylinder { z0: r, z1: l, r });
                }
                shank(&mut p, l.max(r), s)?;
            }
            Tool::BullNose {
                diameter,
                corner_radius,
                flute_length,
                shank: ref s,
            } => {
                let r = positive("diameter", diameter)? / 2.0;
                let rc = positive("corner radius", corner_radius)?;
                let l = positive("flute length", flute_length)?;
                if rc > r {
                    return Err(ToolError::Dimension {
                        name: "corner radius",
                        value: rc,
                        why: "must not exceed half the diameter",
                    });
                }
                p.push(Piece::RoundedDisc {
                    zc: rc,
                    disc: r - rc,
                    r: rc,
                });
                if l > rc {
                    p.push(Piece::Cylinder { z0: rc, z1: l, r });
                }
                shank(&mut p, l.max(2.0 * rc), s)?;
            }
            Tool::Drill {
                diameter,
                point_angle_deg,
                flute_length,
            } => {
                let r = positive("diameter", diameter)? / 2.0;
                let l = positive("flute length", flute_length)?;
                if !(point_angle_deg.is_finite()
                    && point_angle_deg > 0.0
                    && point_angle_deg < 180.0)
                {
                    return Err(ToolError::Dimension {
                        name: "point angle",
                        value: point_angle_deg,
                        why: "must be between 0 and 180 degrees",
                    });
                }
                let tip = r / (point_angle_deg.to_radians() / 2.0).tan();
                p.push(Piece::Cone {
                    z0: 0.0,
                    r0: 0.0,
                    z1: tip,
                    r1: r,
                });
                if l > tip {
                    p.push(Piece::Cylinder { z0: tip, z1: l, r });
                }
            }
            Tool::ContactWheel {
                radius,
                width,
                edge_radius,
            } => {
                let r = positive("wheel radius", radius)?;
                let w = positive("wheel width", width)?;
                if !(edge_radius.is_finite()
                    && edge_radius >= 0.0
                    && edge_radius <= w / 2.0
                    && edge_radius < r)
                {
                    return Err(ToolError::Dimension {
                        name: "edge radius",
                        value: edge_radius,
                        why: "must be 0 or more, at most half the width and below the radius",
                    });
                }
                if edge_radius == 0.0 {
                    p.push(Piece::Cylinder {
                        z0: -w / 2.0,
                        z1: w / 2.0,
                        r,
                    });
                } else {
                    let zc = w / 2.0 - edge_radius;
                    p.push(Piece::RoundedDisc {
                        zc: -zc,
                        disc: r - edge_radius,
                        r: edge_radius,
                    });
                    p.push(Piece::RoundedDisc {
                        zc,
                        disc: r - edge_radius,
                        r: edge_radius,
                    });
                    if zc > 0.0 {
                        p.push(Piece::Cylinder { z0: -zc, z1: zc, r });
                    }
                }
            }
            Tool::DiscWheel { radius, thickness } => {
                let r = positive("wheel radius", radius)?;
                let t = positive("disc thickness", thickness)?;
                p.push(Piece::Cylinder { z0: 0.0, z1: t, r });
            }
        }
        Ok(p)
    }

    /// Places the tool at a pose: the origin and axis of its pieces.
    pub fn place(&self, pose: &ToolPose) -> Result<PlacedTool, ToolError> {
        let finite = pose
            .point
            .iter()
            .chain(pose.axis.iter())
            .all(|v| v.is_finite())
            && pose
                .reference
                .is_none_or(|r| r.iter().all(|v| v.is_finite()));
        if !finite {
            return Err(ToolError::NotFinite);
        }
        let pieces = self.pieces()?;
        let axis = pose.axis.into_inner();
        let (origin, axis) = match *self {
            Tool::ContactWheel { radius, .. } => {
                let reference = pose
                    .reference
                    .ok_or(ToolError::MissingReference { tool: self.name() })?;
                let rotation = reference.cross(&axis);
                let n = rotation.norm();
                if n < 1e-9 {
                    return Err(ToolError::ReferenceAlongAxis { tool: self.name() });
                }
                (pose.point + radius * axis, rotation / n)
            }
            Tool::DiscWheel { radius, .. } => {
                let reference = pose
                    .reference
                    .ok_or(ToolError::MissingReference { tool: self.name() })?;
                let inward = reference.into_inner() - reference.dot(&axis) * axis;
                let n = inward.norm();
                if n < 1e-9 {
                    return Err(ToolError::ReferenceAlongAxis { tool: self.name() });
                }
                (pose.point + radius * inward / n, axis)
            }
            _ => (pose.point, axis),
        };
        Ok(PlacedTool {
            origin,
            axis,
            pieces,
        })
    }
}

/// A tool at one pose: its pieces about the line through `origin` along
/// the unit vector `axis` (part frame, mm).
///
/// The origin is the tip centre for end mills and drills, the wheel centre
/// for the contact wheel (its axis is the rotation axis, reference × tool
/// axis), the centre of the grinding face for the disc wheel (its axis the
/// face normal, into the wheel).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedTool {
    /// Origin of the axial coordinate.
    pub origin: Point3<f64>,
    /// Unit axis of revolution.
    pub axis: Vector3<f64>,
    /// The convex pieces.
    pub pieces: Vec<Piece>,
}

impl Piece {
    /// The largest distance of a point of the piece from the frame origin.
    pub fn reach(&self) -> f64 {
        match *self {
            Piece::Cylinder { z0, z1, r } => z0.abs().max(z1.abs()).hypot(r),
            Piece::Sphere { zc, r } => zc.abs() + r,
            Piece::Cone { z0, r0, z1, r1 } => z0.abs().hypot(r0).max(z1.abs().hypot(r1)),
            Piece::RoundedDisc { zc, disc, r } => zc.abs().hypot(disc) + r,
        }
    }

    /// Axis-aligned bounds of the piece placed at `origin` along `axis`.
    pub fn bounds(&self, origin: &Point3<f64>, axis: &Vector3<f64>) -> (Point3<f64>, Point3<f64>) {
        // A disc of radius r with unit normal w spans r·sqrt(1 − w_i²) along axis i.
        let disc = |z: f64, r: f64, grow: f64| {
            let c = origin + z * axis;
            let e = Vector3::from_fn(|i, _| r * (1.0 - axis[i] * axis[i]).max(0.0).sqrt() + grow);
            (c - e, c + e)
        };
        let (a, b) = match *self {
            Piece::Cylinder { z0, z1, r } => (disc(z0, r, 0.0), disc(z1, r, 0.0)),
            Piece::Cone { z0, r0, z1, r1 } => (disc(z0, r0, 0.0), disc(z1, r1, 0.0)),
            Piece::Sphere { zc, r } => (disc(zc, 0.0, r), disc(zc, 0.0, r)),
            Piece::RoundedDisc { zc, disc: d, r } => (disc(zc, d, r), disc(zc, d, r)),
        };
        (a.0.inf(&b.0), a.1.sup(&b.1))
    }
}

impl PlacedTool {
    /// Axis-aligned bounds of the whole tool.
    pub fn bounds(&self) -> (Point3<f64>, Point3<f64>) {
        let mut lo = Point3::from([f64::INFINITY; 3]);
        let mut hi = Point3::from([f64::NEG_INFINITY; 3]);
        for p in &self.pieces {
            let (a, b) = p.bounds(&self.origin, &self.axis);
            lo = lo.inf(&a);
            hi = hi.sup(&b);
        }
        (lo, hi)
    }

    /// The largest distance of a tool point from the frame origin.
    pub fn reach(&self) -> f64 {
        self.pieces.iter().map(Piece::reach).fold(0.0, f64::max)
    }
}
