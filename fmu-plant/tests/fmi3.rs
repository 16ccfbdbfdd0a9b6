//! The plant through the FMI 3.0 ABI, in process: its Co-Simulation run equal to the FMI
//! 2.0 run to the bit, and its exact directional and adjoint derivatives (`J v` by dual
//! numbers, `J^T w` from J's columns) checked against each other (`<w, J v> = <J^T w, v>`)
//! and against central differences.

use fmi_export::testing::{Fmu, Fmu3, ERR3, OK, OK3};
use fmi_export::Model;
use nigel_plant::Plant;

type P3 = Fmu3<Plant>;

/// The FMI 3.0 value reference of `name`.
fn vr3(name: &str) -> u32 {
    Plant::declaration()
        .model_description3()
        .variable_by_name(name)
        .unwrap_or_else(|| panic!("no {name}"))
        .value_reference
}

fn vr2(name: &str) -> u32 {
    Plant::declaration().value_reference(name).unwrap()
}

const INPUTS: [&str; 12] = [
    "delta_fl", "delta_fr", "delta_rl", "delta_rr", "tau_fl", "tau_fr", "tau_rl", "tau_rr", "mu_fl", "mu_fr", "mu_rl",
    "mu_rr",
];

/// A deterministic sequence in [0, 1) (64-bit LCG, the top 53 bits).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn within(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// Inputs inside the smooth region of the model: moderate steering and drive, grip.
fn random_inputs(r: &mut Lcg) -> Vec<f64> {
    let mut u = Vec::new();
    for _ in 0..4 {
        u.push(r.within(-0.25, 0.25));
    }
    for _ in 0..4 {
        u.push(r.within(0.0, 0.004));
    }
    for _ in 0..4 {
        u.push(r.within(0.5, 1.0));
    }
    u
}

#[test]
fn co_simulation_through_fmi3_equals_the_fmi2_run_bit_for_bit() {
    let f2 = Fmu::<Plant>::cs();
    f2.init_until(0.0, Some(2.0));
    let f3 = P3::cs();
    f3.init_until(0.0, Some(2.0));
    let outputs: Vec<&str> = Plant::declaration()
        .spec
        .variables
        .iter()
        .filter(|v| v.causality == fmi_export::Causality::Output)
        .map(|v| v.name)
        .collect();
    assert!(outputs.len() > 20);
    let mut r = Lcg(7);
    let (mut t, h) = (0.0, 0.02);
    for _ in 0..100 {
        let u = random_inputs(&mut r);
        for (name, x) in INPUTS.iter().zip(&u) {
            assert_eq!(f2.set_real(vr2(name), *x), OK);
        }
        let vrs: Vec<u32> = INPUTS.iter().map(|n| vr3(n)).collect();
        assert_eq!(f3.set_float64(&vrs, &u), OK3);
        assert_eq!(f2.step(t, h), OK);
        let s = f3.step(t, h);
        assert_eq!(s.status, OK3, "{}", f3.last_error());
        t += h;
        assert!(!s.terminate_simulation && !s.early_return && !s.event_handling_needed);
        assert_eq!(s.last_successful_time.to_bits(), t.to_bits());
        for name in &outputs {
            assert_eq!(f2.real(vr2(name)).to_bits(), f3.float64(vr3(name)).to_bits(), "{name} at {t}");
        }
    }
}

/// Model Exchange at a random point: the states and inputs set, in Continuous-Time Mode.
fn me_at(r: &mut Lcg) -> P3 {
    let f = P3::me();
    assert_eq!(f.enter_init(0.0, None), OK3);
    assert_eq!(f.set_float64(&[vr3("v_x_start")], &[0.35]), OK3);
    f.exit_init();
    f.update_discrete_states();
    assert_eq!(f.enter_continuous_time_mode(), OK3);
    let mut x = f.continuous_states();
    let names = Plant::declaration().state_rows.iter().map(|&row| Plant::declaration().variable(row).name);
    for (xi, name) in x.iter_mut().zip(names) {
        *xi = match name {
            "v_x" => r.within(0.2, 0.6),
            "v_y" => r.within(-0.03, 0.03),
            "yaw_rate" => r.within(-0.5, 0.5),
            "psi" => r.within(-3.0, 3.0),
            n if n.starts_with("servo_angle") => r.within(-0.2, 0.2),
            _ => r.within(-1.0, 1.0),
        };
    }
    assert_eq!(f.set_continuous_states(&x), OK3, "{}", f.last_error());
    let u = random_inputs(r);
    assert_eq!(f.set_float64(&INPUTS.map(vr3), &u), OK3, "{}", f.last_error());
    f
}

