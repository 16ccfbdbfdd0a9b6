//! The arguments of one run as the Python half resolves them, and their [`Experiment`].

use nigel_cosim::{Error as CosimError, Experiment, InputTable};
use pyo3::prelude::*;
use std::sync::Arc;

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
        // the translation every front end shares (nigel_cosim::options); errors name the
        // Python keywords (the rk4 step is fmpy's step_size)
        let mut experiment = nigel_cosim::options::RunOptions {
            start_time: args.start_time,
            stop_time: args.stop_time,
            step: args.step,
            output_interval: args.output_interval,
            algorithm: &args.algorithm,
            solver: &args.solver,
            // fmpy tells Co-Simulation FMUs the relative tolerance (given, else the
            // DefaultExperiment's, filled in by the caller)
            relative_tolerance: args.relative_tolerance,
            default_relative_tolerance: 1e-5,
            max_step: args.max_step,
            timeout: args.timeout,
            threads: args.threads,
        }
        .experiment(|name| if name == "max_step" { "step_size".into() } else { name.to_string() })?;
        if let Some((names, time, columns)) = &args.input {
            experiment.input = Some(Arc::new(InputTable::new(names.clone(), time.clone(), columns.clone())?));
        }
        if let Some(output) = &args.output {
            experiment.record = Some(output.iter().map(|n| qualify(n)).collect());
        }
        Ok(experiment)
    }
}
