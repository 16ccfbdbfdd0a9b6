//! What runs one closed loop of Table III: the [`Engine`] trait, its [`Job`] and the
//! recorded [`Run`]; the two engines [`FmuEngine`] (the three `.fmu` archives through the
//! master) and [`InProcess`] (`nigel_benchmark`'s loop, the cross-check).

mod fmu;
mod in_process;

pub use fmu::{default_fmu_dir, FmuEngine, FMU_FILES};
pub use in_process::InProcess;

use crate::Error;
use nigel_benchmark::{Controller, Fidelity, Maneuver, SAMPLE_PERIOD};

/// One cell of the table to run: the column, the row, the controller and the seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Job {
    /// Noise seed of every stream.
    pub seed: u64,
    /// The column: `Paper` is "sim", `Real` is "real".
    pub fidelity: Fidelity,
    /// The row.
    pub maneuver: Maneuver,
    /// The controller.
    pub controller: Controller,
    /// Friction variation, wind and measurement noise as in docs/benchmark.md (`true`), or all
    /// off (`false`: mu = 0.4, no wind, no noise; the run must then stay on its reference
    /// when `controller` is open loop).
    pub disturbed: bool,
}

impl Job {
    /// A disturbed job (the table's).
    pub fn new(seed: u64, fidelity: Fidelity, maneuver: Maneuver, controller: Controller) -> Job {
        Job { seed, fidelity, maneuver, controller, disturbed: true }
    }

    /// `sim/skidpad/robust`.
    pub fn label(&self) -> String {
        format!("{}/{}/{}", self.fidelity.column(), self.maneuver.name(), self.controller.name())
    }
}

/// What one closed-loop run recorded, sample by sample. Pose, state and reference have
/// `n + 1` entries (`t_0 .. t_n`, `t_k = k * 1 ms`); the commands and the friction the
/// plant got over `[t_k, t_(k+1))` have `n`.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// What ran.
    pub job: Job,
    /// The feedback gain the controller used (rows FL, FR, RL, RR; columns `[e_y, e_psi,
    /// beta - beta_ref, yaw_rate - yaw_rate_ref]`; the pose columns are zero for the paper's
    /// three controllers).
    pub gain: [[f64; 4]; 4],
    /// World X of the car \[m\].
    pub x: Vec<f64>,
    /// World Y of the car \[m\].
    pub y: Vec<f64>,
    /// Heading of the car, unwrapped \[rad\].
    pub psi: Vec<f64>,
    /// True body slip angle \[rad\].
    pub beta: Vec<f64>,
    /// True yaw rate [rad/s].
    pub yaw_rate: Vec<f64>,
    /// Reference pose X from the test bench \[m\].
    pub x_ref: Vec<f64>,
    /// Reference pose Y \[m\].
    pub y_ref: Vec<f64>,
    /// Reference heading \[rad\].
    pub psi_ref: Vec<f64>,
    /// Reference body slip angle \[rad\].
    pub beta_ref: Vec<f64>,
    /// Reference yaw rate [rad/s].
    pub yaw_rate_ref: Vec<f64>,
    /// Steering commanded (FL, FR, RL, RR) over `[t_k, t_(k+1))` \[rad\].
    pub delta: Vec<[f64; 4]>,
    /// Road friction per wheel over `[t_k, t_(k+1))` [-].
    pub mu: Vec<[f64; 4]>,
}

impl Run {
    /// Number of samples `n`.
    pub fn n_samples(&self) -> usize {
        self.x.len().saturating_sub(1)
    }

    /// `t_k` \[s\].
    pub fn time(k: usize) -> f64 {
        k as f64 * SAMPLE_PERIOD
    }

