//! NX-style CL output (DESIGN.md §3): `TOOL PATH`, `TLDATA`, `MSYS`,
//! `FEDRAT`, `RAPID`, `GOTO` with six values (point, tool axis) or nine
//! (and the tool reference, kinpost's extension for 6-axis machines),
//! `PRESSURE/H1,value`, `END-OF-PATH`. kinpost's own CL reader reads it and
//! `kinpost post` posts it.

use std::io::{self, Write};

use kinpost_nc::{NumberFormat, TrailingZeros};
use nalgebra::{Isometry3, Point3, Vector3};

use crate::path::{PathOptions, Toolpath};

/// What the CL file says besides the path.
#[derive(Debug, Clone)]
pub struct ClOptions {
    /// `TOOL PATH` name (the program name when posted).
    pub name: String,
    /// Feed rate, mm/min.
    pub feed: f64,
    /// `PRESSURE/word,value` before the first pass (belt-grinding contact
    /// pressure, e.g. `H1` on the MTS1600 family, seed 001).
    pub pressure: Option<(String, f64)>,
    /// Write the feed direction as the tool reference (nine-value GOTOs).
    pub reference: bool,
    /// `$$` comment lines for the head of the file.
    pub comments: Vec<String>,
}

fn fmt(decimals: u8) -> NumberFormat {
    NumberFormat {
        decimals,
        trailing_zeros: TrailingZeros::Keep,
        leading_zero: true,
        plus_sign: false,
        modulo: None,
    }
}

struct Writer<W: Write> {
    out: W,
    line: Vec<u8>,
    length: NumberFormat,
    direction: NumberFormat,
    placement: Isometry3<f64>,
    reference: bool,
}

impl<W: Write> Writer<W> {
    fn number(&mut self, f: NumberFormat, v: f64) -> io::Result<()> {
        f.write(&mut self.line, v)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, format!("{v}: {e}")))
    }

    fn text(&mut self, s: &str) -> io::Result<()> {
        self.out.write_all(s.as_bytes())?;
        self.out.write_all(b"\n")
    }

    /// `GOTO/x,y,z,i,j,k[,u,v,w]` in the part frame.
    fn goto(
        &mut self,
        p: &Vector3<f64>,
        axis: &Vector3<f64>,
        reference: &Vector3<f64>,
    ) -> io::Result<()> {
        let p = self.placement.transform_point(&Point3::from(*p)).coords;
        let a = self.placement.transform_vector(axis);
        let r = self.placement.transform_vector(reference);
        self.line.clear();
        self.line.extend_from_slice(b"GOTO/");
        for (k, v) in [p.x, p.y, p.z].into_iter().enumerate() {
            if k > 0 {
                self.line.push(b',');
            }
            self.number(self.length, v)?;
        }
        let dirs: &[f64] = if self.reference {
            &[a.x, a.y, a.z, r.x, r.y, r.z]
        } else {
            &[a.x, a.y, a.z]
        };
        for &v in dirs {
            self.line.push(b',');
            self.number(self.direction, v)?;
        }
        self.line.push(b'\n');
        self.out.write_all(&self.line)
    }
}

/// Writes `path` as a CL file. The placement of `options` maps surface
/// coordinates to the part frame (points, tool axes and references).
pub fn write_cl<W: Write>(
    path: &Toolpath,
    options: &PathOptions,
    cl: &ClOptions,
    out: W,
) -> io::Result<()> {
    let mut w = Writer {
        out,
        line: Vec::with_capacity(160),
        length: fmt(6),
        direction: fmt(9),
        placement: options.placement,
        reference: cl.reference,
    };
    let wheel = options.wheel;
    let name = if cl.name.trim().is_empty() {
        "GRIND".to_string()
    } else {
        cl.name.replace([',', '\n', '\r', '$'], "_")
    };
    let d = |v: f64| fmt(4).format(v).unwrap_or_else(|_| "0.0000".into());
    w.text(&format!(
        "TOOL PATH/{name},TOOL,WHEEL_R{}_W{}",
        fmt(3).format(wheel.radius).unwrap_or_default(),
        fmt(3).format(wheel.width).unwrap_or_default()
    ))?;
    // NX TLDATA/MILL: diameter, corner radius, length (here the width),
    // taper and tip angles.
    w.text(&format!(
        "TLDATA/MILL,{},0.0000,{},0.0000,0.0000",
        d(2.0 * wheel.radius),
        d(wheel.width)
    ))?;
    w.text(
        "MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000",
    )?;
    for c in &cl.comments {
        w.text(&format!("$$ {}", c.replace(['\n', '\r'], " ")))?;
    }
    if let Some((word, value)) = &cl.pressure {
        w.text(&format!(
            "PRESSURE/{},{}",
            word.replace([',', '\n', '\r', '$'], "_"),
            fmt(3).format(*value).unwrap_or_default()
        ))?;
    }
    let mut feed_written = false;
    for pass in &path.passes {
        let (Some(first), Some(last)) = (pass.points.first(), pass.points.last()) else {
            continue;
        };
        w.text("RAPID")?;
        w.goto(
            &(first.point + first.axis * options.lead),
            &first.axis,
            &first.reference,
        )?;
        if !feed_written {
            w.text(&format!(
                "FEDRAT/MMPM,{}",
                fmt(4).format(cl.feed).unwrap_or_default()
            ))?;
            feed_written = true;
        }
        for p in &pass.points {
            w.goto(&p.point, &p.axis, &p.reference)?;
        }
        w.goto(
            &(last.point + last.axis * options.lead),
            &last.axis,
            &last.reference,
        )?;
    }
    w.text("END-OF-PATH")?;
    w.out.flush()
}
