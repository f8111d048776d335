//! `kinpost sim --stock …`: the stock, the tool and the design of material
//! removal, from their command-line forms.

use std::path::Path;

use anyhow::{Context, Result};
use kinpost_stock::{Design, Mesh, Stock, Tool, default_resolution};
use kinpost_surface::Surface;
use nalgebra::Point3;

use crate::usage;

/// Flute length of an end mill or drill when `--tool` gives none: four
/// diameters (a common stub length), at least 10 mm.
fn default_flute_length(diameter: f64) -> f64 {
    (4.0 * diameter).max(10.0)
}

/// A tool from `--tool`: `flat:D[,FLUTE]`, `ball:D[,FLUTE]`,
/// `bull:D,CORNER[,FLUTE]`, `drill:D[,POINT_ANGLE[,FLUTE]]`,
/// `wheel:RADIUS,WIDTH[,EDGE_RADIUS]` (the belt's contact wheel),
/// `disc:RADIUS,THICKNESS` (the A/C grinder's disc wheel); mm and degrees.
pub fn parse_tool(spec: &str) -> Result<Tool> {
    let bad = |why: &str| usage(format!("--tool {spec}: {why}"));
    let (kind, rest) = spec.split_once(':').ok_or_else(|| {
        bad("expected KIND:VALUES (flat:10, ball:6, bull:10,1, drill:8, wheel:200,25, disc:50,10)")
    })?;
    let values: Vec<f64> = rest
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad("the values must be numbers separated by commas"))?;
    let count = |lo: usize, hi: usize| {
        if (lo..=hi).contains(&values.len()) {
            Ok(())
        } else {
            Err(bad(&format!(
                "`{kind}` takes {} values, {} given",
                if lo == hi {
                    lo.to_string()
                } else {
                    format!("{lo} to {hi}")
                },
                values.len()
            )))
        }
    };
    let v = |i: usize, default: f64| values.get(i).copied().unwrap_or(default);
    let tool = match kind {
        "flat" => {
            count(1, 2)?;
            Tool::FlatEnd {
                diameter: v(0, 0.0),
                flute_length: v(1, default_flute_length(v(0, 0.0))),
                shank: None,
            }
        }
        "ball" => {
            count(1, 2)?;
            Tool::BallEnd {
                diameter: v(0, 0.0),
                flute_length: v(1, default_flute_length(v(0, 0.0))),
                shank: None,
            }
        }
        "bull" => {
            count(2, 3)?;
            Tool::BullNose {
                diameter: v(0, 0.0),
                corner_radius: v(1, 0.0),
                flute_length: v(2, default_flute_length(v(0, 0.0))),
                shank: None,
            }
        }
        "drill" => {
            count(1, 3)?;
            Tool::Drill {
                diameter: v(0, 0.0),
                point_angle_deg: v(1, 118.0),
                flute_length: v(2, default_flute_length(v(0, 0.0))),
            }
        }
        "wheel" => {
            count(2, 3)?;
            Tool::ContactWheel {
                radius: v(0, 0.0),
                width: v(1, 0.0),
                edge_radius: v(2, 0.0),
            }
        }
        "disc" => {
            count(2, 2)?;
            Tool::DiscWheel {
                radius: v(0, 0.0),
                thickness: v(1, 0.0),
            }
        }
        _ => {
            return Err(bad(
                "unknown tool kind (flat, ball, bull, drill, wheel, disc)",
            ));
        }
    };
    tool.pieces().map_err(|e| bad(&e.to_string()))?;
    Ok(tool)
}

