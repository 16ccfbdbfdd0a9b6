//! The norm computations against closed-form values, the two methods against each other,
//! and the other problems (weighted, H2, baseline) verified.

mod common;
use common::paper_4ws;
use nalgebra::DMatrix;
use nigel_synthesis::verify::{ClosedLoop, NormError, SplitMix64};
use nigel_synthesis::{
    min_h2, min_hinf, pole_placement_baseline, verify_design, weighted, PoleRegion,
    SynthesisOptions, VerifyOptions,
};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn system(a: &[f64], bw: &[f64], c: &[f64], nz: usize) -> ClosedLoop {
    ClosedLoop {
        a: DMatrix::from_row_slice(2, 2, a),
        bw: DMatrix::from_row_slice(2, 1, bw),
        c: DMatrix::from_row_slice(nz, 2, c),
    }
}

#[test]
fn norms_of_a_diagonal_system() {
    // G(s) = [1/(s+1); 1/(s+2)]: ||G||_2^2 = 1/2 + 1/4, ||G||_inf = |G(0)| = sqrt(1 + 1/4)
    let s = system(&[-1.0, 0.0, 0.0, -2.0], &[1.0, 1.0], &[1.0, 0.0, 0.0, 1.0], 2);
    let h2 = 0.75f64.sqrt();
    let hinf = 1.25f64.sqrt();
    assert!(rel(s.h2_norm_lyapunov().unwrap(), h2) < 1e-12);
    assert!(rel(s.h2_norm_dual_lyapunov().unwrap(), h2) < 1e-12);
    assert!(rel(s.h2_norm_gramian_integration().unwrap(), h2) < 1e-9);
    let b = s.hinf_norm_hamiltonian(1e-12).unwrap();
    assert!(b.lower <= b.upper && rel(b.upper, hinf) < 1e-10, "{b:?}");
    assert!(rel(s.hinf_norm_frequency_sweep().unwrap(), hinf) < 1e-10);
}

#[test]
fn hinf_of_a_resonance_peak() {
    // x'' + 2 z w0 x' + w0^2 x = w: peak 1 / (2 z w0^2 sqrt(1 - z^2)) at w0 sqrt(1 - 2 z^2)
    let (z, w0) = (0.05, 3.0);
    let s = system(&[0.0, 1.0, -w0 * w0, -2.0 * z * w0], &[0.0, 1.0], &[1.0, 0.0], 1);
    let peak = 1.0 / (2.0 * z * w0 * w0 * (1.0 - z * z).sqrt());
    let b = s.hinf_norm_hamiltonian(1e-12).unwrap();
    assert!(rel(b.upper, peak) < 1e-9, "{b:?} vs {peak}");
    assert!(rel(s.hinf_norm_frequency_sweep().unwrap(), peak) < 1e-9);
    // H2^2 of 1/(s^2 + 2 z w0 s + w0^2) is 1/(4 z w0^3)
    let h2 = (1.0 / (4.0 * z * w0.powi(3))).sqrt();
    assert!(rel(s.h2_norm_lyapunov().unwrap(), h2) < 1e-12);
    assert!(rel(s.h2_norm_gramian_integration().unwrap(), h2) < 1e-8);
}

