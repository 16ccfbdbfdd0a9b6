//! A preliminary nonlinear check of the tracking gain on the benchmark maneuvers of
//! `shared/spec/maneuvers.md` (friction, wind, noise, speed hold and reference as specified
//! there), against open loop and the paper's robust controller. It is *not* the benchmark
//! (that crate is authoritative and adds the along-track speed correction, issue 9 item 3,
//! which this check does not have): it only supports the choice of the tracking weights.
//!
//! `cargo run --release -p nigel-synthesis --example tracking_maneuvers [seeds]`
//!
//! Prints epsilon (norm of the RMSEs of X, Y, psi against the reference) per maneuver,
//! column and controller (mean and worst over the seeds), the tracking controller's worst
//! ratio to the paper's robust controller, and the largest steering command.

use nigel_synthesis::tracking::{design_tracking, tracking_region};
use nigel_synthesis::{
    pareto_sweep, Architecture, PlantSpec, PoleRegion, SweepOptions, SynthesisOptions, TrackingSpec, VerifyOptions,
};
use nigel_vehicle::dynamics::idx;
use nigel_vehicle::{integrate, tracking_errors, Inputs, State, VehicleParams};

const N: usize = 30_000;
const DT: f64 = 1e-3;
const A: f64 = std::f64::consts::PI / 6.0;

