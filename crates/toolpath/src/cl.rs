//! A grinding path as an NX-style CL file ([`ClWriter`]): `TOOL PATH`,
//! `TLDATA`, `MSYS`, `FEDRAT`, `RAPID`, `GOTO` with six values (point,
//! tool axis) or nine (and the tool reference, kinpost's extension for
//! 6-axis machines), `PRESSURE/H1,value`, `END-OF-PATH`. kinpost's own CL
//! reader reads it and `kinpost post` posts it.

use std::io::Write;

use kinpost_cl::{ClWriter, WriteError};
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
    /// pressure, e.g. `H1` on the MTS1600 family, Qi (thesis)).
    pub pressure: Option<(String, f64)>,
    /// Write the feed direction as the tool reference (nine-value GOTOs).
    pub reference: bool,
    /// `$$` comment lines for the head of the file.
    pub comments: Vec<String>,
}

/// The CL statements of the passes, placed in the part frame.
struct Placed<W: Write> {
    cl: ClWriter<W>,
    placement: Isometry3<f64>,
    reference: bool,
}

impl<W: Write> Placed<W> {
    /// `GOTO/x,y,z,i,j,k[,u,v,w]` in the part frame.
    fn goto(
        &mut self,
        p: &Vector3<f64>,
        axis: &Vector3<f64>,
        reference: &Vector3<f64>,
    ) -> Result<(), WriteError> {
        let p = self.placement.transform_point(&Point3::from(*p)).coords;
        let a = self.placement.transform_vector(axis);
        let r = self.placement.transform_vector(reference);
        self.cl.goto(
            [p.x, p.y, p.z],
            [a.x, a.y, a.z],
            self.reference.then_some([r.x, r.y, r.z]),
        )
    }
}

/// Writes `path` as a CL file. The placement of `options` maps surface
/// coordinates to the part frame (points, tool axes and references).
pub fn write_cl<W: Write>(
    path: &Toolpath,
    options: &PathOptions,
    cl: &ClOptions,
    out: W,
) -> Result<(), WriteError> {
    let mut w = Placed {
        cl: ClWriter::new(out),
        placement: options.placement,
        reference: cl.reference,
    };
    let wheel = options.wheel;
    let name = if cl.name.trim().is_empty() {
        "GRIND"
    } else {
        cl.name.as_str()
    };
    let tool = format!(
        "WHEEL_R{}_W{}",
        ClWriter::<W>::number(wheel.radius, 3)?,
        ClWriter::<W>::number(wheel.width, 3)?
    );
    w.cl.tool_path(name, &tool)?;
    // NX TLDATA/MILL: diameter, corner radius, length (here the width),
    // taper and tip angles.
    w.cl.tldata_mill(2.0 * wheel.radius, wheel.width)?;
    w.cl.msys_identity()?;
    for c in &cl.comments {
        w.cl.comment(c)?;
    }
    if let Some((word, value)) = &cl.pressure {
        w.cl.pressure(word, *value)?;
    }
    let mut feed_written = false;
    for pass in &path.passes {
        let (Some(first), Some(last)) = (pass.points.first(), pass.points.last()) else {
            continue;
        };
        w.cl.rapid()?;
        w.goto(
            &(first.point + first.axis * options.lead),
            &first.axis,
            &first.reference,
        )?;
        if !feed_written {
            w.cl.feedrate_mmpm(cl.feed)?;
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
    w.cl.end_of_path()?;
    w.cl.finish()?;
    Ok(())
}