#[test]
fn the_two_ways_agree_on_random_stable_systems() {
    let mut rng = SplitMix64::new(42);
    let mut checked = 0;
    while checked < 200 {
        let mut r = || 20.0 * rng.next_f64() - 10.0;
        let a = [r(), r(), r(), r()];
        let s = ClosedLoop {
            a: DMatrix::from_row_slice(2, 2, &a),
            bw: DMatrix::from_row_slice(2, 1, &[r(), r()]),
            c: DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 0.0, 1.0, r(), r(), r(), r()]),
        };
        if s.max_real_part() >= 0.0 {
            assert!(matches!(s.h2_norm_lyapunov(), Err(NormError::Unstable { .. })));
            assert!(matches!(s.hinf_norm_hamiltonian(1e-10), Err(NormError::Unstable { .. })));
            assert!(s.hinf_norm_frequency_sweep().is_err() && s.h2_norm_gramian_integration().is_err());
            continue;
        }
        if s.max_real_part() >= -1e-3 {
            continue; // too close to the axis for a meaningful comparison
        }
        let h2 = s.h2_norm_lyapunov().unwrap();
        assert!(rel(s.h2_norm_dual_lyapunov().unwrap(), h2) < 1e-9);
        assert!(rel(s.h2_norm_gramian_integration().unwrap(), h2) < 1e-7, "{s:?}");
        let b = s.hinf_norm_hamiltonian(1e-11).unwrap();
        let sweep = s.hinf_norm_frequency_sweep().unwrap();
        assert!(rel(b.upper, sweep) < 1e-8, "{s:?}: {b:?} vs sweep {sweep}");
        // the sweep is a lower bound: an attained value
        assert!(sweep <= b.upper * (1.0 + 1e-12), "{s:?}: {b:?} vs sweep {sweep}");
        // and H-inf >= H2-ish sanity: both positive
        assert!(b.upper > 0.0 && h2 > 0.0);
        checked += 1;
    }
}

#[test]
fn weighted_and_h2_designs_verify() {
    let poly = paper_4ws();
    let opts = SynthesisOptions::default();
    let region = PoleRegion::paper();
    let gs = min_hinf(&poly, &region, &opts).unwrap().gamma.unwrap();
    // equal weights land near the knee of the curve
    let w = weighted(&poly, &region, 1.0, 1.0, &opts).unwrap();
    let (g, nu) = (w.gamma.unwrap(), w.nu.unwrap());
    assert!(g > gs && g < 0.3 && nu > 0.5 && nu < 0.6, "weighted ({g}, {nu})");
    // it is on the curve: min nu at its g is (nearly) its nu
    let on_curve = min_h2(&poly, &region, Some(g), &opts).unwrap().nu.unwrap();
    assert!(rel(on_curve, nu) < 1e-4, "{on_curve} vs {nu}");
    let v = verify_design(&poly, &region, &w.gain, w.gamma, w.nu, &VerifyOptions::default());
    assert!(v.passed() && v.worst_hinf <= g && v.worst_h2 <= nu, "{v:?}");
    assert!(v.hinf_methods_rel_diff < 1e-6 && v.h2_methods_rel_diff < 1e-6);
    // H2 alone: smaller nu than any point of the curve, no H-inf bound certified
    let h = min_h2(&poly, &region, None, &opts).unwrap();
    assert!(h.gamma.is_none() && h.nu.unwrap() < on_curve);
    let v = verify_design(&poly, &region, &h.gain, None, h.nu, &VerifyOptions::default());
    assert!(v.passed() && v.worst_h2 <= h.nu.unwrap());
}

#[test]
fn pole_placement_baseline_is_deterministic_and_reports_robustness() {
    let poly = paper_4ws();
    let opts = SynthesisOptions::default();
    let b = pole_placement_baseline(&poly, 0.4, -2.0, &opts).unwrap();
    let again = pole_placement_baseline(&poly, 0.4, -2.0, &opts).unwrap();
    assert_eq!(b.design.gain, again.design.gain, "deterministic");
    // X >= I holds
    let x = &b.design.lyapunov;
    assert!(nalgebra::SymmetricEigen::new(x.clone()).eigenvalues.min() >= 1.0 - 1e-7);
    // the nominal closed loop has its poles left of -2
    let nominal = poly.at([0.4; 4]);
    let cl = ClosedLoop::new(&nominal, &poly.bw, &b.design.gain);
    assert!(cl.max_real_part() < -2.0, "{:?}", cl.poles());
    // the robustness claim is what the poles say at the 16 vertices
    let worst = poly
        .vertices
        .iter()
        .map(|v| ClosedLoop::new(v, &poly.bw, &b.design.gain).max_real_part())
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(b.max_real_part_over_vertices, worst);
    assert_eq!(b.stabilises_all_vertices, worst < 0.0);
}
