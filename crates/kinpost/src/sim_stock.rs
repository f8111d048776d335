//! `kinpost sim --stock …`: the stock, the tool and the design of material
//! removal, from their command-line forms.

use std::path::Path;

use anyhow::{Context, Result};
use kinpost_stock::{Design, Mesh, Stock, Tool, default_resolution};
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
    design: Option<&Mesh>,
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
        let allowance: f64 = rest
            .trim()
            .parse()
            .map_err(|_| bad("expected design+ALLOWANCE in mm (design+0.2)".into()))?;
        let mesh = design.ok_or_else(|| bad("needs --design FILE.stl".into()))?;
        let (lo, hi) = mesh
            .bounds()
            .ok_or_else(|| bad("the design has no triangles".into()))?;
        let grow = nalgebra::Vector3::repeat(allowance.max(0.0));
        let stock = Stock::from_mesh_offset(mesh, allowance, res(lo - grow, hi + grow))
            .map_err(|e| bad(e.to_string()))?;
        return Ok((stock, format!("design+{allowance}")));
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

/// The design of `--design` as the comparison measures it.
pub fn design(mesh: Mesh) -> Result<Design> {
    Ok(Design::from_mesh(mesh)?)
}
