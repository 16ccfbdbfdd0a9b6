//! The test-bench FMU through the layer's C entry points: the spec's test vectors bit for
//! bit, the reference and the programs equal to nigel-benchmark's, every maneuver and
//! fidelity initializes, direct feedthrough of the measurement, Model Exchange time
//! events, FMU state, and bad input.

use std::f64::consts::PI;

use fmi_export::testing::{Fmu, DISCARD, ERR, OK};
use fmi_export::Model;
use nigel_benchmark::noise::g;
use nigel_benchmark::{Benchmark, Fidelity, Maneuver, Scenario};
use nigel_maneuver::{fidelity_value, maneuver_value, TestBench};

/// The value reference of the variable `name` (by name, as an importer finds it).
fn vr(name: &str) -> u32 {
    TestBench::declaration().value_reference(name).unwrap_or_else(|| panic!("no variable {name}"))
}

type B = Fmu<TestBench>;
const T: f64 = 1e-3;

fn bench(m: Maneuver, f: Fidelity, duration: f64) -> B {
    let b = B::cs();
    assert_eq!(b.set_int(vr("maneuver"), maneuver_value(m)), OK);
    assert_eq!(b.set_int(vr("fidelity"), fidelity_value(f)), OK);
    assert_eq!(b.set_real(vr("duration"), duration), OK);
    b.init();
    b
}

#[test]
fn spec_vectors_at_the_first_samples() {
    let b = bench(Maneuver::Straight, Fidelity::Real, 1.5);
    // k = 0: mu_fl, and beta_meas with beta = 0 is 0.005 g(0, 5, 0)
    // MU at k = 0 is arithmetic on a SplitMix64 uniform (sin(0) = 0): bit-exact anywhere; the
    // noise g goes through the platform libm's ln and cos, so it is compared with this process's
    // g bit for bit and with the spec's glibc vector to 1e-15 relative (benchmark/src/noise.rs)
    assert_eq!(b.real(vr("mu_fl")), 0.5883310808213643);
    assert_eq!(b.real(vr("beta_meas")), 0.005 * g(0, 5, 0));
    assert!((g(0, 5, 0) - 0.014334745996352224).abs() <= 1e-15 * 0.014334745996352224);
    assert_eq!(b.real(vr("yaw_rate_meas")), 0.01 * g(0, 6, 0));
    assert_eq!(b.step(0.0, T), OK);
    // k = 1: the friction's sin and the noise's ln, cos are the platform libm's (within 1 ulp
    // of correctly rounded): 1e-15 is over 10 ulp of mu and of 0.005 g
    assert!((b.real(vr("mu_fl")) - 0.5486795484644006).abs() < 1e-15, "{}", b.real(vr("mu_fl")));
    assert!((b.real(vr("beta_meas")) - 0.005 * 0.5906209568869251).abs() < 1e-17, "{}", b.real(vr("beta_meas")));
    assert_eq!(b.step(T, 998.0 * T), OK);
    assert_eq!(b.real(vr("wind_y")), 0.007915537544713306, "k = 999");
    assert_eq!(b.step(999.0 * T, T), OK);
    assert_eq!(b.real(vr("wind_y")), 0.2629350570802014, "k = 1000");
    assert_eq!(b.real(vr("wind_x")), 0.0);
}

#[test]
fn figure8_switches_at_the_spec_samples() {
    let b = bench(Maneuver::Figure8, Fidelity::Paper, 9.5);
    let a = PI / 6.0;
    let mut sign = 1.0;
    let mut flips = Vec::new();
    for k in 0..9_500u32 {
        let front = b.real(vr("delta_ff_fl"));
        assert_eq!(b.real(vr("delta_ff_fl") + 2), -front);
        if front != sign * a {
            assert_eq!(front, -sign * a, "k = {k}");
            sign = -sign;
            flips.push(k);
        }
        assert_eq!(b.step(k as f64 * T, T), OK);
    }
    assert_eq!(flips, [3144, 6267, 9390]);
}

