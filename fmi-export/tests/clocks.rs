//! FMI 3.0 clocks of the layer on a small clocked model, through the layer's C entry points:
//! the declared clock in the FMI 3.0 description (and none in FMI 2.0's), the samples at the
//! importer's activations in Co-Simulation with Event Mode and in Model Exchange, equal to
//! the FMI 2.0 run's samples to the bit, and every wrong call refused with a message naming
//! the function, the variable and the reason.
//!
//! The model: at each activation t_k = start + k T of its clock `tick` (T = `period`, a
//! fixed parameter, so the clock's interval is `fixed`),
//!   y_k = y_(k-1) + T u(t_k) (y_(-1) = 0),  n_k = k + 1,
//! held between activations; `y` and `n` are the clock's clocked outputs.
#![allow(clippy::missing_safety_doc)]

use fmi_export::abi::fmi3 as abi3;
use fmi_export::fmi_sys::fmi3::*;
use fmi_export::testing::{Fmu, Fmu3, OK};
use fmi_export::*;

#[derive(Clone, Debug, Default)]
struct Summer {
    u: f64,
    period: f64,
    y: f64,
    n: f64,
}

/// The declaration, with or without its clock (the FMI 2.0 side must not differ).
fn spec(clocked: bool) -> DeclarationSpec<Field<Summer>> {
    let mut v = Variables::<Field<Summer>>::new();
    let u = v.real("u").input(0.0).field(|m, _| &mut m.u);
    v.real("period").parameter(0.25).min(1e-3).field(|m, _| &mut m.period);
    let y = v.real("y").discrete_output([u]).describe("y_(k-1) + T u(t_k)").field(|m, _| &mut m.y);
    let n = v.real("n").discrete_output(Dependencies::On(vec![])).describe("k + 1").field(|m, _| &mut m.n);
    DeclarationSpec {
        model_name: "summer",
        model_identifier: "summer",
        description: "y_k = y_(k-1) + T u(t_k) at the activations of its clock",
        version: "1",
        interfaces: Interfaces { model_exchange: true, co_simulation: true },
        capabilities: Capabilities { fmu_state: true, serialize_fmu_state: true, ..Default::default() },
        variables: v.into_vec(),
        clocks: if clocked {
            vec![ClockDecl {
                name: "tick",
                description: "the sample clock",
                interval: ClockInterval::Fixed,
                governs: vec![y, n],
                priority: 0,
            }]
        } else {
            Vec::new()
        },
        ..Default::default()
    }
}

impl Model for Summer {
    type Binding = Field<Summer>;
    declare_model!(Field<Summer>, spec(true));
    fn instantiate(_: &InstantiateContext) -> ModelResult<Self> {
        Ok(Summer::default())
    }
    fn sample_period(&self) -> Option<f64> {
        Some(self.period)
    }
    fn sample(&mut self, k: u64, _time: f64) -> ModelResult {
        // y_(k-1) is the held value (sample k = 0 starts from 0, its start)
        self.y += self.period * self.u;
        self.n = (k + 1) as f64;
        Ok(())
    }
}

/// FMI 3.0 value references: time 0, u 1, period 2, y 3, n 4, the clock tick 5.
mod vr3 {
    pub const U: u32 = 1;
    pub const PERIOD: u32 = 2;
    pub const Y: u32 = 3;
    pub const N: u32 = 4;
    pub const TICK: u32 = 5;
}

fn cs3() -> Fmu3<Summer> {
    Fmu3::<Summer>::try_cs(Summer::declaration().guid(), true).unwrap_or_else(|log| panic!("{:?}", log.0.borrow()))
}

unsafe fn set_clock(f: &Fmu3<Summer>, vr: u32, value: fmi3Clock) -> Fmi3Status {
    abi3::set_clock::<Summer>(Function::Fmi3SetClock, f.c, &vr, 1, &value)
}

fn get_clock(f: &Fmu3<Summer>) -> bool {
    let mut value = 7;
    assert_eq!(unsafe { abi3::get_clock::<Summer>(Function::Fmi3GetClock, f.c, &vr3::TICK, 1, &mut value) }, OK3);
    value == FMI3_CLOCK_ACTIVE
}

