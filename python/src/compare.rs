//! `compare`: a results CSV against a baseline in tolerance tubes (`cosim compare`).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Compares the results CSV `result` with the baseline CSV `baseline` in tolerance tubes
/// (`cosim compare`); with `plot`, a PNG per failing signal into that folder. Returns the
/// report as a dict: `passed`, `tolerance`, `signals` (per signal `name`, `passed`,
/// `points`, `violations`, `worst` (`time`, `value`, `lower`, `upper`, `excess`) or None,
/// `problem`, `detail`), `notes`, `lines` (as `cosim compare` prints them), `figures`.
#[pyfunction]
#[pyo3(signature = (result, baseline, rtol=1e-3, atol=1e-6, time_tol=0.0, signals=None, plot=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn compare<'py>(
    py: Python<'py>,
    result: PathBuf,
    baseline: PathBuf,
    rtol: f64,
    atol: f64,
    time_tol: f64,
    signals: Option<Vec<String>>,
    plot: Option<PathBuf>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    use nigel_cosim::compare;
    use pyo3::types::PyDict;
    let tolerance = compare::Tolerance { rtol, atol, time_tol };
    let bad = |e: String| PyValueError::new_err(e);
    let r = compare::csv::read_results_csv(&result).map_err(bad)?;
    let b = compare::csv::read_results_csv(&baseline).map_err(bad)?;
    let c = compare::compare(&r, &b, &tolerance, signals.as_deref()).map_err(bad)?;
    let figures = match &plot {
        Some(dir) => compare::plot::plot_failures(&r, &b, &c, dir).map_err(bad)?,
        None => Vec::new(),
    };
    let out = PyDict::new(py);
    out.set_item("passed", c.passed())?;
    let tol = PyDict::new(py);
    tol.set_item("rtol", rtol)?;
    tol.set_item("atol", atol)?;
    tol.set_item("time_tol", time_tol)?;
    out.set_item("tolerance", tol)?;
    let mut each = Vec::new();
    for s in &c.signals {
        let d = PyDict::new(py);
        d.set_item("name", &s.name)?;
        d.set_item("passed", s.passed)?;
        d.set_item("points", s.points)?;
        d.set_item("violations", s.violations)?;
        match &s.worst {
            Some(w) => {
                let wd = PyDict::new(py);
                wd.set_item("time", w.time)?;
                wd.set_item("value", w.value)?;
                wd.set_item("lower", w.lower)?;
                wd.set_item("upper", w.upper)?;
                wd.set_item("excess", w.excess)?;
                d.set_item("worst", wd)?;
            }
            None => d.set_item("worst", py.None())?,
        }
        d.set_item("problem", s.problem.clone())?;
        d.set_item("detail", s.detail())?;
        each.push(d);
    }
    out.set_item("signals", each)?;
    out.set_item("notes", c.notes.clone())?;
    out.set_item("lines", c.lines())?;
    out.set_item("figures", figures)?;
    Ok(out)
}