    /// Checks the lengths (every pose/state/reference series `n + 1`, commands `n`, `n >= 1`)
    /// and that everything is finite.
    pub fn check(&self) -> Result<(), Error> {
        let n = self.n_samples();
        let bad = |reason: String| Err(Error::BadRun { run: self.job.label(), reason });
        if n == 0 {
            return bad("no sample recorded".into());
        }
        let series: [(&str, &Vec<f64>); 10] = [
            ("x", &self.x),
            ("y", &self.y),
            ("psi", &self.psi),
            ("beta", &self.beta),
            ("yaw_rate", &self.yaw_rate),
            ("x_ref", &self.x_ref),
            ("y_ref", &self.y_ref),
            ("psi_ref", &self.psi_ref),
            ("beta_ref", &self.beta_ref),
            ("yaw_rate_ref", &self.yaw_rate_ref),
        ];
        for (name, s) in series {
            if s.len() != n + 1 {
                return bad(format!("{name} has {} samples, x has {}", s.len(), n + 1));
            }
            // all finite: one branch-free pass (vectorized); where not, found afterwards
            if !s.iter().fold(true, |ok, v| ok & v.is_finite()) {
                let k = s.iter().position(|v| !v.is_finite()).unwrap_or(0);
                return bad(format!("{name} is {} at t = {} s", s[k], Run::time(k)));
            }
        }
        for (name, s) in [("delta", &self.delta), ("mu", &self.mu)] {
            if s.len() != n {
                return bad(format!("{name} has {} samples, expected {n}", s.len()));
            }
            if !s.iter().flatten().fold(true, |ok, x| ok & x.is_finite()) {
                let k = s.iter().position(|v| v.iter().any(|x| !x.is_finite())).unwrap_or(0);
                return bad(format!("{name} is {:?} at t = {} s", s[k], Run::time(k)));
            }
        }
        Ok(())
    }
}

/// Runs closed loops. Implementations are shared between the worker threads.
pub trait Engine: Sync {
    /// A short name for reports (`fmu (ordered)`, `in-process`).
    fn name(&self) -> String;
    /// Runs one job over the whole benchmark horizon (30 s).
    fn run(&self, job: &Job) -> Result<Run, Error>;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(n: usize) -> Run {
        let s = |k: f64| (0..=n).map(|i| k * i as f64).collect::<Vec<f64>>();
        Run {
            job: Job::new(0, Fidelity::Paper, Maneuver::Straight, Controller::Robust),
            gain: [[0.0; 4]; 4],
            x: s(1.0),
            y: s(2.0),
            psi: s(3.0),
            beta: s(4.0),
            yaw_rate: s(5.0),
            x_ref: s(6.0),
            y_ref: s(7.0),
            psi_ref: s(8.0),
            beta_ref: s(9.0),
            yaw_rate_ref: s(10.0),
            delta: vec![[0.1; 4]; n],
            mu: vec![[0.4; 4]; n],
        }
    }

    /// The finiteness check names the series, the first bad value and its time, wherever
    /// it sits (the branch-free pass must not miss one at either end).
    #[test]
    fn check_finds_the_first_non_finite_value_with_its_time() {
        assert!(run(100).check().is_ok());
        for k in [0, 37, 100] {
            let mut r = run(100);
            r.psi_ref[k] = f64::NAN;
            r.psi_ref[100 - k / 2] = f64::INFINITY;
            let first = k.min(100 - k / 2);
            let e = r.check().unwrap_err().to_string();
            assert!(e.contains("psi_ref is") && e.contains(&format!("at t = {} s", Run::time(first))), "{k}: {e}");
        }
        let mut r = run(100);
        r.mu[63][2] = f64::NEG_INFINITY;
        let e = r.check().unwrap_err().to_string();
        assert!(e.contains("mu is [0.4, 0.4, -inf, 0.4]") && e.contains(&format!("at t = {} s", Run::time(63))), "{e}");
        let mut r = run(100);
        r.delta.pop();
        assert!(r.check().unwrap_err().to_string().contains("delta has 99 samples, expected 100"));
    }
}