/// The stock of `--stock` (`box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX`,
/// `design+ALLOWANCE`, or a closed STL file) in the part frame, at
/// `resolution` (default from its size), and how to name it in the report.
pub fn load_stock(
    spec: &str,
    resolution: Option<f64>,
    design: Option<&DesignSource>,
) -> Result<(Stock, String)> {
    let bad = |why: String| usage(format!("--stock {spec}: {why}"));
    let res =
        |lo: Point3<f64>, hi: Point3<f64>| resolution.unwrap_or_else(|| default_resolution(lo, hi));
    if let Some(rest) = spec.strip_prefix("box:") {
        let v: Vec<f64> = rest
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad("expected six numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX".into()))?;
        let [x0, y0, z0, x1, y1, z1] = v[..] else {
            return Err(bad(format!("expected six numbers, {} given", v.len())));
        };
        let (lo, hi) = (Point3::new(x0, y0, z0), Point3::new(x1, y1, z1));
        let stock = Stock::from_box(lo, hi, res(lo, hi)).map_err(|e| bad(e.to_string()))?;
        return Ok((stock, format!("box:{x0},{y0},{z0},{x1},{y1},{z1}")));
    }
    if let Some(rest) = spec.strip_prefix("design+") {
        let values: Vec<f64> = rest
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad("expected design+ALLOWANCE[,DEPTH] in mm (design+0.2)".into()))?;
        let allowance = values[0];
        let design = design.ok_or_else(|| bad("needs --design".into()))?;
        return match (design, &values[1..]) {
            (DesignSource::Mesh(mesh), []) => {
                let (lo, hi) = mesh
                    .bounds()
                    .ok_or_else(|| bad("the design has no triangles".into()))?;
                let grow = nalgebra::Vector3::repeat(allowance.max(0.0));
                let stock = Stock::from_mesh_offset(mesh, allowance, res(lo - grow, hi + grow))
                    .map_err(|e| bad(e.to_string()))?;
                Ok((stock, format!("design+{allowance}")))
            }
            (DesignSource::Mesh(_), _) => Err(bad(
                "DEPTH is for a design surface (JSON); an STL design is a solid".into(),
            )),
            (
                DesignSource::Surface {
                    surface,
                    region,
                    flip,
                    chord_mm,
                },
                rest,
            ) => {
                let depth = match rest {
                    [] => OPEN_STOCK_DEPTH_MM,
                    [d] => *d,
                    _ => return Err(bad("expected design+ALLOWANCE[,DEPTH]".into())),
                };
                let shell =
                    Design::shell_of_surface(surface, *region, *chord_mm, *flip, allowance, depth)
                        .map_err(|e| bad(e.to_string()))?;
                let name = if rest.is_empty() {
                    format!("design+{allowance}")
                } else {
                    format!("design+{allowance},{depth}")
                };
                stock_of_shell(&shell, res, bad, name)
            }
        };
    }
    let mesh = read_mesh(Path::new(spec))?;
    let (lo, hi) = mesh
        .bounds()
        .ok_or_else(|| bad("the mesh has no triangles".into()))?;
    let stock = Stock::from_mesh(&mesh, res(lo, hi)).map_err(|e| bad(e.to_string()))?;
    Ok((stock, spec.to_string()))
}

/// A mesh from an STL file (binary or ASCII).
pub fn read_mesh(path: &Path) -> Result<Mesh> {
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let name = path.display().to_string();
    Ok(Mesh::read_stl(std::io::BufReader::new(file), &name)?)
}

/// Largest process file read, bytes: a process file is a few lines.
const MAX_PROCESS_FILE_BYTES: usize = 1 << 20;

/// The belt-grinding process model of `--process` (located errors).
pub fn read_process(path: &Path) -> Result<kinpost_stock::ProcessModel> {
    let text = crate::read_text(path, "process file", MAX_PROCESS_FILE_BYTES)?;
    if text.len() > MAX_PROCESS_FILE_BYTES {
        anyhow::bail!(
            "process file {} is larger than {} bytes",
            path.display(),
            MAX_PROCESS_FILE_BYTES
        );
    }
    kinpost_stock::ProcessModel::from_toml(&text, &path.display().to_string())
        .map_err(crate::report)
}

/// The outside of a design surface (`--design-side`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DesignSide {
    /// The side of the surface normal S_u × S_v.
    #[value(name = "+")]
    Plus,
    /// The side away from it.
    #[value(name = "-")]
    Minus,
}

