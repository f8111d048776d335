//! `kinpost wheel`: what the pressure axis does to the wheel (Qi (thesis),
//! §2.7–2.13): the input-link angle α, the wheel offset in the
//! linkage plane and the axis correction the post applies, per pressure, and
//! the wheel-centre trajectory as an SVG plot (Qi (thesis) Figures 2.24, 2.35).

use std::fmt::Write as _;

use kinpost_machine::{Clamp, Kinematics, Machine, PressureAxis, WheelModel};

/// The wheel at one pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct WheelRow {
    pub pressure: f64,
    /// Inside the calibration, or clamped to one of its ends.
    pub clamp: Clamp,
    /// Angle of the input link, degrees (linkage model only).
    pub alpha_deg: Option<f64>,
    /// The wheel offset along the two plane directions, mm.
    pub offset: [f64; 2],
    /// The change of each free linear axis (machine order) that puts the
    /// contact point back where it is at the reference pressure, at the home
    /// orientation; `None` where the axes cannot (fewer than three linear
    /// axes).
    pub correction: Option<Vec<(usize, f64)>>,
}

/// The pressure axis of `machine`, or why there is none.
pub fn pressure_axis(machine: &Machine) -> Result<&PressureAxis, String> {
    machine.pressure.as_ref().ok_or_else(|| {
        format!(
            "machine `{}` has no pressure axis (no [pressure] section)",
            machine.name
        )
    })
}