#[test]
fn reference_and_program_are_the_benchmark_library_s() {
    for (m, f) in [(Maneuver::LaneChange, Fidelity::Real), (Maneuver::Slalom, Fidelity::Paper)] {
        let b = bench(m, f, 16.0);
        let lib = Benchmark::prepare(Scenario { n_samples: 16_000, ..Scenario::new(m, f) }).unwrap();
        let r = &lib.reference.trajectory;
        let mut t = 0.0;
        let beta = 0.01;
        assert_eq!(b.set_real(vr("beta"), beta), OK);
        for k in 0..=16_000usize {
            if k % 7 == 0 || (14_790..15_210).contains(&k) {
                let got = b.reals(&[
                    vr("x_ref"),
                    vr("y_ref"),
                    vr("psi_ref"),
                    vr("beta_ref"),
                    vr("yaw_rate_ref"),
                    vr("speed_ref"),
                ]);
                assert_eq!(got, [r.x[k], r.y[k], r.psi[k], r.beta[k], r.yaw_rate[k], 0.35], "{m} k = {k}");
                let s = lib.sample(k, beta, 0.0).unwrap();
                assert_eq!(b.real(vr("delta_ff_fl") + 1), s.delta_ff[1], "{m} k = {k}");
                assert_eq!(b.real(vr("mu_fl") + 3), s.mu[3]);
                assert_eq!(b.real(vr("beta_meas")), s.beta_meas);
            }
            if k < 16_000 {
                assert_eq!(b.step(t, T), OK, "{}", b.last_error());
                t = (k + 1) as f64 * T;
            }
        }
        // the run ends at `duration` the FMI way: a step past it is discarded, the time stays
        // at the end, fmi2Terminated is true, and the last sample's values stand
        assert_eq!(b.step(t, T), DISCARD);
        assert!(b.last_message().contains("duration"), "{}", b.last_message());
        assert!(b.terminated());
        assert_eq!(b.last_successful_time(), 16.0);
        assert_eq!(b.real(vr("x_ref")), r.x[16_000]);
    }
}

#[test]
fn every_maneuver_and_fidelity_initializes() {
    for m in Maneuver::ALL {
        for f in Fidelity::ALL {
            let b = bench(m, f, 30.0);
            assert_eq!(b.step(0.0, 10.0 * T), OK, "{m} {f:?}: {}", b.last_error());
            let x = b.real(vr("x_ref"));
            assert!(x > 0.0033 && x < 0.0036, "{m} {f:?}: x_ref = {x}");
        }
    }
}

#[test]
fn measurement_is_fed_through_and_held() {
    let b = bench(Maneuver::Skidpad, Fidelity::Real, 1.0);
    assert_eq!(b.step(0.0, T), OK);
    assert_eq!(b.set_real(vr("beta"), 0.2), OK);
    assert_eq!(b.real(vr("beta_meas")), 0.2 + 0.005 * g(0, 5, 1), "the input of t_1 at t_1");
    assert_eq!(b.set_real(vr("beta"), 0.3), OK);
    assert_eq!(b.real(vr("beta_meas")), 0.3 + 0.005 * g(0, 5, 1), "set again at the same instant");
    assert_eq!(b.step(T, 0.5 * T), OK);
    assert_eq!(b.set_real(vr("beta"), -0.3), OK);
    assert_eq!(b.real(vr("beta_meas")), 0.3 + 0.005 * g(0, 5, 1), "held between samples");
    // paper fidelity and the noise switch off: the true value
    for (f, noise) in [(Fidelity::Paper, true), (Fidelity::Real, false)] {
        let b = B::cs();
        assert_eq!(b.set_int(vr("fidelity"), fidelity_value(f)), OK);
        assert_eq!(b.set_bool(vr("measurement_noise"), noise), OK);
        assert_eq!(b.set_real(vr("duration"), 0.1), OK);
        b.init();
        assert_eq!(b.set_real(vr("yaw_rate"), 0.7), OK);
        assert_eq!(b.real(vr("yaw_rate_meas")), 0.7);
    }
}

