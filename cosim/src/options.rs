//! The options of a run as a front end takes them (the `cosim run` command line, the Python
//! `simulate`), translated into an [`Experiment`] in one place so that every front end
//! checks and means the same.

use crate::error::{Error, Result};
use crate::me::Solver;
use crate::simulate::{Algorithm, Experiment};
use std::time::Duration;

/// What a front end was given for a run (times resolved already, e.g. by
/// [`crate::defaults::RunTimes`]).
#[derive(Clone, Debug)]
pub struct RunOptions<'a> {
    /// Start time, s.
    pub start_time: f64,
    /// Stop time, s.
    pub stop_time: f64,
    /// Communication step, s.
    pub step: f64,
    /// Interval of the recorded rows, s (`None`: every step).
    pub output_interval: Option<f64>,
    /// `jacobi` or `ordered`.
    pub algorithm: &'a str,
    /// `rk4`, `dopri5` or `bdf`.
    pub solver: &'a str,
    /// Relative tolerance of dopri5 and bdf, and the one Co-Simulation FMUs are told
    /// (`None`: the FMUs are told none, the solvers use `default_relative_tolerance`).
    pub relative_tolerance: Option<f64>,
    /// The solvers' relative tolerance where none is given (the front end's default).
    pub default_relative_tolerance: f64,
    /// Largest rk4 step, s.
    pub max_step: Option<f64>,
    /// Wall-clock limit of the run, s.
    pub timeout: Option<f64>,
    /// Threads stepping the instances.
    pub threads: usize,
}

impl RunOptions<'_> {
    /// The experiment of these options; an error names the option by `option_name` (the
    /// front end's spelling of `relative_tolerance`, `max_step`, `timeout`, `threads`).
    pub fn experiment(&self, option_name: impl Fn(&str) -> String) -> Result<Experiment> {
        let bad = |m: String| Error::Experiment(m);
        let mut experiment = Experiment::new(self.stop_time, self.step);
        experiment.start_time = self.start_time;
        experiment.output_interval = self.output_interval;
        experiment.algorithm = self.algorithm.parse::<Algorithm>().map_err(bad)?;
        let rtol = self.relative_tolerance.unwrap_or(self.default_relative_tolerance);
        if !(rtol > 0.0 && rtol.is_finite()) {
            return Err(bad(format!("{} {rtol} must be positive", option_name("relative_tolerance"))));
        }
        if let Some(m) = self.max_step.filter(|m| !(*m > 0.0 && m.is_finite())) {
            return Err(bad(format!("{} {m} must be a positive number of seconds", option_name("max_step"))));
        }
        experiment.co_simulation_tolerance = self.relative_tolerance;
        experiment.solver = Solver::named(self.solver, rtol, self.max_step).map_err(bad)?;
        if let Some(t) = self.timeout {
            experiment.timeout =
                Some(Duration::try_from_secs_f64(t).ok().filter(|d| !d.is_zero()).ok_or_else(|| {
                    bad(format!("{} {t} must be a positive number of seconds", option_name("timeout")))
                })?);
        }
        if self.threads == 0 {
            return Err(bad(format!("{} must be at least 1", option_name("threads"))));
        }
        experiment.threads = self.threads;
        Ok(experiment)
    }
}

/// A `cosim run` option's spelling of an option name (`max_step` is `--max-step`,
/// `relative_tolerance` is `--rtol`).
pub fn cli_option_name(name: &str) -> String {
    match name {
        "relative_tolerance" => "--rtol".into(),
        other => format!("--{}", other.replace('_', "-")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options() -> RunOptions<'static> {
        RunOptions {
            start_time: 0.5,
            stop_time: 2.0,
            step: 1e-3,
            output_interval: Some(0.01),
            algorithm: "ordered",
            solver: "dopri5",
            relative_tolerance: Some(1e-4),
            default_relative_tolerance: 1e-6,
            max_step: None,
            timeout: Some(3.0),
            threads: 2,
        }
    }

    #[test]
    fn translates_every_option() {
        let e = options().experiment(cli_option_name).unwrap();
        assert_eq!((e.start_time, e.stop_time, e.step, e.output_interval), (0.5, 2.0, 1e-3, Some(0.01)));
        assert_eq!(e.algorithm, Algorithm::Ordered);
        // the absolute tolerance is the relative one / 100 (the documented rule)
        assert_eq!(e.solver, Solver::Dopri5 { rtol: 1e-4, atol: 1e-6 });
        assert_eq!(e.co_simulation_tolerance, Some(1e-4));
        // none given: the FMUs are told none, the solver takes the front end's default
        let e = RunOptions { relative_tolerance: None, ..options() }.experiment(cli_option_name).unwrap();
        assert_eq!((e.solver, e.co_simulation_tolerance), (Solver::Dopri5 { rtol: 1e-6, atol: 1e-8 }, None));
        assert_eq!((e.timeout, e.threads), (Some(Duration::from_secs(3)), 2));
        assert_eq!("rk4".parse::<Solver>(), Ok(Solver::Rk4 { max_step: None }));
        assert_eq!("bdf".parse::<Solver>(), Ok(Solver::Bdf { rtol: 1e-6, atol: 1e-8 }));
    }

    #[test]
    fn bad_options_are_named_in_the_front_end_spelling() {
        let message = |o: RunOptions, name: fn(&str) -> String| o.experiment(name).unwrap_err().to_string();
        let o = RunOptions { relative_tolerance: Some(0.0), ..options() };
        assert!(message(o.clone(), cli_option_name).contains("--rtol 0 must be positive"));
        assert!(message(o, |n| n.to_string()).contains("relative_tolerance 0 must be positive"));
        let o = RunOptions { threads: 0, ..options() };
        assert!(message(o, cli_option_name).contains("--threads must be at least 1"));
        let o = RunOptions { solver: "euler", ..options() };
        assert!(message(o, cli_option_name).contains("unknown solver \"euler\""));
        let o = RunOptions { max_step: Some(-1.0), solver: "rk4", ..options() };
        assert!(message(o, cli_option_name).contains("--max-step -1 must be a positive number of seconds"));
    }
}
