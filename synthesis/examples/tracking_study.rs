//! The short study behind the tracking weights ([`nigel_synthesis::tracking`]): for each
//! candidate (lateral, heading and steering allowances), the min-H-inf design `gamma*`, the
//! Pareto point, and the linear closed loop at the 16 vertices: a 0.25 N wind step, the
//! recovery from a 2 cm lateral offset, and the loop with the 0.03 s steering servo.
//!
//! `cargo run --release -p nigel-synthesis --example tracking_study`

use nigel_synthesis::design::{min_hinf, pareto_sweep};
use nigel_synthesis::tracking::{
    offset_recovery, servo_loop_max_real_part, tracking_region, tracking_sweep_options, wind_step,
};
use nigel_synthesis::{verify_design, SynthesisOptions, TrackingSpec, TrackingWeights, VerifyOptions};

fn main() {
    let region = tracking_region();
    let opts = SynthesisOptions::default();
    println!("pole region: {}", region.describe());
    println!(
        "{:>6} {:>6} {:>6} | {:>8} {:>8} {:>8} | {:>6} {:>6} | {:>8} {:>8} {:>8} | {:>7} {:>7} {:>7} | {:>8} | {:>7} {:>7} | verified",
        "e_y", "e_psi", "u", "gamma*", "g", "nu", "slow", "fast", "wind ss", "wind pk", "wind u'", "off u", "off u'",
        "off 2s", "servo Re", "|K_y|", "|K_psi|"
    );
    let lateral = [0.10, 0.05, 0.02, 0.01];
    let steering = [0.1, 0.25, 0.5];
    for &ly in &lateral {
        for &lu in &steering {
            let weights = TrackingWeights { lateral: 1.0 / ly, heading: 1.0 / 0.1, steering: 1.0 / lu };
            let spec = TrackingSpec { weights, ..TrackingSpec::default_design() };
            let poly = spec.polytope().unwrap();
            let gs = match min_hinf(&poly, &region, &opts) {
                Ok(d) => d.gamma.unwrap(),
                Err(e) => {
                    println!("{ly:>6} {:>6} {lu:>6} | {e}", 0.1);
                    continue;
                }
            };
            let sweep = pareto_sweep(&poly, &region, &tracking_sweep_options(gs, 0), &opts, None).unwrap();
            let d = sweep.chosen_design().unwrap();
            let g = sweep.chosen_point().g;
            let k = &d.gain;
            let v = verify_design(&poly, &region, k, Some(g), d.nu, &VerifyOptions::default());
            let slow = v.vertices.iter().flat_map(|p| p.poles.iter().map(|z| -z[0])).fold(f64::INFINITY, f64::min);
            let fast = v.vertices.iter().flat_map(|p| p.poles.iter().map(|z| z[0].hypot(z[1]))).fold(0.0, f64::max);
            let wind = wind_step(&poly, k, 0.25, 10.0);
            let off = offset_recovery(&poly, k, 0.02, 2.0);
            let servo = servo_loop_max_real_part(&poly, k, 0.03);
            let ky = (0..k.nrows()).map(|i| k[(i, 0)].abs()).fold(0.0, f64::max);
            let kp = (0..k.nrows()).map(|i| k[(i, 1)].abs()).fold(0.0, f64::max);
            println!(
                "{ly:>6} {:>6} {lu:>6} | {gs:>8.4} {g:>8.4} {:>8.4} | {slow:>6.2} {fast:>6.1} | {:>8.5} {:>8.5} {:>8.4} | {:>7.4} {:>7.3} {:>7.4} | {servo:>8.3} | {ky:>7.2} {kp:>7.2} | {}",
                0.1,
                d.nu.unwrap(),
                wind.lateral_final,
                wind.lateral_peak,
                wind.steering_rate_peak,
                off.steering_peak,
                off.steering_rate_peak,
                off.lateral_final,
                v.passed()
            );
        }
    }
}