#[test]
fn disturbance_switches_and_seed() {
    let b = B::cs();
    assert_eq!(b.set_bool(vr("friction_variation"), false), OK);
    assert_eq!(b.set_bool(vr("wind"), false), OK);
    assert_eq!(b.set_int(vr("seed"), 7), OK);
    assert_eq!(b.set_real(vr("duration"), 2.0), OK);
    b.init();
    assert_eq!(b.step(0.0, 1.5), OK);
    assert_eq!(
        b.reals(&[vr("mu_fl"), vr("mu_fl") + 1, vr("mu_fl") + 2, vr("mu_fl") + 3, vr("wind_y")]),
        [0.4, 0.4, 0.4, 0.4, 0.0]
    );
    let c = B::cs();
    assert_eq!(c.set_int(vr("seed"), 7), OK);
    assert_eq!(c.set_real(vr("duration"), 2.0), OK);
    c.init();
    let expect = 0.55 + 0.1 * nigel_benchmark::noise::u(7, 0, 0) - 0.05; // sin(0) = 0 at k = 0
    assert!((c.real(vr("mu_fl")) - expect).abs() < 1e-15, "{} vs {expect}", c.real(vr("mu_fl")));
    assert!((c.real(vr("mu_fl")) - 0.5883310808213643).abs() > 1e-3, "seed 7 is not seed 0");
}

#[test]
fn model_exchange_outputs_change_at_the_events() {
    let b = B::me();
    assert_eq!(b.set_int(vr("maneuver"), maneuver_value(Maneuver::LaneChange)), OK);
    assert_eq!(b.set_real(vr("duration"), 15.0), OK);
    b.init();
    assert_eq!(b.new_discrete_states(), Some(T));
    assert_eq!(b.enter_continuous_time_mode(), OK);
    let mu0 = b.real(vr("mu_fl"));
    assert_eq!(b.set_time(0.7e-3), OK);
    assert_eq!(b.real(vr("mu_fl")), mu0);
    // to the lane change at 14.8 s event by event
    let mut t = T;
    for k in 1..=14_800u32 {
        assert_eq!(b.set_time(t), OK);
        assert_eq!(b.enter_event_mode(), OK);
        let next = b.new_discrete_states().unwrap();
        assert_eq!(b.enter_continuous_time_mode(), OK);
        assert!((next - (k + 1) as f64 * T).abs() < 1e-12);
        t = next;
    }
    assert_eq!(b.real(vr("delta_ff_fl")), PI / 6.0);
}

#[test]
fn fmu_state_round_trip() {
    let b = bench(Maneuver::Fishhook, Fidelity::Real, 3.0);
    assert_eq!(b.step(0.0, 0.5), OK);
    let saved = b.serialized_state();
    let read = |b: &B| b.reals(&[vr("x_ref"), vr("delta_ff_fl"), vr("mu_fl"), vr("beta_meas")]);
    assert_eq!(b.step(0.5, 2.0), OK);
    let first = read(&b);
    assert_eq!(b.restore_serialized(&saved), OK, "{}", b.last_error());
    assert_eq!(b.step(0.5, 2.0), OK);
    assert_eq!(read(&b), first);
}

#[test]
fn bad_input_is_refused_naming_the_variable_and_reset_recovers() {
    let b = B::cs();
    for (name, value) in [("maneuver", 7), ("fidelity", 0), ("seed", -1)] {
        b.assert_refused_then_reset(b.set_int(vr(name), value), name);
    }
    // 1e308 s: longer than the 600 s a reference may cover
    for (name, value) in [("steer_amplitude", f64::NAN), ("speed_target", 0.0), ("duration", -1.0), ("duration", 1e308)] {
        b.assert_refused_then_reset(b.set_real(vr(name), value), name);
    }
    // a step far past the reference is refused, not run
    assert_eq!(b.set_real(vr("duration"), 0.5), OK);
    b.init();
    assert_eq!(b.step(0.0, 1e9), DISCARD);
    assert!(b.last_message().contains("duration"), "{}", b.last_message());
    assert_eq!(b.last_successful_time(), 0.5);
    assert_eq!(b.reset(), OK);
    assert_eq!(b.set_real(vr("duration"), 0.01), OK);
    b.init();
    assert_eq!(b.int(vr("maneuver")), 1);
    assert_eq!(b.step(0.0, 0.01), OK);
}