/// `FROM:TO:STEP` as the list of pressures FROM, FROM+STEP, … up to TO
/// (TO included when a step lands on it).
pub fn parse_table(text: &str) -> Result<Vec<f64>, String> {
    let bad = || format!("--table `{text}`: expected FROM:TO:STEP, e.g. 3000:3600:100");
    let parts: Vec<f64> = text
        .split(':')
        .map(|p| p.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    let [from, to, step] = <[f64; 3]>::try_from(parts).map_err(|_| bad())?;
    if step <= 0.0 || to < from {
        return Err(format!(
            "--table `{text}`: STEP must be positive and TO not below FROM"
        ));
    }
    let count = ((to - from) / step + 1e-9).floor();
    if count > 10_000.0 {
        return Err(format!(
            "--table `{text}`: more than 10000 rows; take a larger STEP"
        ));
    }
    Ok((0..=count as usize)
        .map(|k| from + step * k as f64)
        .collect())
}

/// The pressures shown when none are asked for: the calibration rows and
/// the reference, in order.
pub fn default_pressures(p: &PressureAxis) -> Vec<f64> {
    let mut v: Vec<f64> = match &p.model {
        WheelModel::Linkage { alpha_deg, .. } => alpha_deg.iter().map(|r| r[0]).collect(),
        WheelModel::Offsets(rows) => rows.iter().map(|r| r[0]).collect(),
    };
    v.push(p.reference);
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// The wheel at each of `pressures`.
pub fn rows(machine: &Machine, pressures: &[f64]) -> Result<Vec<WheelRow>, String> {
    let p = pressure_axis(machine)?;
    let home = machine.home_joints();
    let reference = Kinematics::new(machine).fk(&home);
    let free_linear: Vec<usize> = (0..machine.axes.len())
        .filter(|&i| !machine.axes[i].is_rotary() && machine.axes[i].is_free())
        .collect();
    let rotary: Vec<usize> = (0..machine.axes.len())
        .filter(|&i| machine.axes[i].is_rotary())
        .collect();
    let mut solutions = Vec::new();
    let mut out = Vec::with_capacity(pressures.len());
    for &h in pressures {
        if !(h.is_finite() && h >= 0.0) {
            return Err(format!("pressure `{h}` must be a number not below 0"));
        }
        // The axis values that put the wheel at pressure h where it is at
        // the reference with every axis at home: the correction.
        let kin = Kinematics::new(&machine.at_pressure(h));
        let correction = kin
            .ik_all_branches(&reference, Some(&home[..]), &mut solutions)
            .ok()
            .and_then(|()| {
                solutions.iter().min_by(|a, b| {
                    let turn = |s: &kinpost_machine::Solution| {
                        rotary
                            .iter()
                            .map(|&i| (s.joints[i] - home[i]).abs())
                            .sum::<f64>()
                    };
                    turn(a).total_cmp(&turn(b))
                })
            })
            .map(|s| {
                free_linear
                    .iter()
                    .map(|&i| (i, s.joints[i] - home[i]))
                    .collect()
            });
        out.push(WheelRow {
            pressure: h,
            clamp: p.clamp(h),
            alpha_deg: p.alpha_deg(h),
            offset: p.plane_offset(h),
            correction,
        });
    }
    Ok(out)
}

/// The table `kinpost wheel` prints.
pub fn table_text(machine: &Machine, rows: &[WheelRow]) -> Result<String, String> {
    let p = pressure_axis(machine)?;
    let [e1, e2] = p.plane.map(|i| machine.axes[i].name.as_str());
    let mut s = String::new();
    let model = match &p.model {
        WheelModel::Linkage { link_length, .. } => format!(
            "four-bar linkage, input link {} mm, angle alpha from {e1} towards {e2}",
            trim(*link_length)
        ),
        WheelModel::Offsets(_) => "measured wheel offsets".to_string(),
    };
    let _ = writeln!(
        s,
        "machine {}: pressure word {}, reference {} = {}; {model}",
        machine.name,
        p.name,
        p.name,
        trim(p.reference)
    );
    let _ = writeln!(
        s,
        "offset: where the wheel (its contact point) is against where it is at the reference, along the home directions of {e1} and {e2}"
    );
    let _ = writeln!(
        s,
        "correction: the change of the linear axes that puts the contact point back, at the home orientation (it turns with the head)"
    );
    let _ = writeln!(s);
    let linear: Vec<&str> = rows
        .iter()
        .find_map(|r| r.correction.as_ref())
        .map(|c| {
            c.iter()
                .map(|&(i, _)| machine.axes[i].name.as_str())
                .collect()
        })
        .unwrap_or_default();
    let _ = write!(
        s,
        "{:>10}  {:>10}  {:>12}  {:>12}",
        p.name,
        "alpha [°]",
        format!("offset {e1}"),
        format!("offset {e2}")
    );
    for name in &linear {
        let _ = write!(s, "  {:>10}", format!("corr. {name}"));
    }
    s.push('\n');
    let mut clamped = false;
    for r in rows {
        let mark = if r.clamp == Clamp::Inside { ' ' } else { '*' };
        clamped |= mark == '*';
        let alpha = r
            .alpha_deg
            .map_or_else(|| "-".to_string(), |a| format!("{a:.4}"));
        let _ = write!(
            s,
            "{:>9}{mark}  {alpha:>10}  {:>12.4}  {:>12.4}",
            trim(r.pressure),
            r.offset[0],
            r.offset[1]
        );
        match &r.correction {
            Some(c) => {
                for (_, v) in c {
                    let _ = write!(s, "  {:>10.4}", v + 0.0);
                }
            }
            None => {
                for _ in &linear {
                    let _ = write!(s, "  {:>10}", "-");
                }
            }
        }
        s.push('\n');
    }
    if clamped {
        let [lo, hi] = p.range();
        let _ = writeln!(
            s,
            "* outside the calibration ({} .. {}): the piston sits on its stop",
            trim(lo),
            trim(hi)
        );
    }
    let [lo, hi] = p.range();
    let (a, b) = (p.plane_offset(lo), p.plane_offset(hi));
    let _ = writeln!(
        s,
        "between the ends of the calibration, {} = {} and {}: {:.4} mm along {e1}, {:.4} mm along {e2}",
        p.name,
        trim(lo),
        trim(hi),
        (b[0] - a[0]).abs(),
        (b[1] - a[1]).abs()
    );
    Ok(s)
}

/// A number without trailing zeros (pressures, lengths as the user wrote them).
fn trim(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// Tick positions for `lo..hi`: 1, 2 or 5 times a power of ten, about six.
fn ticks(lo: f64, hi: f64) -> (Vec<f64>, usize) {
    let span = (hi - lo).max(1e-9);
    let raw = span / 6.0;
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power);
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    ((first..=last).map(|k| k as f64 * step).collect(), decimals)
}

/// The wheel-centre trajectory over the whole calibration (the curve) and
/// the given rows (marked and labelled), as a self-contained SVG: offset
/// along the first plane direction across, along the second up, each axis
/// scaled to its own range (the Y excursion is tens of times smaller than
/// the Z stroke, as in Qi (thesis) Figure 2.24).
pub fn svg(machine: &Machine, rows: &[WheelRow]) -> Result<String, String> {
    let p = pressure_axis(machine)?;
    let [e1, e2] = p.plane.map(|i| machine.axes[i].name.as_str());
    let [lo, hi] = p.range();
    // The curve: 240 steps over the calibration plus its breakpoints.
    let mut samples: Vec<f64> = (0..=240)
        .map(|k| lo + (hi - lo) * k as f64 / 240.0)
        .collect();
    samples.extend(default_pressures(p));
    samples.sort_by(f64::total_cmp);
    samples.dedup();
    let curve: Vec<[f64; 2]> = samples.iter().map(|&h| p.plane_offset(h)).collect();
    let points = curve.iter().chain(rows.iter().map(|r| &r.offset));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for q in points {
        x0 = x0.min(q[0]);
        x1 = x1.max(q[0]);
        y0 = y0.min(q[1]);
        y1 = y1.max(q[1]);
    }
    // Some room around the data; a flat range gets a width of its own.
    let pad = |a: &mut f64, b: &mut f64| {
        let m = ((*b - *a) * 0.08).max(0.05);
        *a -= m;
        *b += m;
    };
    pad(&mut x0, &mut x1);
    pad(&mut y0, &mut y1);
    let (w, h) = (720.0, 540.0);
    let (left, right, top, bottom) = (90.0, 30.0, 60.0, 70.0);
    let sx = |x: f64| left + (x - x0) / (x1 - x0) * (w - left - right);
    let sy = |y: f64| top + (y1 - y) / (y1 - y0) * (h - top - bottom);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(
        s,
        r#"<rect x="0" y="0" width="{w}" height="{h}" fill="white"/>"#
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="15">Wheel-centre trajectory of {}, {} = {} .. {} (reference {})</text>"#,
        w / 2.0,
        escape(&machine.name),
        escape(&p.name),
        trim(lo),
        trim(hi),
        trim(p.reference)
    );
    let _ = writeln!(
        s,
        r##"<text x="{}" y="42" text-anchor="middle" fill="#555">offset from the wheel position at the reference pressure (open circle); axes scaled separately</text>"##,
        w / 2.0
    );
    // Frame, grid and tick labels.
    let (px0, px1, py0, py1) = (sx(x0), sx(x1), sy(y1), sy(y0));
    let (xt, xd) = ticks(x0, x1);
    let (yt, yd) = ticks(y0, y1);
    for t in &xt {
        let x = sx(*t);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.2}" y1="{py0:.2}" x2="{x:.2}" y2="{py1:.2}" stroke="#ddd"/><text x="{x:.2}" y="{:.2}" text-anchor="middle">{:.xd$}</text>"##,
            py1 + 18.0,
            t + 0.0
        );
    }
    for t in &yt {
        let y = sy(*t);
        let _ = writeln!(
            s,
            r##"<line x1="{px0:.2}" y1="{y:.2}" x2="{px1:.2}" y2="{y:.2}" stroke="#ddd"/><text x="{:.2}" y="{:.2}" text-anchor="end">{:.yd$}</text>"##,
            px0 - 6.0,
            y + 4.0,
            t + 0.0
        );
    }
    let _ = writeln!(
        s,
        r#"<rect x="{px0:.2}" y="{py0:.2}" width="{:.2}" height="{:.2}" fill="none" stroke="black"/>"#,
        px1 - px0,
        py1 - py0
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.2}" y="{:.2}" text-anchor="middle">offset along {} [mm]</text>"#,
        (px0 + px1) / 2.0,
        h - 20.0,
        escape(e1)
    );
    let _ = writeln!(
        s,
        r#"<text x="20" y="{:.2}" text-anchor="middle" transform="rotate(-90 20 {:.2})">offset along {} [mm]</text>"#,
        (py0 + py1) / 2.0,
        (py0 + py1) / 2.0,
        escape(e2)
    );
    // The trajectory and the rows.
    let path: Vec<String> = curve
        .iter()
        .map(|q| format!("{:.2},{:.2}", sx(q[0]), sy(q[1])))
        .collect();
    let _ = writeln!(
        s,
        r##"<polyline points="{}" fill="none" stroke="#1f5fbf" stroke-width="2"/>"##,
        path.join(" ")
    );
    // The reference: where the wheel is without offset.
    let _ = writeln!(
        s,
        r##"<circle cx="{:.2}" cy="{:.2}" r="5" fill="none" stroke="black"/>"##,
        sx(0.0),
        sy(0.0)
    );
    for r in rows {
        let (x, y) = (sx(r.offset[0]), sy(r.offset[1]));
        let _ = writeln!(
            s,
            r##"<circle cx="{x:.2}" cy="{y:.2}" r="3.5" fill="#c0392b"/><text x="{:.2}" y="{:.2}">{}={}</text>"##,
            x + 7.0,
            y + 4.0,
            escape(&p.name),
            trim(r.pressure)
        );
    }
    s.push_str("</svg>\n");
    Ok(s)
}

