//! The controller's FMI 3.0 description declares the
//! sample period as the periodic input clock `sample_clock`, and a run driven by the
//! clock's activations (Co-Simulation with Event Mode, through the layer's C entry points)
//! gives the FMI 2.0 run's outputs to the bit at every sample, inputs set at the same
//! instants.

use fmi_export::abi::fmi3 as abi3;
use fmi_export::fmi_sys::fmi3::*;
use fmi_export::testing::{Fmu, Fmu3, OK, OK3};
use fmi_export::{Function, Model};
use nigel_controller::Controller;

const INPUTS: [&str; 10] = [
    "beta",
    "yaw_rate",
    "speed",
    "beta_ref",
    "yaw_rate_ref",
    "speed_ref",
    "delta_ff_fl",
    "delta_ff_fr",
    "delta_ff_rl",
    "delta_ff_rr",
];
const OUTPUTS: [&str; 9] =
    ["delta_fl", "delta_fr", "delta_rl", "delta_rr", "tau_fl", "tau_fr", "tau_rl", "tau_rr", "drive_force"];

/// FMI 2.0 and FMI 3.0 value references of `name` (row r is FMI 3.0 value reference r + 1).
fn vrs(name: &str) -> (u32, u32) {
    let d = Controller::declaration();
    let row = d.spec.variables.iter().position(|v| v.name == name).unwrap_or_else(|| panic!("no {name}"));
    (d.spec.variables[row].value_reference, row as u32 + 1)
}

/// Inputs at sample k: a slow sweep that saturates the drive force now and then.
fn inputs(k: usize) -> [f64; 10] {
    let t = k as f64 * 1e-3;
    let s = (7.0 * t).sin();
    [0.02 * s, 0.3 * (3.0 * t).cos(), 0.2 + 0.5 * t, 0.0, 0.1 * s, 0.9, 0.05 * s, 0.05 * s, 0.0, 0.0]
}

#[test]
fn the_fmi3_description_declares_the_sample_clock_governing_the_held_outputs() {
    let d = Controller::declaration();
    let (clock, vr) = d.clock().expect("the sample clock");
    assert_eq!(clock.name, "sample_clock");
    let xml3 = d.xml3();
    assert!(xml3.contains(&format!(r#"<Clock name="sample_clock" valueReference="{vr}""#)), "{xml3}");
    assert!(xml3.contains(r#"intervalVariability="fixed""#) && xml3.contains(r#"hasEventMode="true""#));
    assert_eq!(xml3.matches(&format!(r#"clocks="{vr}""#)).count(), OUTPUTS.len(), "{xml3}");
    assert!(!d.xml().contains("Clock"), "FMI 2.0 has no clocks");
}

/// 400 samples of 1 ms from t = 0: the FMI 3.0 run activates the clock at each t_k = k
/// 1 ms (the interval read with fmi3GetIntervalDecimal), the FMI 2.0 run steps 1 ms; the
/// nine held outputs and the integrator agree to the bit at every sample.
#[test]
fn a_clocked_run_equals_the_fmi2_run_bit_for_bit() {
    let (_, clock_vr) = Controller::declaration().clock().unwrap();
    let f3 = Fmu3::<Controller>::try_cs(Controller::declaration().guid(), true).unwrap();
    let f2 = Fmu::<Controller>::cs();
    f2.init();
    assert_eq!(f3.enter_init(0.0, None), OK3);
    let (mut interval, mut qualifier) = (f64::NAN, -1);
    let s = unsafe {
        abi3::get_interval_decimal::<Controller>(
            Function::Fmi3GetIntervalDecimal,
            f3.c,
            &clock_vr,
            1,
            &mut interval,
            &mut qualifier,
        )
    };
    assert_eq!((s, interval, qualifier), (OK3, 1e-3, FMI3_INTERVAL_CHANGED));
    assert_eq!(f3.exit_init(), OK3, "{}", f3.last_error());
    let in_vrs: Vec<(u32, u32)> = INPUTS.iter().map(|n| vrs(n)).collect();
    let out_vrs: Vec<(u32, u32)> = OUTPUTS.iter().chain(&["speed_integral"]).map(|n| vrs(n)).collect();
    let (out2, out3): (Vec<u32>, Vec<u32>) = out_vrs.into_iter().unzip();
    let mut t = 0.0;
    for k in 0..400 {
        let x = inputs(k);
        if k > 0 {
            assert_eq!(f3.enter_event_mode(), OK3, "{}", f3.last_error());
        }
        for (&(v2, v3), &value) in in_vrs.iter().zip(&x) {
            assert_eq!(f2.set_real(v2, value), OK);
            assert_eq!(f3.set_float64(&[v3], &[value]), OK3);
        }
        let active = FMI3_CLOCK_ACTIVE;
        let s = unsafe { abi3::set_clock::<Controller>(Function::Fmi3SetClock, f3.c, &clock_vr, 1, &active) };
        assert_eq!(s, OK3, "{}", f3.last_error());
        let mut y3 = vec![0.0; out3.len()];
        assert_eq!(f3.get_float64(&out3, &mut y3), OK3, "{}", f3.last_error());
        let y2 = f2.reals(&out2);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&y3), bits(&y2), "sample {k} at t = {t} s");
        f3.update_discrete_states();
        let s = unsafe { abi3::enter_step_mode::<Controller>(Function::Fmi3EnterStepMode, f3.c) };
        assert_eq!(s, OK3, "{}", f3.last_error());
        assert_eq!(f3.step(t, 1e-3).status, OK3, "{}", f3.last_error());
        assert_eq!(f2.step(t, 1e-3), OK);
        t += 1e-3;
    }
}