/// How deep under an open design surface its stock `design+ALLOWANCE`
/// reaches, mm, when the spec gives no DEPTH: deeper than any grinding or
/// finishing pass gouges, so a gouge is measured, not cut through.
pub const OPEN_STOCK_DEPTH_MM: f64 = 2.0;

/// The design of `--design`: a closed STL, or a surface file (JSON) of
/// which `region` is compared, its material on the side away from its
/// normal S_u × S_v (`flip`: towards it).
pub enum DesignSource {
    /// A closed mesh (STL) of the part.
    Mesh(Mesh),
    /// One surface of the part.
    Surface {
        /// The surface, in the part frame.
        surface: Box<Surface>,
        /// The parameter rectangle compared, `[u0, u1, v0, v1]`.
        region: [f64; 4],
        /// The material lies on the side of S_u × S_v.
        flip: bool,
        /// Chord tolerance of its triangles, mm.
        chord_mm: f64,
    },
}

impl DesignSource {
    /// From `--design FILE` (a `.json` file is a surface), `--design-side`
    /// and `--design-region`; `chord_mm` the tessellation's chord.
    pub fn load(
        path: &Path,
        side: Option<DesignSide>,
        region: Option<&str>,
        chord_mm: f64,
    ) -> Result<DesignSource> {
        let is_surface = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        if !is_surface {
            if region.is_some() || side.is_some() {
                return Err(usage(
                    "--design-region and --design-side are for a design surface (JSON); an STL is a closed solid, compared whole",
                ));
            }
            return Ok(DesignSource::Mesh(read_mesh(path)?));
        }
        let surface = crate::cmd_surface::load_surface(path)?;
        let (u0, u1) = surface.u_range();
        let (v0, v1) = surface.v_range();
        let region = match region {
            None => [u0, u1, v0, v1],
            Some(r) => {
                let v: Vec<f64> = r
                    .split(',')
                    .map(|v| v.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| usage(format!("--design-region {r}: expected U0,U1,V0,V1")))?;
                let [a, b, c, d] = v[..] else {
                    return Err(usage(format!(
                        "--design-region {r}: expected four numbers U0,U1,V0,V1"
                    )));
                };
                let ordered = |lo: f64, hi: f64| 0.0 <= lo && lo < hi && hi <= 1.0;
                if !(ordered(a, b) && ordered(c, d)) {
                    return Err(usage(format!(
                        "--design-region {r}: fractions of the parameter domain, 0 ≤ U0 < U1 ≤ 1 and 0 ≤ V0 < V1 ≤ 1"
                    )));
                }
                let (du, dv) = (u1 - u0, v1 - v0);
                [u0 + a * du, u0 + b * du, v0 + c * dv, v0 + d * dv]
            }
        };
        Ok(DesignSource::Surface {
            surface: Box::new(surface),
            region,
            flip: side == Some(DesignSide::Minus),
            chord_mm,
        })
    }

    /// The design as the comparison measures it (the mesh moves into it).
    pub fn into_design(self) -> Result<Design> {
        Ok(match self {
            DesignSource::Mesh(mesh) => Design::from_mesh(mesh)?,
            DesignSource::Surface {
                surface,
                region,
                flip,
                chord_mm,
            } => Design::from_surface_region(&surface, region, chord_mm, flip)?,
        })
    }
}

/// A stock from a closed shell mesh.
fn stock_of_shell(
    shell: &Mesh,
    res: impl Fn(Point3<f64>, Point3<f64>) -> f64,
    bad: impl Fn(String) -> anyhow::Error,
    name: String,
) -> Result<(Stock, String)> {
    let (lo, hi) = shell
        .bounds()
        .ok_or_else(|| bad("the design has no triangles".into()))?;
    let stock = Stock::from_mesh(shell, res(lo, hi)).map_err(|e| bad(e.to_string()))?;
    Ok((stock, name))
}