/// Text for SVG: `&`, `<`, `>` escaped (names come from machine files).
fn escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinpost_machine::builtin;

    #[test]
    fn table_ranges() {
        assert_eq!(
            parse_table("3000:3600:100").unwrap(),
            vec![3000.0, 3100.0, 3200.0, 3300.0, 3400.0, 3500.0, 3600.0]
        );
        assert_eq!(parse_table("0:1:0.4").unwrap(), vec![0.0, 0.4, 0.8]);
        assert_eq!(parse_table("5:5:1").unwrap(), vec![5.0]);
        for bad in ["3000:3600", "a:b:c", "1:0:1", "0:1:0", "0:1e9:1"] {
            assert!(parse_table(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn ticks_are_round() {
        assert_eq!(ticks(-0.1, 1.9).0, vec![0.0, 0.5, 1.0, 1.5]);
        let (t, d) = ticks(-40.0, 17.0);
        assert_eq!(t, vec![-40.0, -30.0, -20.0, -10.0, 0.0, 10.0]);
        assert_eq!(d, 0);
        assert_eq!(ticks(0.0, 0.06).1, 2);
    }

    #[test]
    fn mts1600_rows_correct_the_offset() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let rows = rows(&m, &[3000.0, 3475.0, 4000.0]).unwrap();
        assert_eq!(rows[1].offset, [0.0, 0.0]);
        assert_eq!(rows[2].clamp, Clamp::Above);
        // Y and Z carry the head: they move back by the offset (Y's home
        // direction is e₁, Z's is e₂), X does not move.
        let c: Vec<f64> = rows[0]
            .correction
            .as_ref()
            .unwrap()
            .iter()
            .map(|&(_, v)| v)
            .collect();
        let [d1, d2] = rows[0].offset;
        assert!(c[0].abs() < 1e-9, "{c:?}");
        assert!(
            (c[1] + d1).abs() < 1e-9 && (c[2] + d2).abs() < 1e-9,
            "{c:?}"
        );
        let text = table_text(&m, &rows).unwrap();
        assert!(text.contains("4000*"), "{text}");
        let svg = svg(&m, &rows).unwrap();
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        // The three rows and the reference.
        assert_eq!(svg.matches("<circle").count(), 4);
    }
}
