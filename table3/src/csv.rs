//! One CSV per recorded run: `t, x, y, psi, x_ref, y_ref, psi_ref, beta, yaw_rate,
//! beta_ref, yaw_rate_ref, delta_fl..rr, mu_fl..rr` per sample (the commands and friction
//! of the last row, which no step uses, left empty).

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::io;
use crate::{Error, Run};

/// `sim_skidpad_robust.csv`.
pub fn file_name(run: &Run) -> String {
    let j = &run.job;
    format!("{}_{}_{}.csv", j.fidelity.column(), j.maneuver.name(), j.controller.name())
}

/// Writes `run` as CSV to `w`.
pub fn write<W: Write>(run: &Run, mut w: W) -> std::io::Result<()> {
    writeln!(
        w,
        "t,x,y,psi,x_ref,y_ref,psi_ref,beta,yaw_rate,beta_ref,yaw_rate_ref,delta_fl,delta_fr,delta_rl,delta_rr,mu_fl,mu_fr,mu_rl,mu_rr"
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
        if k < n {
            let (d, m) = (run.delta[k], run.mu[k]);
            writeln!(w, ",{},{},{},{},{},{},{},{}", d[0], d[1], d[2], d[3], m[0], m[1], m[2], m[3])?;
        } else {
            writeln!(w, ",,,,,,,,")?;
        }
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