/// `maneuver` and `fidelity` are plain Integer parameters (libcosim and ecos do not see FMI
/// Enumerations): declared min/max, their values (1-based, unchanged) listed in their
/// descriptions, no type definitions left behind.
#[test]
fn switches_are_integer_parameters_listing_their_values() {
    use fmi_export::model_description::{Causality, VariableType};
    use fmi_export::Model;
    let md = TestBench::declaration().model_description();
    let names = ["straight", "lane_change", "skidpad", "fishhook", "slalom", "figure_8"];
    let cases: [(&str, u32, i32, &[&str]); 2] =
        [("maneuver", vr("maneuver"), 1, &names), ("fidelity", vr("fidelity"), 1, &["paper", "real"])];
    for (name, r, start, items) in cases {
        let v = md.variable(name).unwrap();
        assert_eq!((v.causality, v.value_reference), (Causality::Parameter, r));
        let max = items.len() as i32;
        assert_eq!(
            v.variable_type,
            VariableType::Integer { start: Some(start), min: Some(1), max: Some(max) },
            "{name}"
        );
        let text = v.description.as_deref().unwrap_or("");
        for (k, item) in items.iter().enumerate() {
            assert!(text.contains(&format!("{} {item} (", k + 1)), "{item} = {} missing from {text:?}", k + 1);
        }
        for bad in [0, max + 1] {
            let b = B::cs();
            assert_eq!(b.set_int(r, bad), ERR);
            assert!(b.last_error().contains(name), "{}", b.last_error());
        }
    }
    for (k, m) in Maneuver::ALL.iter().enumerate() {
        assert_eq!((m.name(), maneuver_value(*m)), (names[k], k as i32 + 1));
    }
    assert_eq!((fidelity_value(Fidelity::Paper), fidelity_value(Fidelity::Real)), (1, 2));
    assert!(md.type_definitions.is_empty());
    assert!(!TestBench::declaration().xml().contains("Enumeration"));
}

/// The reference outputs of a Co-Simulation run of the lane change from `start`, 1 ms steps.
fn reference_from(start: f64, steps: usize) -> Vec<[f64; 4]> {
    let b = B::cs();
    assert_eq!(b.set_int(vr("maneuver"), maneuver_value(Maneuver::LaneChange)), OK);
    assert_eq!(b.set_real(vr("duration"), 1.0), OK);
    b.init_at(start);
    (0..steps)
        .map(|n| {
            assert_eq!(b.set_real(vr("beta"), 1e-3 * n as f64), OK);
            let row = [b.real(vr("x_ref")), b.real(vr("psi_ref")), b.real(vr("mu_fl")), b.real(vr("beta_meas"))];
            assert_eq!(b.step(start + n as f64 * T, T), OK, "start {start}: {}", b.last_error());
            row
        })
        .collect()
}

/// At a Unix start time the test bench's samples run at their own instants, not one or
/// three samples early (the tolerance 1e-12 |t| exceeded the period): the outputs at each
/// offset from the start are those of the run from 0, bit for bit.
#[test]
fn large_start_times_give_the_same_reference_bit_for_bit() {
    let at_zero = reference_from(0.0, 800);
    assert!(at_zero[799][0] > at_zero[1][0], "the reference moves");
    for start in [1e6, 1.7e9, 1e12] {
        assert_eq!(reference_from(start, 800), at_zero, "start time {start} s");
    }
}

