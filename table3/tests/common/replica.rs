//! The loop of docs/benchmark.md once more, written here from nigel_benchmark's and
//! nigel_vehicle's public pieces, with one difference from nigel_benchmark's: the plant
//! is stepped over `t_(k+1) - t_k` with `t_k = k * 1 ms` (as the master does, like fmpy),
//! not over exactly 1 ms, with the plant FMU's sub-step rule. It explains the last bits
//! between the FMU run and the in-process run.

use nigel_benchmark::{Benchmark, ControllerInputs, SampledController, Scenario, SAMPLE_PERIOD};
use nigel_table3::{Job, Run};
use nigel_vehicle::dynamics::{idx, stable_rk4_step};
use nigel_vehicle::{integrate, straight_running, Inputs};

/// The run of `job` with the master's step sizes.
pub fn run_on_master_grid(job: &Job) -> Run {
    let mut scenario = Scenario { seed: job.seed, ..Scenario::new(job.maneuver, job.fidelity) };
    if !job.disturbed {
        scenario = scenario.undisturbed();
    }
    let bench = Benchmark::prepare(scenario).unwrap();
    let params = job.fidelity.params();
    let d = scenario.disturbances();
    let r = &bench.reference.trajectory;
    let n = scenario.n_samples;
    let mut controller = SampledController::new(job.controller.settings()).unwrap();
    let mut s = straight_running(scenario.speed_ref);
    let mut run = Run {
        job: *job,
        gain: job.controller.feedback_gain(),
        x: vec![],
        y: vec![],
        psi: vec![],
        beta: vec![],
        yaw_rate: vec![],
        x_ref: r.x.clone(),
        y_ref: r.y.clone(),
        psi_ref: r.psi.clone(),
        beta_ref: r.beta.clone(),
        yaw_rate_ref: r.yaw_rate.clone(),
        delta: vec![],
        mu: vec![],
    };
    for k in 0..=n {
        let (beta, yaw_rate, speed) =
            (s[idx::V_Y].atan2(s[idx::V_X]), s[idx::YAW_RATE], s[idx::V_X].hypot(s[idx::V_Y]));
        run.x.push(s[idx::X]);
        run.y.push(s[idx::Y]);
        run.psi.push(s[idx::PSI]);
        run.beta.push(beta);
        run.yaw_rate.push(yaw_rate);
        if k == n {
            break;
        }
        let (beta_meas, yaw_rate_meas) = d.measure(k, beta, yaw_rate);
        let out = controller.step(&ControllerInputs {
            beta: beta_meas,
            yaw_rate: yaw_rate_meas,
            speed,
            beta_ref: r.beta[k],
            yaw_rate_ref: r.yaw_rate[k],
            speed_ref: scenario.speed_ref,
            delta_ff: bench.program().steering(k),
            x: s[idx::X],
            y: s[idx::Y],
            psi: s[idx::PSI],
            x_ref: r.x[k],
            y_ref: r.y[k],
            psi_ref: r.psi[k],
        });
        let mut u = Inputs::<f64>::coasting(0.0);
        u.delta = out.delta;
        u.tau = out.tau;
        u.mu = d.friction(k);
        [u.wind_x, u.wind_y] = d.wind(k);
        let h = (k + 1) as f64 * SAMPLE_PERIOD - k as f64 * SAMPLE_PERIOD;
        let substep = 0.5e-3_f64.min(stable_rk4_step(&params, &u));
        s = integrate(&params, &s, &u, h, substep);
        run.delta.push(out.delta);
        run.mu.push(u.mu);
    }
    run
}
