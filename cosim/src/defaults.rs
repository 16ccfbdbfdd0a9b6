//! The times of a run that its caller leaves out, filled in from the model's
//! `DefaultExperiment`: the master's defaults (`cosim run`, the Python package's
//! `System.simulate` and `System.initialize`) and fmpy's (the Python package's
//! `simulate_fmu`, which is to give fmpy's numbers).

use model_description::DefaultExperiment;

/// What the caller of a run gave (`None`: left to the defaults).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GivenTimes {
    /// Start time, s.
    pub start_time: Option<f64>,
    /// Stop time, s.
    pub stop_time: Option<f64>,
    /// Step size, s: the communication step ([`RunTimes::master`]), fmpy's `step_size`
    /// ([`RunTimes::fmpy`]).
    pub step_size: Option<f64>,
    /// fmpy's `output_interval`, s (only [`RunTimes::fmpy`] reads it).
    pub output_interval: Option<f64>,
    /// Relative tolerance.
    pub relative_tolerance: Option<f64>,
}

/// A run's start and stop time, communication step and relative tolerance, the caller's
/// where given, else the defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunTimes {
    /// Start time, s.
    pub start_time: f64,
    /// Stop time, s.
    pub stop_time: f64,
    /// Communication step, s.
    pub step: f64,
    /// Relative tolerance (`None`: the solver's own default).
    pub relative_tolerance: Option<f64>,
}

impl RunTimes {
    /// The master's defaults: the start time given, else the DefaultExperiment's
    /// `startTime`, else 0; the stop time given, else `stopTime`, else start + 1 s; the
    /// relative tolerance given, else `tolerance` (these as fmpy's `simulate_fmu` fills them
    /// in); the communication step given, else `stepSize`, else 1 ms.
    pub fn master(default: &DefaultExperiment, given: &GivenTimes) -> RunTimes {
        let (start_time, stop_time, relative_tolerance) = start_stop_tolerance(default, given);
        RunTimes {
            start_time,
            stop_time,
            step: given.step_size.or(default.step_size).unwrap_or(1e-3),
            relative_tolerance,
        }
    }

    /// fmpy 0.3's defaults (`fmpy.simulate_fmu`), in its order: start time, stop time and
    /// relative tolerance as [`RunTimes::master`]; with `T` = stop - start, `step_size` if
    /// not given `10^(round(log10 T) - 3)` (when `T` > 0); `output_interval` if not given:
    /// for Co-Simulation the DefaultExperiment's `stepSize` doubled until `T` holds at most
    /// 1000 of it, else fmpy's automatic interval ([`auto_interval`], 1 ms for `T` <= 0);
    /// for Model Exchange `step_size` doubled likewise (no `step_size`: the automatic
    /// interval). The communication step is that output interval: fmpy records one row a
    /// step in Co-Simulation and one an output point in Model Exchange.
    ///
    /// Where fmpy divides by a `stepSize` of 0 (a `ZeroDivisionError`), the 0 is passed on:
    /// the run refuses it as a communication step.
    pub fn fmpy(default: &DefaultExperiment, co_simulation: bool, given: &GivenTimes) -> RunTimes {
        let (start_time, stop_time, relative_tolerance) = start_stop_tolerance(default, given);
        let total = stop_time - start_time;
        let step_size = given.step_size.or_else(|| (total > 0.0).then(|| decade_thousandth(total)));
        // doubled until at most 1000 intervals (a non-positive one stays as it is)
        let at_most_1000 = |mut interval: f64| {
            while interval > 0.0 && total / interval > 1000.0 {
                interval *= 2.0;
            }
            interval
        };
        let from_experiment = default.step_size.filter(|_| co_simulation).map(at_most_1000);
        let step = given.output_interval.or(from_experiment).unwrap_or_else(|| match step_size {
            Some(h) if !co_simulation => at_most_1000(h),
            _ if total > 0.0 => auto_interval(total),
            _ => 1e-3,
        });
        RunTimes { start_time, stop_time, step, relative_tolerance }
    }
}

fn start_stop_tolerance(default: &DefaultExperiment, given: &GivenTimes) -> (f64, f64, Option<f64>) {
    let start = given.start_time.or(default.start_time).unwrap_or(0.0);
    let stop = given.stop_time.or(default.stop_time).unwrap_or(start + 1.0);
    (start, stop, given.relative_tolerance.or(default.tolerance))
}

/// `10^(round(log10 t) - 3)`, rounding half to even as NumPy's `round` does.
fn decade_thousandth(t: f64) -> f64 {
    10f64.powf(t.log10().round_ties_even() - 3.0)
}

