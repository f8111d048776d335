//! `kinpost calibrate`: Preston's coefficient and the contact wheel's
//! stiffness fitted to measured grinding traces (`kinpost_stock::calibrate`:
//! passes give K_p by least squares through the origin, dwells the Winkler
//! modulus), printed, and written into a process file for `kinpost sim
//! --process`.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use kinpost_stock::{ProcessModel, Trace, TraceFile, calibrate};

use crate::sinks::{deliver, open_outputs};
use crate::{read_text, report};

/// Largest trace or process file read, bytes: a few hundred traces.
const MAX_FILE_BYTES: usize = 1 << 20;

/// The arguments of `kinpost calibrate`.
#[derive(clap::Args)]
pub struct CalibrateArgs {
    /// The measured traces (TOML, `[[trace]]` tables of kind `pass` or
    /// `dwell`: force_n, belt_mm_s, feed_mm_s or dwell_s, width_mm,
    /// radius_mm for a dwell, and the measured depth_mm).
    traces: PathBuf,
    /// A process file whose force table is kept: with -o, the same file
    /// with the fitted coefficients is written.
    #[arg(long, value_name = "FILE.toml")]
    process: Option<PathBuf>,
    /// Write the calibrated process file here (needs --process), or - for
    /// standard output.
    #[arg(long, short, value_name = "FILE.toml", requires = "process")]
    output: Option<PathBuf>,
}

impl CalibrateArgs {
    /// Whether the process file goes to standard output (`-o -`).
    pub fn writes_stdout(&self) -> bool {
        self.output.as_deref() == Some(Path::new("-"))
    }
}

/// `kinpost calibrate`: the fit on `out`.
pub fn calibrate_command(args: &CalibrateArgs, out: &mut impl Write) -> Result<()> {
    let mut inputs: Vec<(&str, &Path)> = vec![("traces", args.traces.as_path())];
    if let Some(p) = &args.process {
        inputs.push(("process file", p.as_path()));
    }
    let outputs: Vec<(&str, &Path)> = args
        .output
        .iter()
        .map(|o| ("--output", o.as_path()))
        .collect();
    let mut sinks = open_outputs(&inputs, &outputs)?;
    let text = read_limited(&args.traces, "trace file")?;
    let name = args.traces.display().to_string();
    let traces = TraceFile::from_toml(&text, &name).map_err(report)?.trace;
    let fit = calibrate(&traces).with_context(|| format!("cannot calibrate from {name}"))?;
    let (passes, dwells) = traces.iter().fold((0, 0), |(p, d), t| match t {
        Trace::Pass { .. } => (p + 1, d),
        Trace::Dwell { .. } => (p, d + 1),
    });
    writeln!(
        out,
        "Preston's coefficient K_p = {:.6e} mm²/N ({passes} passes)",
        fit.preston_mm2_per_n
    )?;
    match fit.stiffness_n_per_mm3 {
        Some(k) => writeln!(out, "wheel stiffness k = {k:.6} N/mm³ ({dwells} dwells)")?,
        None => writeln!(out, "wheel stiffness: no dwell trace, not fitted")?,
    }
    writeln!(
        out,
        "rms depth residual {:.6} mm over {} traces",
        fit.rms_mm,
        traces.len()
    )?;
    if let (Some(p), Some(sink)) = (&args.process, sinks.first_mut()) {
        let pname = p.display().to_string();
        let base =
            ProcessModel::from_toml(&read_limited(p, "process file")?, &pname).map_err(report)?;
        let calibrated = base.calibrated(&fit);
        write!(
            sink,
            "# {pname} calibrated by `kinpost calibrate` from {name}: K_p fitted to {passes} passes{}; rms depth residual {:.6} mm.\n{}",
            if fit.stiffness_n_per_mm3.is_some() {
                format!(", k to {dwells} dwells")
            } else {
                String::new()
            },
            fit.rms_mm,
            calibrated.to_toml()
        )
        .context("cannot write the process file")?;
    }
    deliver(sinks)
}

/// A small text file, refused beyond [`MAX_FILE_BYTES`].
fn read_limited(path: &Path, what: &str) -> Result<String> {
    let text = read_text(path, what, MAX_FILE_BYTES)?;
    if text.len() > MAX_FILE_BYTES {
        anyhow::bail!(
            "{what} {} is larger than {MAX_FILE_BYTES} bytes",
            path.display()
        );
    }
    Ok(text)
}