/// The end of the benchmark, the FMI way. Model Exchange: the event at t = duration (the
/// last sample) reports terminateSimulation and no next event. Co-Simulation: a step
/// across it ends there with fmi2Discard, fmi2Terminated and fmi2LastSuccessfulTime =
/// duration. A stop time past duration is refused when initialization ends, not at
/// fmi2SetupExperiment: an importer (fmpy) sets the start values (a longer duration) after
/// that call.
#[test]
fn the_end_of_the_benchmark_is_announced_the_fmi_way() {
    let me = B::me();
    assert_eq!(me.set_real(vr("duration"), 0.01), OK);
    me.init();
    let mut events = Vec::new();
    let mut t = 0.0;
    loop {
        let (next, terminate) = me.event_iteration();
        events.push((t, next, terminate));
        let Some(next) = next else { break };
        assert!(!terminate);
        assert_eq!(me.enter_continuous_time_mode(), OK);
        assert_eq!(me.set_time(next), OK);
        assert_eq!(me.enter_event_mode(), OK);
        t = next;
    }
    assert_eq!(events.len(), 11, "samples 0 ..= 10: {events:?}");
    assert_eq!(*events.last().unwrap(), (0.01, None, true));

    let cs = B::cs();
    assert_eq!(cs.set_real(vr("duration"), 0.01), OK);
    cs.init();
    assert_eq!(cs.step(0.0, 0.004), OK);
    assert_eq!(cs.step(0.004, 0.004), OK);
    assert!(!cs.terminated());
    assert_eq!(cs.step(0.008, 0.004), DISCARD, "across t = duration");
    assert!(cs.last_message().contains("duration"), "{}", cs.last_message());
    assert!(cs.terminated());
    assert_eq!(cs.last_successful_time(), 0.01);

    let late = B::cs();
    assert_eq!(late.setup_at(0.0, Some(40.0)), OK, "duration may still be set");
    assert_eq!(late.enter_init(), OK);
    assert_eq!(late.exit_init(), ERR, "stopTime 40 s past the default duration of 30 s");
    let e = late.last_error();
    assert!(e.contains("fmi2ExitInitializationMode") && e.contains("stopTime = 40") && e.contains("duration"), "{e}");
    // fmpy's order: fmi2SetupExperiment, the start values, then initialization
    let longer = B::cs();
    assert_eq!(longer.setup_at(0.0, Some(60.0)), OK);
    assert_eq!(longer.set_real(vr("duration"), 600.0), OK);
    assert_eq!(longer.enter_init(), OK);
    assert_eq!(longer.exit_init(), OK, "{}", longer.last_error());
    let shortened = B::cs();
    assert_eq!(shortened.setup_at(0.0, Some(30.0)), OK);
    assert_eq!(shortened.enter_init(), OK);
    assert_eq!(shortened.set_real(vr("duration"), 20.0), OK);
    assert_eq!(shortened.exit_init(), ERR);
    assert!(shortened.last_error().contains("duration"), "{}", shortened.last_error());
}

/// A serialized test-bench state whose next event or sample index disagrees with its
/// time is refused (a next event at 1e300 froze the outputs; sample 20000 at t = 6 ms
/// jumped x_ref to 6.54), naming what disagrees.
#[test]
fn an_inconsistent_test_bench_state_is_refused() {
    let b = bench(Maneuver::LaneChange, Fidelity::Paper, 30.0);
    for n in 0..6 {
        assert_eq!(b.step(n as f64 * T, T), OK);
    }
    let bytes = b.serialized_state();
    let guid = TestBench::declaration().guid().len();
    let at = |i: usize| 8 + 4 + 4 + guid + 8 + 8 * i;
    let g = B::cs();
    assert_eq!(g.restore_serialized(&bytes), OK, "{}", g.last_error());
    assert_eq!(g.real(vr("x_ref")), b.real(vr("x_ref")));
    for (i, value, what) in [(5, 1e300, "next event"), (10, 20_000.0, "sample"), (10, 40_000.0, "last sample")] {
        let mut c = bytes.clone();
        c[at(i)..at(i) + 8].copy_from_slice(&f64::to_le_bytes(value));
        let g = B::cs();
        assert_eq!(g.restore_serialized(&c), ERR, "number {i} = {value}");
        assert!(g.last_error().contains(what), "number {i} = {value}: {}", g.last_error());
    }
}

