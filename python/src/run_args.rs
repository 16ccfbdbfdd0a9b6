//! The arguments of one run as the Python half resolves them, and their [`Experiment`].

use nigel_cosim::{Error as CosimError, Experiment, InputTable, Solver};
use pyo3::prelude::*;
use std::sync::Arc;
use std::time::Duration;

/// The arguments of one run, resolved by the Python half.
#[derive(FromPyObject)]
pub(crate) struct RunArgs {
    pub(crate) start_time: f64,
    pub(crate) stop_time: f64,
    pub(crate) step: f64,
    pub(crate) output_interval: Option<f64>,
    pub(crate) algorithm: String,
    pub(crate) start_values: Vec<(String, String)>,
    pub(crate) input: Option<(Vec<String>, Vec<f64>, Vec<Vec<f64>>)>,
    pub(crate) output: Option<Vec<String>>,
    pub(crate) solver: String,
    /// The largest step of `rk4` (fmpy's `step_size` in Model Exchange); None: the communication step.
    pub(crate) max_step: Option<f64>,
    pub(crate) relative_tolerance: Option<f64>,
    pub(crate) timeout: Option<f64>,
    pub(crate) threads: usize,
}

impl RunArgs {
    /// The experiment of these arguments; `qualify` turns a recorded name into its system name.
    pub(crate) fn experiment(&self, qualify: impl Fn(&str) -> String) -> Result<Experiment, CosimError> {
        let args = self;
        let mut experiment = Experiment::new(args.stop_time, args.step);
        experiment.start_time = args.start_time;
        experiment.output_interval = args.output_interval;
        experiment.algorithm = args.algorithm.parse().map_err(CosimError::Experiment)?;
        let rtol = args.relative_tolerance.unwrap_or(1e-5);
        if !(rtol > 0.0 && rtol.is_finite()) {
            return Err(CosimError::Experiment(format!("relative_tolerance {rtol} must be positive")));
        }
        // fmpy tells Co-Simulation FMUs the relative tolerance (given, else the
        // DefaultExperiment's, filled in by the caller)
        experiment.co_simulation_tolerance = args.relative_tolerance;
        experiment.solver = match args.solver.as_str() {
            "rk4" => {
                if args.max_step.is_some_and(|m| !(m > 0.0 && m.is_finite())) {
                    return Err(CosimError::Experiment(format!(
                        "step_size {} must be a positive number of seconds",
                        args.max_step.unwrap_or_default()
                    )));
                }
                Solver::Rk4 { max_step: args.max_step }
            }
            "dopri5" => Solver::Dopri5 { rtol, atol: rtol / 100.0 },
            "bdf" => Solver::Bdf { rtol, atol: rtol / 100.0 },
            other => {
                return Err(CosimError::Experiment(format!("unknown solver {other:?} (rk4, dopri5, bdf)")));
            }
        };
        if let Some((names, time, columns)) = &args.input {
            experiment.input = Some(Arc::new(InputTable::new(names.clone(), time.clone(), columns.clone())?));
        }
        if let Some(output) = &args.output {
            experiment.record = Some(output.iter().map(|n| qualify(n)).collect());
        }
        if let Some(t) = args.timeout {
            experiment.timeout =
                Some(Duration::try_from_secs_f64(t).ok().filter(|d| !d.is_zero()).ok_or_else(|| {
                    CosimError::Experiment(format!("timeout {t} must be a positive number of seconds"))
                })?);
        }
        if args.threads == 0 {
            return Err(CosimError::Experiment("threads must be at least 1".into()));
        }
        experiment.threads = args.threads;
        Ok(experiment)
    }
}