fn mix(mut z: u64) -> u64 {
    z ^= z >> 30;
    z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 27;
    z = z.wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn unif(seed: u64, stream: u64, k: u64) -> f64 {
    let z = ((seed << 8) | stream).wrapping_add((k + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    (mix(z) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

fn gauss(seed: u64, stream: u64, k: u64) -> f64 {
    (-2.0 * (1.0 - unif(seed, stream, 2 * k)).ln()).sqrt()
        * (std::f64::consts::TAU * unif(seed, stream, 2 * k + 1)).cos()
}

#[derive(Clone, Copy, PartialEq)]
enum Maneuver {
    Straight,
    LaneChange,
    Skidpad,
    Fishhook,
    Slalom,
    Figure8,
}

const MANEUVERS: [(Maneuver, &str); 6] = [
    (Maneuver::Straight, "straight"),
    (Maneuver::LaneChange, "lane-change"),
    (Maneuver::Skidpad, "skidpad"),
    (Maneuver::Fishhook, "fishhook"),
    (Maneuver::Slalom, "slalom"),
    (Maneuver::Figure8, "figure-8"),
];

/// Front amplitude of the program at sample `k` (rear is its negative).
fn program(m: Maneuver, k: usize, figure8_sign: &[f64]) -> f64 {
    let t = k as f64 * DT;
    match m {
        Maneuver::Straight => 0.0,
        Maneuver::LaneChange if (14.8..15.0).contains(&t) => A,
        Maneuver::LaneChange if (15.0..15.2).contains(&t) => -A,
        Maneuver::LaneChange => 0.0,
        Maneuver::Skidpad if (2.5..27.5).contains(&t) => A,
        Maneuver::Skidpad => 0.0,
        Maneuver::Fishhook if (2.5..25.0).contains(&t) => A * (t - 2.5) / 22.5,
        Maneuver::Fishhook if (25.0..27.5).contains(&t) => A,
        Maneuver::Fishhook => 0.0,
        Maneuver::Slalom if (2.5..27.5).contains(&t) => A * (30.0 * std::f64::consts::PI * (t - 2.5) / 25.0).cos(),
        Maneuver::Slalom => 0.0,
        Maneuver::Figure8 => A * figure8_sign[k],
    }
}

enum Controller<'a> {
    OpenLoop,
    Robust(&'a [[f64; 2]; 4]),
    Tracking(&'a [[f64; 4]; 4]),
}

struct SpeedHold {
    integral: f64,
}

impl SpeedHold {
    fn force(&mut self, s: &State<f64>) -> f64 {
        let e = 0.35 - s[idx::V_X].hypot(s[idx::V_Y]);
        let f = 53.6 * e + 268.0 * self.integral;
        if f.abs() > 20.0 {
            20f64.copysign(f)
        } else {
            self.integral += e * DT;
            f
        }
    }
}

struct Run {
    states: Vec<State<f64>>,
    max_steer: f64,
}

#[allow(clippy::too_many_arguments)]
fn simulate(
    p: &VehicleParams,
    m: Maneuver,
    figure8_sign: &[f64],
    ctrl: &Controller,
    reference: Option<&[State<f64>]>,
    seed: u64,
    disturbed: bool,
    noisy: bool,
) -> Run {
    let mut s = nigel_vehicle::straight_running(0.35);
    let mut hold = SpeedHold { integral: 0.0 };
    let mut states = Vec::with_capacity(N + 1);
    states.push(s);
    let mut max_steer: f64 = 0.0;
    for k in 0..N {
        let t = k as f64 * DT;
        let ku = k as u64;
        let mut u = Inputs::coasting(0.4);
        if disturbed {
            let theta = std::f64::consts::TAU * t / 30.0;
            for i in 0..4 {
                let phi = i as f64 * std::f64::consts::FRAC_PI_2;
                u.mu[i] = 0.35 * (std::f64::consts::TAU * 12.0 * theta - phi).sin()
                    + 0.55
                    + (0.1 * unif(seed, i as u64, ku) - 0.05);
            }
            let fw = if t >= 1.0 { 0.25 } else { 0.0 } + 0.1 * 0.25 * unif(seed, 4, ku);
            u.wind_y = fw;
        }
        let front = program(m, k, figure8_sign);
        let mut delta = [front, front, -front, -front];
        let mut measured = s;
        if noisy {
            let beta = s[idx::V_Y].atan2(s[idx::V_X]) + 0.005 * gauss(seed, 5, ku);
            let speed = s[idx::V_X].hypot(s[idx::V_Y]);
            measured[idx::V_X] = speed * beta.cos();
            measured[idx::V_Y] = speed * beta.sin();
            measured[idx::YAW_RATE] = s[idx::YAW_RATE] + 0.01 * gauss(seed, 6, ku);
        }
        if let Some(r) = reference {
            let rk = &r[k];
            match ctrl {
                Controller::OpenLoop => {}
                Controller::Robust(gain) => {
                    let x = [
                        measured[idx::V_Y].atan2(measured[idx::V_X]) - rk[idx::V_Y].atan2(rk[idx::V_X]),
                        measured[idx::YAW_RATE] - rk[idx::YAW_RATE],
                    ];
                    for i in 0..4 {
                        delta[i] += gain[i][0] * x[0] + gain[i][1] * x[1];
                    }
                }
                Controller::Tracking(gain) => {
                    let e = tracking_errors(&measured, rk).feedback();
                    for i in 0..4 {
                        delta[i] += (0..4).map(|j| gain[i][j] * e[j]).sum::<f64>();
                    }
                }
            }
        }
        max_steer = delta.iter().fold(max_steer, |a, d| a.max(d.abs()));
        u.delta = delta;
        let f = hold.force(&s);
        u.tau = [f * p.r_wheel / 4.0; 4];
        s = integrate(p, &s, &u, DT, 5e-4);
        states.push(s);
    }
    Run { states, max_steer }
}

/// The figure-8 switching table from the nominal paper-fidelity run.
fn figure8_table() -> Vec<f64> {
    let p = VehicleParams::table2();
    let mut sign = 1.0;
    let mut table = vec![0.0; N];
    let mut s = nigel_vehicle::straight_running(0.35);
    let mut hold = SpeedHold { integral: 0.0 };
    let mut psi_last = 0.0;
    let mut dist_prev = f64::INFINITY;
    let mut flips = Vec::new();
    for (k, slot) in table.iter_mut().enumerate() {
        let dist = s[idx::X].hypot(s[idx::Y]);
        if (s[idx::PSI] - psi_last).abs() >= 1.5 * std::f64::consts::PI && dist > dist_prev {
            sign = -sign;
            psi_last = s[idx::PSI];
            flips.push(k);
        }
        dist_prev = dist;
        *slot = sign;
        let mut u = Inputs::coasting(0.4);
        u.delta = [A * sign, A * sign, -A * sign, -A * sign];
        let f = hold.force(&s);
        u.tau = [f * p.r_wheel / 4.0; 4];
        s = integrate(&p, &s, &u, DT, 5e-4);
    }
    eprintln!("figure-8 flips at samples {:?} (spec: 3144, 6267, 9390, ...)", &flips[..flips.len().min(3)]);
    table
}

fn epsilon(run: &[State<f64>], reference: &[State<f64>]) -> f64 {
    let mut sq = [0.0; 3];
    for k in 1..=N {
        for (j, ix) in [idx::X, idx::Y, idx::PSI].into_iter().enumerate() {
            sq[j] += (run[k][ix] - reference[k][ix]).powi(2);
        }
    }
    sq.iter().map(|s| s / N as f64).sum::<f64>().sqrt()
}

fn main() {
    let seeds: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(10);
    let opts = SynthesisOptions::default();
    let paper_poly = PlantSpec::paper(Architecture::FourWheelSteering).polytope().unwrap();
    let sweep = pareto_sweep(&paper_poly, &PoleRegion::paper(), &SweepOptions::default(), &opts, None).unwrap();
    let kp = &sweep.chosen_design().unwrap().gain;
    let k_paper: [[f64; 2]; 4] = std::array::from_fn(|i| [kp[(i, 0)], kp[(i, 1)]]);
    let design = design_tracking(
        &TrackingSpec::default_design(),
        &tracking_region(),
        &opts,
        &VerifyOptions { interior_points: 4, ..VerifyOptions::default() },
        0,
        None,
    )
    .unwrap();
    let k_track = design.k_track;
    let table = figure8_table();
    println!("epsilon over seeds 0..{} (mean / worst); ratio = worst over seeds of tracking / robust", seeds - 1);
    println!(
        "{:<12} {:<5} | {:>19} | {:>19} | {:>19} | {:>6} | {:>9}",
        "maneuver", "col", "open loop", "robust (paper)", "tracking", "ratio", "max|delta|"
    );
    for (m, name) in MANEUVERS {
        for (col, params, noisy) in
            [("sim", VehicleParams::table2(), false), ("real", VehicleParams::real_fidelity(), true)]
        {
            let reference = simulate(&params, m, &table, &Controller::OpenLoop, None, 0, false, false).states;
            let mut stats = [(0.0, 0.0f64); 3];
            let mut worst_ratio: f64 = 0.0;
            let mut max_steer: f64 = 0.0;
            let mut tracking_best_everywhere = true;
            for seed in 0..seeds {
                let mut eps = [0.0; 3];
                for (c, ctrl) in [Controller::OpenLoop, Controller::Robust(&k_paper), Controller::Tracking(&k_track)]
                    .iter()
                    .enumerate()
                {
                    let run = simulate(&params, m, &table, ctrl, Some(&reference), seed, true, noisy);
                    eps[c] = epsilon(&run.states, &reference);
                    stats[c].0 += eps[c] / seeds as f64;
                    stats[c].1 = stats[c].1.max(eps[c]);
                    if c == 2 {
                        max_steer = max_steer.max(run.max_steer);
                    }
                }
                worst_ratio = worst_ratio.max(eps[2] / eps[1]);
                tracking_best_everywhere &= eps[2] < eps[0] && eps[2] < eps[1];
            }
            println!(
                "{name:<12} {col:<5} | {:>9.3e} {:>9.3e} | {:>9.3e} {:>9.3e} | {:>9.3e} {:>9.3e} | {:>6.3} | {:>9.4}{}",
                stats[0].0,
                stats[0].1,
                stats[1].0,
                stats[1].1,
                stats[2].0,
                stats[2].1,
                worst_ratio,
                max_steer,
                if tracking_best_everywhere { "" } else { "  (tracking not lowest in every seed)" }
            );
        }
    }
}