/// fmpy's automatic output interval for a run of length `t` s (`fmpy.util.auto_interval`):
/// `10^(round(log10 t) - 3)`, then scaled by 5, 4, 2, 1/5, 1/4 or 1/2 so that `t` holds
/// 500 to 1000 intervals where it can.
pub fn auto_interval(t: f64) -> f64 {
    let h = decade_thousandth(t);
    let n = t / h;
    if n >= 2500.0 {
        h * 5.0
    } else if n >= 2000.0 {
        h * 4.0
    } else if n >= 1000.0 {
        h * 2.0
    } else if n <= 200.0 {
        h / 5.0
    } else if n <= 250.0 {
        h / 4.0
    } else if n <= 500.0 {
        h / 2.0
    } else {
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn experiment(start: Option<f64>, stop: Option<f64>, step: Option<f64>) -> DefaultExperiment {
        DefaultExperiment { start_time: start, stop_time: stop, step_size: step, tolerance: Some(1e-7) }
    }

    /// The given times win; else the DefaultExperiment's; else 0, start + 1 s and 1 ms.
    #[test]
    fn master_defaults() {
        let none = GivenTimes::default();
        let d = experiment(Some(2.0), Some(5.0), Some(0.01));
        assert_eq!(
            RunTimes::master(&d, &none),
            RunTimes { start_time: 2.0, stop_time: 5.0, step: 0.01, relative_tolerance: Some(1e-7) }
        );
        let given = GivenTimes { start_time: Some(3.0), step_size: Some(0.5), relative_tolerance: Some(1e-4), ..none };
        assert_eq!(
            RunTimes::master(&d, &given),
            RunTimes { start_time: 3.0, stop_time: 5.0, step: 0.5, relative_tolerance: Some(1e-4) }
        );
        let times = RunTimes::master(&DefaultExperiment::default(), &GivenTimes { start_time: Some(0.5), ..none });
        assert_eq!(times, RunTimes { start_time: 0.5, stop_time: 1.5, step: 1e-3, relative_tolerance: None });
    }

    /// The values fmpy 0.3.32's `fmpy.util.auto_interval` returns for these lengths (by
    /// hand: t = 3 s gives 10^(round(0.477) - 3) = 1 ms, 3000 points, so x5; 10 s: 10 ms,
    /// 1000 points, x2; 0.3 s: 0.1 ms, 3000 points, x5; 2 s: 1 ms, 2000 points, x4; 7 s:
    /// 10 ms, 700 points, kept). Exact: the same float64 operations (pow, one multiply or
    /// divide) give the same double.
    #[test]
    fn auto_interval_as_fmpy() {
        assert_eq!(auto_interval(3.0), 0.005);
        assert_eq!(auto_interval(10.0), 0.02);
        assert_eq!(auto_interval(0.3), 0.0005);
        assert_eq!(auto_interval(2.0), 0.004);
        assert_eq!(auto_interval(7.0), 0.01);
    }

    /// Co-Simulation: the stepSize doubled until at most 1000 steps (1 ms over 3 s: 3000,
    /// 1500, then 4 ms gives 750); none: the automatic interval. Model Exchange: the
    /// step_size (default 10^(round(log10 3) - 3) = 1 ms) doubled likewise.
    #[test]
    fn fmpy_output_interval() {
        let none = GivenTimes::default();
        let d = experiment(None, Some(3.0), Some(1e-3));
        assert_eq!(RunTimes::fmpy(&d, true, &none).step, 4e-3);
        assert_eq!(RunTimes::fmpy(&experiment(None, Some(3.0), None), true, &none).step, 0.005);
        assert_eq!(RunTimes::fmpy(&d, false, &none).step, 4e-3);
        let given = GivenTimes { step_size: Some(1e-4), ..none };
        // 1e-4 doubled 5 times: 3.2e-3 (937.5 steps); doubling a double is exact
        assert_eq!(RunTimes::fmpy(&d, false, &given).step, 1e-4 * 32.0);
        let given = GivenTimes { output_interval: Some(0.25), ..none };
        assert_eq!(RunTimes::fmpy(&d, true, &given).step, 0.25);
        // an empty run: 1 ms; a stepSize of 0 is passed on for the run to refuse
        assert_eq!(RunTimes::fmpy(&experiment(Some(1.0), Some(1.0), None), true, &none).step, 1e-3);
        assert_eq!(RunTimes::fmpy(&experiment(None, None, Some(0.0)), true, &none).step, 0.0);
    }
}
