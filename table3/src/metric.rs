//! The metric of docs/benchmark.md, from what a run recorded: RMSE of the true X, Y and the
//! unwrapped heading against the test bench's reference pose over the samples
//! `t = 1 ms .. 30 s` (`k = 1 ..= n`), `epsilon` their 2-norm; and the auxiliary
//! `||(RMSE_beta, RMSE_r)||` of the quantities the controller regulates.

use crate::Run;

/// The metric of one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metric {
    /// `[RMSE_X [m], RMSE_Y [m], RMSE_psi [rad]]`.
    pub rmse: [f64; 3],
    /// `epsilon = ||rmse||_2` (Table III).
    pub eps: f64,
    /// `[RMSE_beta [rad], RMSE_r [rad/s]]`.
    pub rmse_state: [f64; 2],
    /// `||rmse_state||_2`.
    pub eps_state: f64,
    /// The largest steering command `|delta_i|` of the run, any wheel \[rad\] (against the
    /// plant's limit `delta_max = pi/2`).
    pub max_delta: f64,
}

/// Root mean square of `a[k] - b[k]` over `k = 1 ..= n` (0 for `n = 0`).
pub fn rmse(a: &[f64], b: &[f64], n: usize) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 1..=n {
        let e = a[k] - b[k];
        sum += e * e;
    }
    (sum / n as f64).sqrt()
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl Metric {
    /// The metric of `run` (its series must have `n + 1` entries: see [`Run::check`]).
    pub fn of(run: &Run) -> Metric {
        let n = run.n_samples();
        let rmse = [rmse(&run.x, &run.x_ref, n), rmse(&run.y, &run.y_ref, n), rmse(&run.psi, &run.psi_ref, n)];
        let rmse_state = [self::rmse(&run.beta, &run.beta_ref, n), self::rmse(&run.yaw_rate, &run.yaw_rate_ref, n)];
        let max_delta = run.delta.iter().flatten().fold(0.0f64, |m, d| m.max(d.abs()));
        Metric { rmse, eps: norm(&rmse), rmse_state, eps_state: norm(&rmse_state), max_delta }
    }
}