fn interval(f: &Fmu3<Summer>) -> (Fmi3Status, f64, fmi3IntervalQualifier) {
    let (mut t, mut q) = (f64::NAN, -1);
    let s = unsafe {
        abi3::get_interval_decimal::<Summer>(Function::Fmi3GetIntervalDecimal, f.c, &vr3::TICK, 1, &mut t, &mut q)
    };
    (s, t, q)
}

fn enter_step_mode(f: &Fmu3<Summer>) -> Fmi3Status {
    unsafe { abi3::enter_step_mode::<Summer>(Function::Fmi3EnterStepMode, f.c) }
}

const OK3: Fmi3Status = Fmi3Status::Ok;
const ERR3: Fmi3Status = Fmi3Status::Error;

/// The input of the runs: u(t) = t (exact in binary at the activations below).
fn input(t: f64) -> f64 {
    t
}

/// One activation at `t` in Event Mode: the input, the clock, the outputs, the update
/// (Co-Simulation: no time event, the activations are the importer's).
fn activate(f: &Fmu3<Summer>, t: f64) -> (f64, f64) {
    let (out, next) = activate_publishing(f, t);
    assert_eq!(next, None, "the activations are the importer's: no time event");
    out
}

/// [`activate`], with the `nextEventTime` the update gives (Model Exchange: the next
/// activation time).
fn activate_publishing(f: &Fmu3<Summer>, t: f64) -> ((f64, f64), Option<f64>) {
    assert_eq!(f.set_float64(&[vr3::U], &[input(t)]), OK3, "{}", f.last_error());
    assert_eq!(unsafe { set_clock(f, vr3::TICK, FMI3_CLOCK_ACTIVE) }, OK3, "{}", f.last_error());
    assert!(get_clock(f));
    let mut out = [0.0; 2];
    assert_eq!(f.get_float64(&[vr3::Y, vr3::N], &mut out), OK3, "{}", f.last_error());
    let update = f.update_discrete_states();
    assert!(!update.terminate_simulation && !update.discrete_states_need_update);
    assert!(!get_clock(f));
    ((out[0], out[1]), update.next_event_time)
}

