//! The time base of a run: communication point `n` is at `t0 + n h`, computed from the
//! integer step count (no time is accumulated), and the last step ends exactly at the
//! stop time when the interval is not a whole number of steps.

use crate::error::{Error, Result};
use crate::simulate::types::Experiment;
use crate::system::{is_cs, System};

/// The fraction of a step below which the interval's remainder is no step of its own.
pub(crate) const WHOLE_STEP_TOLERANCE: f64 = 1e-6;

/// The distance from `x` to the next f64 away from zero (the spacing of times near `x`).
pub(crate) fn ulp(x: f64) -> f64 {
    let a = x.abs();
    if !a.is_finite() {
        return f64::INFINITY;
    }
    f64::from_bits(a.to_bits() + 1) - a
}

/// One communication step: from `t = t0 + n h` to `t_next` (`t0 + (n + 1) h`, or the stop
/// time for a shorter last step).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Point {
    /// Step number from the start (0-based).
    pub n: u64,
    /// Start of the step, s.
    pub t: f64,
    /// End of the step, s.
    pub t_next: f64,
    /// A row is recorded at `t_next`.
    pub output_point: bool,
}

/// The communication points of a run.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Clock {
    /// Start time, s.
    pub(crate) t0: f64,
    /// Communication step, s.
    pub(crate) h: f64,
    /// Stop time, s.
    pub(crate) stop: f64,
    /// Number of communication steps.
    pub(crate) steps: u64,
    /// A row every `stride` steps (and at the last).
    pub(crate) stride: u64,
    /// The last step is shorter than `h` and ends at `stop`.
    partial: bool,
}

impl Clock {
    /// Step `n` of the run.
    #[inline]
    pub(crate) fn point(&self, n: u64) -> Point {
        let last = n + 1 == self.steps;
        let t_next = if last && self.partial { self.stop } else { self.t0 + (n + 1) as f64 * self.h };
        Point { n, t: self.t0 + n as f64 * self.h, t_next, output_point: (n + 1).is_multiple_of(self.stride) || last }
    }

    /// Rows a run records (the initial one included).
    pub(crate) fn rows(&self) -> u64 {
        self.steps / self.stride + 2
    }

    /// The points of experiment `e`: the number of steps, the output stride, and whether
    /// the last step is shorter (the interval is not a whole number of steps: allowed only
    /// when every Co-Simulation instance has `canHandleVariableCommunicationStepSize`),
    /// checked.
    pub(crate) fn new(e: &Experiment, system: &System) -> Result<Clock> {
        let ok = |x: f64| x.is_finite();
        if !(ok(e.start_time) && ok(e.stop_time) && ok(e.step)) || e.step <= 0.0 || e.stop_time < e.start_time {
            return Err(Error::Experiment(format!(
                "need finite times with stop >= start and step > 0 (start {}, stop {}, step {})",
                e.start_time, e.stop_time, e.step
            )));
        }
        // the step must be resolvable by the times of the run
        let resolution = 2.0 * ulp(e.start_time.abs().max(e.stop_time.abs()));
        if e.step < 2.0 * resolution {
            return Err(Error::Experiment(format!(
                "the step {} s is below the resolution of f64 times near {} s ({resolution:e} s): the points cannot be told apart",
                e.step,
                e.start_time.abs().max(e.stop_time.abs())
            )));
        }
        // a whole number n of steps when the point t0 + n h, as computed here, is the stop
        // time to within a millionth of a step, or to the rounding of the times themselves
        // (two ulps of the larger time; at |t| = 1e6 s that is 2.3e-10 s): relative to the
        // step, not to |t|, so a start at 1e6 s or 1e12 s counts the same steps as 0
        let mut steps = ((e.stop_time - e.start_time) / e.step).round();
        let gap = (e.start_time + steps * e.step - e.stop_time).abs();
        let partial = gap > (WHOLE_STEP_TOLERANCE * e.step).max(resolution);
        if partial {
            if let Some(fixed) = system.instances.iter().find(|i| is_cs(i) && !i.fmu.can_handle_variable_step()) {
                return Err(Error::Experiment(format!(
                    "the interval {} s is not a whole number of steps of {} s, and {} cannot take a shorter last step (canHandleVariableCommunicationStepSize is false)",
                    e.stop_time - e.start_time,
                    e.step,
                    fixed.name
                )));
            }
            steps = ((e.stop_time - e.start_time) / e.step).ceil();
        }
        if steps > e.max_steps as f64 {
            return Err(Error::Experiment(format!(
                "{steps} communication steps exceed the cap of {} steps of a run (Experiment::max_steps, --max-steps)",
                e.max_steps
            )));
        }
        let stride = match e.output_interval {
            None => 1.0,
            Some(d) => {
                let r = d / e.step;
                if !(d.is_finite() && d > 0.0) || (r - r.round()).abs() > 1e-9 * r.max(1.0) || r.round() < 1.0 {
                    return Err(Error::Experiment(format!(
                        "the output interval {d} s must be a whole multiple of the step {} s",
                        e.step
                    )));
                }
                r.round()
            }
        };
        Ok(Clock {
            t0: e.start_time,
            h: e.step,
            stop: e.stop_time,
            steps: steps as u64,
            stride: stride as u64,
            partial,
        })
    }
}