/// The disturbance settings are parameters starting at the paper's values, and other values
/// change the outputs as docs/benchmark.md's formulas say.
#[test]
fn disturbance_settings_change_the_outputs_as_the_formulas_say() {
    use nigel_benchmark::noise::u;
    let defaults = B::cs();
    assert_eq!(defaults.setup(), OK);
    assert_eq!(defaults.enter_init(), OK);
    let starts = [
        (vr("friction_mean"), 0.55),
        (vr("friction_amplitude"), 0.35),
        (vr("friction_frequency"), 12.0),
        (vr("friction_noise"), 0.1),
        (vr("friction_phase_fl"), 0.0),
        (vr("friction_phase_fl") + 1, PI / 2.0),
        (vr("friction_phase_fl") + 2, PI),
        (vr("friction_phase_fl") + 3, 1.5 * PI),
        (vr("wind_amplitude"), 0.25),
        (vr("wind_noise"), 0.1),
        (vr("wind_direction"), PI / 2.0),
        (vr("wind_start"), 1.0),
        (vr("beta_noise"), 0.005),
        (vr("yaw_rate_noise"), 0.01),
    ];
    for (r, start) in starts {
        assert_eq!(defaults.real(r), start, "value reference {r}");
    }

    let b = B::cs();
    let settings = [
        (vr("friction_mean"), 0.8),
        (vr("friction_amplitude"), 0.1),
        (vr("friction_noise"), 0.02),
        (vr("wind_amplitude"), 0.4),
        (vr("wind_direction"), 0.0),
        (vr("wind_start"), 0.5),
        (vr("beta_noise"), 0.02),
    ];
    for (r, value) in settings {
        assert_eq!(b.set_real(r, value), OK);
    }
    assert_eq!(b.set_int(vr("fidelity"), fidelity_value(Fidelity::Real)), OK);
    assert_eq!(b.set_int(vr("seed"), 3), OK);
    assert_eq!(b.set_real(vr("duration"), 2.0), OK);
    b.init();
    let (mut sum, mut n, mut low, mut high) = (0.0, 0, f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..2_000u32 {
        let t = k as f64 * T;
        let theta = 2.0 * PI * t / 30.0;
        for i in 0..4u32 {
            let mu = b.real(vr("mu_fl") + i);
            let phase = [0.0, PI / 2.0, PI, 1.5 * PI][i as usize];
            let by_hand = 0.1 * (24.0 * PI * theta - phase).sin() + 0.8 + 0.02 * (u(3, i as u8, k as u64) - 0.5);
            // the same formula written as w (u - 1/2) instead of w u - w / 2, and (2 pi 12) theta
            // against 24 pi theta: a few ulp of numbers below 1 (libm's sin within 1 ulp)
            assert!((mu - by_hand).abs() < 1e-14, "k {k} wheel {i}: {mu} vs {by_hand}");
            (sum, n, low, high) = (sum + mu, n + 1, low.min(mu), high.max(mu));
        }
        // direction 0: the whole wind along world X, exactly none along Y
        let force = if k >= 500 { 0.4 } else { 0.0 } + 0.1 * 0.4 * u(3, 4, k as u64);
        assert_eq!((b.real(vr("wind_x")), b.real(vr("wind_y"))), (force, 0.0), "k {k}");
        assert_eq!(b.real(vr("beta_meas")), 0.02 * g(3, 5, k as u64), "beta = 0, k {k}");
        assert_eq!(b.step(t, T), OK);
    }
    // 2 s hold 5.03 periods of the sinusoid (24 pi^2 / 30 s = 7.9 rad/s): the mean is 0.8 to
    // within the partial period (0.1 x 0.03 / 5) and the noise's mean (0.02 x 0.29 / sqrt(8000))
    let mean = sum / n as f64;
    assert!((mean - 0.8).abs() < 0.01, "mean friction {mean}");
    assert!(low >= 0.8 - 0.1 - 0.01 && high <= 0.8 + 0.1 + 0.01, "{low} .. {high}");
    assert!(low < 0.8 - 0.09 && high > 0.8 + 0.09, "the sinusoid's whole swing: {low} .. {high}");
}

/// Settings out of their declared range are refused by the setter, and a combination that
/// would make the friction negative at the end of initialization; both name the variable.
#[test]
fn disturbance_settings_out_of_range_are_refused_naming_the_variable() {
    let b = B::cs();
    assert_eq!(b.set_real(vr("wind_amplitude"), -0.1), ERR);
    assert!(b.last_error().contains("wind_amplitude"), "{}", b.last_error());
    assert_eq!(b.reset(), OK);
    assert_eq!(b.set_real(vr("friction_phase_fl") + 2, f64::NAN), ERR);
    assert!(b.last_error().contains("friction_phase_rl"), "{}", b.last_error());
    assert_eq!(b.reset(), OK);
    // 0.3 - 0.35 - 0.05 < 0: each value in its range, the combination not
    assert_eq!(b.set_real(vr("friction_mean"), 0.3), OK);
    assert_eq!(b.setup(), OK);
    assert_eq!(b.enter_init(), OK);
    assert_eq!(b.exit_init(), ERR);
    assert!(b.last_error().contains("friction_mean"), "{}", b.last_error());
    assert_eq!(b.reset(), OK);
    assert_eq!(b.set_real(vr("friction_mean"), 0.7), OK);
    assert_eq!(b.set_real(vr("friction_amplitude"), 0.25), OK);
    assert_eq!(b.set_real(vr("duration"), 0.1), OK);
    b.init();
    assert_eq!(b.step(0.0, 0.1), OK);
}

/// The value references the layer assigned, pinned: a change shows in review.
#[test]
fn value_references_are_the_pinned_ones() {
    fmi_export::testing::assert_pinned_value_references::<TestBench>(env!("CARGO_MANIFEST_DIR"));
}

/// The test bench through FMI 3.0: every output equal to the FMI 2.0 run to the bit, the
/// step that reaches the duration says terminateSimulation (the run ends there), and a
/// step across it is discarded with terminateSimulation and lastSuccessfulTime at the
/// duration, as FMI 2.0's Discard with fmi2Terminated.
#[test]
fn fmi3_co_simulation_equals_fmi2_and_ends_at_the_duration() {
    use fmi_export::testing::{assert_cs_runs_agree, Fmu3, DISCARD3, OK3};
    let vr3 =
        |name: &str| TestBench::declaration().model_description3().variable_by_name(name).unwrap().value_reference;
    // the default maneuver and fidelity, the first 0.3 s of its 30 s
    let compared = assert_cs_runs_agree::<TestBench>(0.0, 0.01, 30, false, |_, _| None);
    assert!(compared > 300, "{compared}");
    let f = Fmu3::<TestBench>::cs();
    assert_eq!(f.enter_init(0.0, None), OK3);
    assert_eq!(f.set_float64(&[vr3("duration")], &[0.01]), OK3);
    assert_eq!(f.exit_init(), OK3);
    let s = f.step(0.0, 0.004);
    assert!(s.status == OK3 && !s.terminate_simulation);
    let s = f.step(0.004, 0.006);
    assert!(s.status == OK3 && s.terminate_simulation, "the step reaching the duration: {s:?}");
    assert_eq!(s.last_successful_time, 0.01);
    let s = f.step(0.01, 0.004);
    assert_eq!(s.status, DISCARD3, "past the duration");
    assert!(s.terminate_simulation);
    assert_eq!(s.last_successful_time, 0.01);
    assert_eq!(f.terminate(), OK3);

    // the stop time is checked against the duration when initialization ends, after the
    // start values: 60 s with duration 600 s passes, with the default 30 s it does not
    let longer = Fmu3::<TestBench>::cs();
    assert_eq!(longer.enter_init(0.0, Some(60.0)), OK3, "{}", longer.last_error());
    assert_eq!(longer.set_float64(&[vr3("duration")], &[600.0]), OK3);
    assert_eq!(longer.exit_init(), OK3, "{}", longer.last_error());
    let late = Fmu3::<TestBench>::cs();
    assert_eq!(late.enter_init(0.0, Some(60.0)), OK3);
    assert_eq!(late.exit_init(), fmi_export::testing::ERR3);
    let e = late.last_error();
    assert!(e.contains("stopTime = 60") && e.contains("duration"), "{e}");
}

/// An FMI 3.0 instance has no stepFailed state: a serialized FMI 2.0 state taken after a
/// Discarded step is refused by fmi3SetFMUState, naming the state.
#[test]
fn an_fmi3_instance_refuses_an_fmi2_step_failed_state() {
    use fmi_export::testing::{Fmu3, ERR3, OK3};
    let cs = B::cs();
    assert_eq!(cs.set_real(vr("duration"), 0.01), OK);
    cs.init();
    assert_eq!(cs.step(0.0, 0.02), DISCARD, "across t = duration");
    let failed = cs.serialized_state();
    let f = Fmu3::<TestBench>::cs();
    assert_eq!(f.enter_init(0.0, None), OK3);
    assert_eq!(f.exit_init(), OK3);
    assert_eq!(f.restore_serialized(&failed), ERR3);
    let e = f.last_error();
    assert!(e.contains("StepFailed") && e.contains("Fmi3"), "{e}");
}