/// The unknowns (the outputs and the state derivatives) and the knowns (the inputs and
/// the states) of Continuous-Time Mode, FMI 3.0 value references.
fn unknowns_and_knowns() -> (Vec<u32>, Vec<u32>) {
    let s = &Plant::declaration().model_description3().model_structure;
    let unknowns = s.outputs.iter().chain(&s.continuous_state_derivatives).map(|u| u.value_reference).collect();
    let states = Plant::declaration().model_description3().states();
    let knowns = INPUTS.iter().map(|n| vr3(n)).chain(states).collect();
    (unknowns, knowns)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `<w, J v> = <J^T w, v>` at random points and seeds: J v by one dual-number evaluation
/// with seed v, J^T w from the columns. Both are the same bilinear form of J's entries
/// summed in other orders, so they agree to rounding: within 1e-13 of `sum |w_i J_ij v_j|`
/// (a few hundred products and sums of at most ~60 terms each, eps = 2.2e-16 each: the
/// worst case is ~1e-13 of that sum). The adjoint of a unit seed is a row of J exactly.
#[test]
fn adjoint_and_directional_derivatives_agree_at_random_points() {
    let (unknowns, knowns) = unknowns_and_knowns();
    let mut r = Lcg(42);
    for _ in 0..20 {
        let f = me_at(&mut r);
        let v: Vec<f64> = knowns.iter().map(|_| r.within(-1.0, 1.0)).collect();
        let w: Vec<f64> = unknowns.iter().map(|_| r.within(-1.0, 1.0)).collect();
        let jv = f.directional(&unknowns, &knowns, &v).unwrap_or_else(|s| panic!("{s:?} {}", f.last_error()));
        let jtw = f.adjoint(&unknowns, &knowns, &w).unwrap_or_else(|s| panic!("{s:?} {}", f.last_error()));
        // the columns of J, one directional derivative each
        let columns: Vec<Vec<f64>> = knowns.iter().map(|&k| f.directional(&unknowns, &[k], &[1.0]).unwrap()).collect();
        let scale: f64 = (0..knowns.len())
            .map(|j| (0..unknowns.len()).map(|i| (w[i] * columns[j][i] * v[j]).abs()).sum::<f64>())
            .sum();
        assert!(scale > 1e-3, "a point where J does something: {scale}");
        let (left, right) = (dot(&w, &jv), dot(&jtw, &v));
        assert!((left - right).abs() <= 1e-13 * scale, "<w, Jv> = {left}, <J^T w, v> = {right}, scale {scale}");
        for (i, &unknown) in unknowns.iter().enumerate().step_by(7) {
            let mut e = vec![0.0; unknowns.len()];
            e[i] = 1.0;
            let row = f.adjoint(&unknowns, &knowns, &e).unwrap();
            for j in 0..knowns.len() {
                // equal as numbers (a -0 entry sums to +0)
                assert_eq!(row[j], columns[j][i], "d {unknown} / d {}", knowns[j]);
            }
        }
    }
}

/// J^T w against central differences of `<w, y>` along each known, h = 1e-6 (the
/// tolerance of the FMI 2.0 directional-derivative tests: truncation O(h^2 y''') and
/// rounding O(eps / h) are ~1e-10 relative on these smooth terms; 1e-6 relative plus 1e-7
/// absolute holds with margin).
#[test]
fn adjoint_derivatives_agree_with_central_differences() {
    let (unknowns, knowns) = unknowns_and_knowns();
    let n_inputs = INPUTS.len();
    let mut r = Lcg(1234);
    for _ in 0..3 {
        let f = me_at(&mut r);
        let w: Vec<f64> = unknowns.iter().map(|_| r.within(-1.0, 1.0)).collect();
        let exact = f.adjoint(&unknowns, &knowns, &w).unwrap();
        let u0: Vec<f64> = INPUTS.iter().map(|n| f.float64(vr3(n))).collect();
        let x0 = f.continuous_states();
        let g = |f: &P3| {
            let mut y = vec![0.0; unknowns.len()];
            assert_eq!(f.get_float64(&unknowns, &mut y), OK3, "{}", f.last_error());
            dot(&w, &y)
        };
        let h = 1e-6;
        for j in 0..knowns.len() {
            let at = |d: f64| {
                if j < n_inputs {
                    assert_eq!(f.set_float64(&[knowns[j]], &[u0[j] + d]), OK3);
                } else {
                    let mut x = x0.clone();
                    x[j - n_inputs] += d;
                    assert_eq!(f.set_continuous_states(&x), OK3);
                }
                let value = g(&f);
                assert_eq!(f.set_float64(&INPUTS.map(vr3), &u0), OK3);
                assert_eq!(f.set_continuous_states(&x0), OK3);
                value
            };
            let fd = (at(h) - at(-h)) / (2.0 * h);
            assert!((exact[j] - fd).abs() <= 1e-6 * fd.abs() + 1e-7, "known {}: {} vs {fd}", knowns[j], exact[j]);
        }
    }
}

/// In Initialization Mode the parameters are knowns, in FMI 3.0 as in FMI 2.0: the adjoint
/// agrees with the directional derivatives there too; after initialization a parameter is
/// refused, and so are seed and sensitivity counts that do not fit.
#[test]
fn adjoint_derivatives_in_initialization_mode_and_bad_counts() {
    let f = P3::cs();
    assert_eq!(f.enter_init(0.0, None), OK3);
    assert_eq!(f.set_float64(&[vr3("v_x_start"), vr3("yaw_rate_start")], &[0.35, 0.3]), OK3);
    let s = &Plant::declaration().model_description3().model_structure;
    let unknowns: Vec<u32> = s.continuous_state_derivatives.iter().map(|u| u.value_reference).collect();
    let knowns: Vec<u32> = ["m", "I_z", "l_f", "c_fl", "v_x_start", "delta_fl"].map(vr3).to_vec();
    let mut r = Lcg(5);
    let v: Vec<f64> = knowns.iter().map(|_| r.within(-1.0, 1.0)).collect();
    let w: Vec<f64> = unknowns.iter().map(|_| r.within(-1.0, 1.0)).collect();
    let jv = f.directional(&unknowns, &knowns, &v).unwrap_or_else(|_| panic!("{}", f.last_error()));
    let jtw = f.adjoint(&unknowns, &knowns, &w).unwrap_or_else(|_| panic!("{}", f.last_error()));
    let (left, right) = (dot(&w, &jv), dot(&jtw, &v));
    // scale: the same bound as at random points, from |w| |J| |v| <= sum of |J v| terms
    let scale: f64 = knowns
        .iter()
        .zip(&v)
        .map(|(&k, vj)| {
            let col = f.directional(&unknowns, &[k], &[1.0]).unwrap();
            col.iter().zip(&w).map(|(c, wi)| (c * wi * vj).abs()).sum::<f64>()
        })
        .sum();
    assert!(scale > 0.0 && (left - right).abs() <= 1e-13 * scale, "{left} vs {right} (scale {scale})");
    // counts
    let mut out = vec![0.0; knowns.len()];
    let st = unsafe {
        fmi_export::abi::fmi3::get_partial_derivatives::<Plant>(
            fmi_export::Function::Fmi3GetAdjointDerivative,
            f.c,
            unknowns.as_ptr(),
            unknowns.len(),
            knowns.as_ptr(),
            knowns.len(),
            w.as_ptr(),
            w.len() - 1,
            out.as_mut_ptr(),
            out.len(),
        )
    };
    assert_eq!(st, ERR3);
    assert!(f.last_error().contains("nSeed") && f.last_error().contains("fmi3GetAdjointDerivative"));
    // a parameter after initialization
    let g = P3::cs();
    g.init_until(0.0, None);
    assert_eq!(g.adjoint(&unknowns, &[vr3("m")], &w), Err(ERR3));
    assert!(g.last_error().contains("known m is not an input"), "{}", g.last_error());
}

/// A time an f64 cannot resolve is refused: startTime = f64::MAX (the next double is
/// infinite, so every later currentCommunicationPoint looked like "now") at
/// fmi3EnterInitializationMode, and at startTime = 1e300 a step of 20 ms that leaves the
/// time where it was (the doubles there are 1.5e284 apart) at fmi3DoStep.
#[test]
fn times_an_f64_cannot_resolve_are_refused() {
    let f = P3::cs();
    assert_eq!(f.enter_init(f64::MAX, None), ERR3);
    let e = f.last_error();
    assert!(e.contains("startTime") && e.contains("resolve"), "{e}");
    let f = P3::cs();
    assert_eq!(f.enter_init(0.0, Some(f64::MAX)), ERR3);
    assert!(f.last_error().contains("stopTime"), "{}", f.last_error());
    let f = P3::cs();
    f.init_until(1e300, None);
    let s = f.step(1e300, 0.02);
    assert_eq!(s.status, ERR3);
    let e = f.last_error();
    assert!(e.contains("does not advance") && e.contains("resolves 1.48"), "{e}");
    let f = P3::cs();
    f.init_until(0.0, None);
    assert_eq!(f.step(0.0, 0.02).status, OK3, "{}", f.last_error());
    assert_eq!(f.step(1e300, 0.02).status, ERR3, "a current time far from the FMU's");
}
