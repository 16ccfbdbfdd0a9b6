//! One CSV per recorded run, in fmpy's result format (comma-separated, quoted names,
//! `"time"` first, every field a number, so `fmpy.util.read_csv` and `plot_result` read it):
//! `time, x, y, psi, x_ref, y_ref, psi_ref, beta, yaw_rate, beta_ref, yaw_rate_ref,
//! delta_fl..rr, mu_fl..rr`, one row per sample `t_k = k * 1 ms`, k = 0 .. n.
//!
//! The steering commands and the friction are held over `[t_k, t_(k+1))`; row k carries the
//! value held from `t_k` on. The last row (`t_n`, the stop time) starts no interval: it
//! carries the value held up to `t_n`, that of row n - 1, as a zero-order hold's left limit.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::io;
use crate::{Error, Run};

/// The column names, in order (written quoted).
pub const COLUMNS: [&str; 19] = [
    "time", "x", "y", "psi", "x_ref", "y_ref", "psi_ref", "beta", "yaw_rate", "beta_ref", "yaw_rate_ref", "delta_fl",
    "delta_fr", "delta_rl", "delta_rr", "mu_fl", "mu_fr", "mu_rl", "mu_rr",
];

/// `sim_skidpad_robust.csv`.
pub fn file_name(run: &Run) -> String {
    let j = &run.job;
    format!("{}_{}_{}.csv", j.fidelity.column(), j.maneuver.name(), j.controller.name())
}

/// Writes `run` as CSV to `w`.
pub fn write<W: Write>(run: &Run, mut w: W) -> std::io::Result<()> {
    writeln!(
        w,
        "{}",
        COLUMNS.iter().map(|c| format!("\"{c}\"")).collect::<Vec<_>>().join(",")
    )?;
    let n = run.n_samples();
    for k in 0..=n {
        write!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{}",
            Run::time(k),
            run.x[k],
            run.y[k],
            run.psi[k],
            run.x_ref[k],
            run.y_ref[k],
            run.psi_ref[k],
            run.beta[k],
            run.yaw_rate[k],
            run.beta_ref[k],
            run.yaw_rate_ref[k]
        )?;
        // the held value; at t_n the one held up to it (n >= 1: a run has at least one sample)
        let held = k.min(n.saturating_sub(1));
        let (d, m) = (run.delta[held], run.mu[held]);
        writeln!(w, ",{},{},{},{},{},{},{},{}", d[0], d[1], d[2], d[3], m[0], m[1], m[2], m[3])?;
    }
    w.flush()
}

/// Writes every run into `dir` (created if needed); returns the files written.
pub fn write_all(runs: &[Run], dir: &Path) -> Result<Vec<PathBuf>, Error> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let mut files = Vec::new();
    for run in runs {
        let path = dir.join(file_name(run));
        let f = std::fs::File::create(&path).map_err(io(&path))?;
        write(run, std::io::BufWriter::new(f)).map_err(io(&path))?;
        files.push(path);
    }
    Ok(files)
}