#[test]
fn the_fmi3_description_declares_the_clock_and_the_fmi2_description_is_unchanged() {
    let d = Summer::declaration();
    let unclocked = Declaration::new(spec(false)).unwrap();
    assert_eq!(d.xml(), unclocked.xml(), "FMI 2.0 has no clocks: the same description");
    let xml3 = d.xml3();
    assert!(
        xml3.contains(
            r#"<Clock name="tick" valueReference="5" description="the sample clock" causality="input" variability="discrete" priority="0" intervalVariability="fixed"/>"#
        ),
        "{xml3}"
    );
    assert!(xml3.contains(r#"name="y" valueReference="3""#) && xml3.contains(r#"clocks="5""#), "{xml3}");
    assert_eq!(xml3.matches(r#"clocks="5""#).count(), 2, "y and n are clocked, u is not: {xml3}");
    assert!(xml3.contains(r#"hasEventMode="true""#), "{xml3}");
    assert!(!unclocked.xml3().contains("hasEventMode") && !unclocked.xml3().contains("<Clock"));
    // the description reads back with the clock, and the earlier value references stand
    let back = model_description::fmi3::ModelDescription::from_xml(xml3).unwrap();
    let tick = back.variable(vr3::TICK).unwrap();
    assert_eq!(tick.clock.as_ref().unwrap().interval_variability.as_deref(), Some("fixed"));
    assert_eq!(d.value_reference_table(), "u 0 1\nperiod 1 2\ny 2 3\nn 3 4\ntick - 5\n");
    assert_eq!(unclocked.value_reference_table(), "u 0 1\nperiod 1 2\ny 2 3\nn 3 4\n");
}

/// Co-Simulation with Event Mode from start 0.5 s with T = 0.25 s: activations at 0.5,
/// 0.75, 1.0 and 1.25 s (t_k = 0.5 + 0.25 k), y_k = 0.25 (0.5 + 0.75 + ... + t_k):
/// 0.125, 0.3125, 0.5625, 0.875 (exact in binary); the FMI 2.0 run of the same model,
/// inputs set at the same instants, reads the same bits.
#[test]
fn co_simulation_samples_at_the_importers_activations_as_fmi2_samples_at_time_events() {
    let f = cs3();
    assert_eq!(f.enter_init(0.5, Some(2.0)), OK3);
    assert_eq!(interval(&f), (OK3, 0.25, FMI3_INTERVAL_CHANGED), "fixed: new to the importer in Initialization Mode");
    assert_eq!(f.exit_init(), OK3, "{}", f.last_error());
    assert_eq!(interval(&f), (OK3, 0.25, FMI3_INTERVAL_UNCHANGED));
    let mut shift = f64::NAN;
    let s = unsafe { abi3::get_shift_decimal::<Summer>(Function::Fmi3GetShiftDecimal, f.c, &vr3::TICK, 1, &mut shift) };
    assert_eq!((s, shift), (OK3, 0.0));
    let expected = [(0.125, 1.0), (0.3125, 2.0), (0.5625, 3.0), (0.875, 4.0)];
    let fmi2 = Fmu::<Summer>::cs();
    fmi2.init_at(0.5);
    // FMI 2.0 value references: u 0, y 2, n 3 (Reals)
    let mut t = 0.5;
    for (k, want) in expected.into_iter().enumerate() {
        // FMI 3.0 starts in Event Mode; later activations enter it from Step Mode
        if k > 0 {
            assert_eq!(f.enter_event_mode(), OK3, "{}", f.last_error());
        }
        let got = activate(&f, t);
        assert_eq!(got, want, "activation {k} at t = {t} s");
        assert_eq!(enter_step_mode(&f), OK3, "{}", f.last_error());
        assert_eq!(fmi2.set_real(0, input(t)), OK);
        assert_eq!((fmi2.real(2).to_bits(), fmi2.real(3)), (got.0.to_bits(), got.1), "FMI 2.0 at t = {t} s");
        // two steps per interval: the first ends between activations
        for h in [0.125, 0.125] {
            assert_eq!(f.step(t, h).status, OK3, "{}", f.last_error());
            assert_eq!(fmi2.step(t, h), OK, "{}", fmi2.last_error());
            t += h;
        }
    }
    assert_eq!(f.float64(vr3::U), 1.25, "a non-clocked variable reads in Step Mode");
    // a clocked output between activations holds the last activation's value
    assert_eq!((f.float64(vr3::Y), f.float64(vr3::N)), expected[3]);
}

/// Co-Simulation instantiated with `eventModeUsed = false` (as fmpy's `simulate_fmu` does):
/// the instance samples by time itself, so the same run as the FMI 2.0 one stepped on the
/// same grid with the same inputs, to the bit: from start 0.5 s with T = 0.25 s, steps of
/// 0.125 s, the samples at 0.5, 0.75, 1.0 and 1.25 s give y = 0.125, 0.3125, 0.5625, 0.875
/// (as the activations above), read at every communication point; the clock is not the
/// importer's (one info message says so), and the Event Mode calls are refused.
#[test]
fn co_simulation_without_event_mode_samples_by_time_as_fmi2() {
    let f = Fmu3::<Summer>::try_cs(Summer::declaration().guid(), false)
        .unwrap_or_else(|log| panic!("refused: {:?}", log.0.borrow()));
    let infos: Vec<String> = f.log.0.borrow().iter().filter(|r| r.0 == 0).map(|r| r.2.clone()).collect();
    assert_eq!(infos.len(), 1, "{infos:?}");
    assert!(
        infos[0].starts_with("fmi3InstantiateCoSimulation: eventModeUsed = false: tick is not driven"),
        "{infos:?}"
    );
    assert_eq!(f.enter_init(0.5, Some(2.0)), OK3);
    assert_eq!(f.exit_init(), OK3, "{}", f.last_error());
    let fmi2 = Fmu::<Summer>::cs();
    fmi2.init_at(0.5);
    let expected = [0.125, 0.125, 0.3125, 0.3125, 0.5625, 0.5625, 0.875, 0.875];
    let mut t = 0.5;
    for (i, want) in expected.into_iter().enumerate() {
        assert_eq!(f.set_float64(&[vr3::U], &[input(t)]), OK3, "{}", f.last_error());
        assert_eq!(fmi2.set_real(0, input(t)), OK);
        let (y3, n3) = (f.float64(vr3::Y), f.float64(vr3::N));
        assert_eq!((y3.to_bits(), n3), (fmi2.real(2).to_bits(), fmi2.real(3)), "FMI 2.0 at t = {t} s");
        assert_eq!((y3, n3), (want, (i / 2 + 1) as f64), "at t = {t} s");
        assert_eq!(f.step(t, 0.125).status, OK3, "{}", f.last_error());
        assert_eq!(fmi2.step(t, 0.125), OK);
        t += 0.125;
    }
    assert_eq!(f.enter_event_mode(), ERR3);
    assert!(
        f.last_error()
            .contains("fmi3EnterEventMode: not available: the instance was created with eventModeUsed = false"),
        "{}",
        f.last_error()
    );
    assert_eq!(enter_step_mode(&f), ERR3);
    assert!(f.last_error().contains("eventModeUsed = false"), "{}", f.last_error());
}

/// Model Exchange: the importer sets the time of each activation, enters Event Mode and
/// activates the clock; the same y_k as above, and each update publishes the next
/// activation t_(k+1) = t_k + 0.25 s as `nextEventTime`.
#[test]
fn model_exchange_samples_at_the_importers_activations() {
    let f = Fmu3::<Summer>::me();
    f.init_until(0.5, None);
    let mut t = 0.5;
    for (k, want) in [(0.125, 1.0), (0.3125, 2.0), (0.5625, 3.0)].into_iter().enumerate() {
        if k > 0 {
            assert_eq!(f.enter_continuous_time_mode(), OK3);
            assert_eq!(f.set_time(t), OK3);
            assert_eq!(f.enter_event_mode(), OK3, "{}", f.last_error());
        }
        assert_eq!(activate_publishing(&f, t), (want, Some(t + 0.25)), "activation {k} at t = {t} s");
        // a second update at the same instant: no activation due, nothing sampled
        let again = f.update_discrete_states();
        assert_eq!((again.next_event_time, f.float64(vr3::Y)), (Some(t + 0.25), want.0), "{}", f.last_error());
        t += 0.25;
    }
    assert!(f.log.0.borrow().iter().all(|r| !r.2.contains("not activated")), "no fallback: {:?}", f.log.0.borrow());
}

/// Model Exchange by an importer that never calls fmi3SetClock (fmpy's Model Exchange): at
/// the initial event (t_0 = 0.5 s) the update finds the activation due and the clock not
/// activated, so the instance samples by its time events as the FMI 2.0 archive: y_k =
/// 0.125, 0.3125, 0.5625, 0.875 at t_k = 0.5 + 0.25 k with u(t_k) = t_k (the values derived
/// above), nextEventTime t_(k+1) after each, to the bit the FMI 2.0 instance driven by the
/// same calls; one info message names the clock; a late fmi3SetClock is an error naming it.
#[test]
fn model_exchange_without_clock_activations_samples_by_time_events_as_fmi2() {
    let f = Fmu3::<Summer>::me();
    let fmi2 = Fmu::<Summer>::me();
    assert_eq!(f.enter_init(0.5, None), OK3);
    assert_eq!(f.set_float64(&[vr3::U], &[input(0.5)]), OK3);
    assert_eq!(f.exit_init(), OK3, "{}", f.last_error());
    assert_eq!(fmi2.setup_at(0.5, None), OK);
    assert_eq!(fmi2.enter_init(), OK);
    assert_eq!(fmi2.set_real(0, input(0.5)), OK);
    assert_eq!(fmi2.exit_init(), OK, "{}", fmi2.last_error());
    let mut t = 0.5;
    for (k, want) in [0.125, 0.3125, 0.5625, 0.875].into_iter().enumerate() {
        if k > 0 {
            assert_eq!(f.enter_continuous_time_mode(), OK3);
            assert_eq!(f.set_time(t), OK3);
            assert_eq!(f.set_float64(&[vr3::U], &[input(t)]), OK3);
            assert_eq!(f.enter_event_mode(), OK3, "{}", f.last_error());
            assert_eq!(fmi2.enter_continuous_time_mode(), OK);
            assert_eq!(fmi2.set_time(t), OK);
            assert_eq!(fmi2.set_real(0, input(t)), OK);
            assert_eq!(fmi2.enter_event_mode(), OK);
        }
        let update = f.update_discrete_states();
        assert!(!update.discrete_states_need_update, "{}", f.last_error());
        assert_eq!(update.next_event_time, Some(t + 0.25), "at t = {t} s: {}", f.last_error());
        let next2 = fmi2.new_discrete_states();
        let (y, n) = (f.float64(vr3::Y), f.float64(vr3::N));
        assert_eq!((y, n), (want, (k + 1) as f64), "sample {k} at t = {t} s");
        assert_eq!((y.to_bits(), n, update.next_event_time), (fmi2.real(2).to_bits(), fmi2.real(3), next2));
        t += 0.25;
    }
    let infos: Vec<String> = f.log.0.borrow().iter().filter(|r| r.0 == 0).map(|r| r.2.clone()).collect();
    let fallback: Vec<&String> = infos.iter().filter(|m| m.contains("not activated")).collect();
    assert_eq!(fallback.len(), 1, "{infos:?}");
    assert!(fallback[0].contains("tick not activated (fmi3SetClock) at its activation time t = 0.5 s"), "{infos:?}");
    assert_eq!(unsafe { set_clock(&f, vr3::TICK, FMI3_CLOCK_ACTIVE) }, ERR3);
    assert!(
        f.last_error().contains("fmi3SetClock: tick activated, but the instance samples by time events"),
        "{}",
        f.last_error()
    );
}

/// An input set after the sample ran while the clock is active undoes it: the sample
/// runs again with the new input (y_0 = T u = 0.25 * 2.0 = 0.5, not 0.25 * 1.0).
#[test]
fn an_input_set_during_the_activation_is_the_samples() {
    let f = cs3();
    f.init_until(0.0, None);
    assert_eq!(f.set_float64(&[vr3::U], &[1.0]), OK3);
    assert_eq!(unsafe { set_clock(&f, vr3::TICK, FMI3_CLOCK_ACTIVE) }, OK3);
    assert_eq!(f.float64(vr3::Y), 0.25);
    assert_eq!(f.set_float64(&[vr3::U], &[2.0]), OK3);
    assert_eq!(f.float64(vr3::Y), 0.5);
    f.update_discrete_states();
    assert_eq!(enter_step_mode(&f), OK3);
    assert_eq!(f.step(0.0, 0.25).status, OK3);
    assert_eq!(f.enter_event_mode(), OK3);
    assert_eq!(activate(&f, 0.25).0, 0.5 + 0.25 * 0.25);
}

/// Every wrong use: an fmi3Error with a message naming the function, the clock or the
/// variable, and the reason.
#[test]
fn wrong_uses_of_the_clock_are_errors_naming_function_variable_and_reason() {
    let f = cs3();
    assert_eq!(f.enter_init(0.0, None), OK3);
    let s = unsafe { set_clock(&f, vr3::TICK, FMI3_CLOCK_ACTIVE) };
    assert_eq!(s, ERR3);
    assert!(f.last_error().starts_with("fmi3SetClock: not allowed in state InitializationMode"), "{}", f.last_error());

    let f = cs3();
    f.init_until(0.0, None);
    assert_eq!(unsafe { set_clock(&f, vr3::U, FMI3_CLOCK_ACTIVE) }, ERR3);
    assert!(f.last_error().contains("value reference 1 is u, a Float64 variable, not a clock"), "{}", f.last_error());

    let f = cs3();
    f.init_until(0.0, None);
    assert_eq!(unsafe { set_clock(&f, vr3::TICK, 2) }, ERR3);
    assert!(f.last_error().contains("neither fmi3ClockActive (1) nor fmi3ClockInactive (0)"));

    let f = cs3();
    f.init_until(0.0, None);
    assert_eq!(unsafe { set_clock(&f, vr3::TICK, FMI3_CLOCK_ACTIVE) }, OK3);
    assert_eq!(unsafe { set_clock(&f, vr3::TICK, FMI3_CLOCK_INACTIVE) }, ERR3);
    assert!(f.last_error().contains("tick cannot be deactivated (canBeDeactivated is false)"));

    let f = cs3();
    f.init_until(0.0, None);
    assert_eq!(unsafe { set_clock(&f, vr3::TICK, FMI3_CLOCK_ACTIVE) }, OK3);
    assert_eq!(enter_step_mode(&f), ERR3);
    assert!(f.last_error().contains("tick is still active"), "{}", f.last_error());

    // a step past the activation at 0 s (not made), then past the one at 0.25 s
    let f = cs3();
    f.init_until(0.0, None);
    assert_eq!(enter_step_mode(&f), OK3);
    assert_eq!(f.step(0.0, 0.1).status, ERR3);
    assert!(f.last_error().contains("passes activation 0 of tick at t = 0 s"), "{}", f.last_error());
    let f = cs3();
    f.init_until(0.0, None);
    activate(&f, 0.0);
    assert_eq!(enter_step_mode(&f), OK3);
    assert_eq!(f.step(0.0, 0.2).status, OK3);
    assert_eq!(f.step(0.2, 0.1).status, ERR3);
    assert!(f.last_error().contains("from 0.2 s to 0.30000000000000004 s passes activation 1 of tick at t = 0.25 s"));

    // an activation at another time than the next
    let f = cs3();
    f.init_until(0.0, None);
    activate(&f, 0.0);
    assert_eq!(enter_step_mode(&f), OK3);
    assert_eq!(f.step(0.0, 0.125).status, OK3);
    assert_eq!(f.enter_event_mode(), OK3);
    assert_eq!(unsafe { set_clock(&f, vr3::TICK, FMI3_CLOCK_ACTIVE) }, ERR3);
    assert!(
        f.last_error().contains("tick activated at t = 0.125 s, but its next activation is at t = 0.25 s"),
        "{}",
        f.last_error()
    );

    // the timing is the FMU's; no fractions
    let f = cs3();
    assert_eq!(f.enter_init(0.0, None), OK3);
    let s = unsafe { abi3::clock_timing::<Summer>(Function::Fmi3SetIntervalDecimal, f.c, &vr3::TICK, 1) };
    assert_eq!(s, ERR3);
    assert!(f.last_error().starts_with("fmi3SetIntervalDecimal: the interval and shift of tick are the FMU's"));
    let f = cs3();
    assert_eq!(f.enter_init(0.0, None), OK3);
    let s = unsafe { abi3::clock_fraction::<Summer>(Function::Fmi3GetIntervalFraction, f.c, &vr3::TICK, 1) };
    assert_eq!(s, ERR3);
    assert!(f.last_error().contains("supportsFraction = false"), "{}", f.last_error());
    // the period is read when asked: a bad one is refused naming the clock
    let f = cs3();
    assert_eq!(f.set_float64(&[vr3::PERIOD], &[0.5]), OK3);
    assert_eq!(f.enter_init(0.0, None), OK3);
    assert_eq!(interval(&f), (OK3, 0.5, FMI3_INTERVAL_CHANGED));
}

/// `fmi3InstantiateScheduledExecution` of the model (no callbacks the FMU would call).
fn se3() -> (fmi3Instance, Box<fmi_export::testing::Log>) {
    let log = Box::<fmi_export::testing::Log>::default();
    let name = std::ffi::CString::new("se").unwrap();
    let token = std::ffi::CString::new(Summer::declaration().guid()).unwrap();
    let env = &*log as *const fmi_export::testing::Log as *mut std::ffi::c_void;
    let c = unsafe {
        abi3::instantiate_scheduled_execution::<Summer>(
            Function::Fmi3InstantiateScheduledExecution,
            name.as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            FMI3_FALSE,
            FMI3_TRUE,
            env,
            Some(fmi_export::testing::log_message),
            None,
            None,
            None,
        )
    };
    assert!(!c.is_null(), "{:?}", log.0.borrow());
    (c, log)
}

fn last_error(log: &fmi_export::testing::Log) -> String {
    log.0.borrow().iter().rev().find(|r| r.0 >= 3).map(|r| r.2.clone()).unwrap_or_default()
}

/// Scheduled Execution: the clock's model partition activated at 0.5, 0.75 and 1.0 s (T
/// = 0.25 s from start 0.5 s) gives the y_k of the other interfaces; the description
/// offers it with the clock's priority; wrong activations are errors.
#[test]
fn scheduled_execution_activates_the_clocks_partition() {
    assert!(Summer::declaration().xml3().contains("<ScheduledExecution"), "{}", Summer::declaration().xml3());
    let (c, log) = se3();
    let s = unsafe {
        abi3::enter_initialization_mode::<Summer>(Function::Fmi3EnterInitializationMode, c, 0, 0.0, 0.5, 0, 0.0)
    };
    assert_eq!(s, OK3);
    let (mut t, mut q) = (f64::NAN, -1);
    let s = unsafe {
        abi3::get_interval_decimal::<Summer>(Function::Fmi3GetIntervalDecimal, c, &vr3::TICK, 1, &mut t, &mut q)
    };
    assert_eq!((s, t, q), (OK3, 0.25, FMI3_INTERVAL_CHANGED));
    assert_eq!(
        unsafe {
            abi3::status3(fmi_export::abi::exit_initialization_mode::<Summer>(Function::Fmi3ExitInitializationMode, c))
        },
        OK3
    );
    let activate = |t: f64| unsafe {
        abi3::activate_model_partition::<Summer>(Function::Fmi3ActivateModelPartition, c, vr3::TICK, t)
    };
    let get = |vrs: &[u32]| {
        let mut out = vec![0.0; vrs.len()];
        let s = unsafe {
            abi3::get::<Summer, abi3::value::Float64>(
                Function::Fmi3GetFloat64,
                c,
                vrs.as_ptr(),
                vrs.len(),
                out.as_mut_ptr(),
                out.len(),
            )
        };
        assert_eq!(s, OK3, "{}", last_error(&log));
        out
    };
    for (k, want) in [(0.125, 1.0), (0.3125, 2.0), (0.5625, 3.0)].into_iter().enumerate() {
        let t = 0.5 + 0.25 * k as f64;
        let s = unsafe { abi3::set::<Summer, abi3::value::Float64>(Function::Fmi3SetFloat64, c, &vr3::U, 1, &t, 1) };
        assert_eq!(s, OK3);
        assert_eq!(activate(t), OK3, "{}", last_error(&log));
        assert_eq!(get(&[vr3::Y, vr3::N, 0]), [want.0, want.1, t], "activation {k}");
    }
    // the next activation is at 1.25 s
    assert_eq!(activate(1.2), ERR3);
    assert!(
        last_error(&log).starts_with(
            "fmi3ActivateModelPartition: activationTime = 1.2 s for tick, but its next activation is at t = 1.25 s"
        ),
        "{}",
        last_error(&log)
    );
    unsafe { fmi_export::abi::free_instance::<Summer>(Function::Fmi3FreeInstance, c) };
    let (c, log) = se3();
    unsafe {
        abi3::enter_initialization_mode::<Summer>(Function::Fmi3EnterInitializationMode, c, 0, 0.0, 0.0, 0, 0.0);
        fmi_export::abi::exit_initialization_mode::<Summer>(Function::Fmi3ExitInitializationMode, c);
    }
    let on = FMI3_CLOCK_ACTIVE;
    assert_eq!(unsafe { abi3::set_clock::<Summer>(Function::Fmi3SetClock, c, &vr3::TICK, 1, &on) }, ERR3);
    assert!(last_error(&log).contains("not available in Scheduled Execution"), "{}", last_error(&log));
    let (mut e, mut te, mut er, mut last) = (0, 0, 0, 0.0);
    let s =
        unsafe { abi3::do_step::<Summer>(Function::Fmi3DoStep, c, 0.0, 0.1, 0, &mut e, &mut te, &mut er, &mut last) };
    assert_eq!(s, ERR3);
    assert!(last_error(&log).contains("created for ScheduledExecution"), "{}", last_error(&log));
    unsafe { fmi_export::abi::free_instance::<Summer>(Function::Fmi3FreeInstance, c) };
}

/// A serialized FMU state of a clocked instance (in Step Mode between activations) restores
/// its sample count: the activations after it give the same y_k again.
#[test]
fn a_clocked_instance_restores_its_serialized_state() {
    let f = cs3();
    f.init_until(0.0, None);
    activate(&f, 0.0);
    assert_eq!(enter_step_mode(&f), OK3);
    assert_eq!(f.step(0.0, 0.25).status, OK3);
    let bytes = f.serialized_state();
    let run = |f: &Fmu3<Summer>| {
        assert_eq!(f.enter_event_mode(), OK3, "{}", f.last_error());
        let y = activate(f, 0.25);
        assert_eq!(enter_step_mode(f), OK3);
        y
    };
    // y_1 = 0.25 (0 + 0.25) = 0.0625, n_1 = 2
    assert_eq!(run(&f), (0.0625, 2.0));
    assert_eq!(f.restore_serialized(&bytes), OK3, "{}", f.last_error());
    assert_eq!(run(&f), (0.0625, 2.0));
}
