//! Every layer feature on a small sampled toy model, through the layer's C entry points
//! (`fmi_export::abi`, what `export_fmi!` exports): Integer/Boolean/Enumeration,
//! tunable and fixed parameters, time events in Model Exchange and inside `fmi2DoStep`,
//! event iteration, the default FMU state from the declaration, opt-in capabilities,
//! Warning/Discard, bad input, stopTime, and the FMU states an instance owns.
//!
//! The toy: a sampled integrator with feed-through, zero continuous states. At every
//! sample t_k = k T (T = `sample_period`):
//!   y_k = gain u(t_k) + acc_k + offset (when `enabled`),  acc_{k+1} = acc_k + T u(t_k),
//! held between samples; `samples` counts the samples; mode `settle` asks for one extra
//! event iteration per sample (counted in `iterations`).
#![allow(clippy::missing_safety_doc)]

use std::cell::RefCell;
use std::ffi::{c_char, c_int, CString};
use std::ptr::null_mut;

use fmi_export::abi::{self, Fmi2EventInfo};
use fmi_export::ffi::*;
use fmi_export::model_description::{Causality, Variability, VariableType};
use fmi_export::testing::{self, ERR, OK};
use fmi_export::*;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum V {
    U,
    Gain,
    Period,
    Mode,
    Offset,
    Enabled,
    Acc,
    Y,
    Samples,
    Iterations,
}

const SUM: i32 = 1;
const SETTLE: i32 = 2;
const STOP_AT_3: i32 = 3;

thread_local! {
    /// Live toy models of this thread (every test runs on its own thread).
    static LIVE: RefCell<i64> = const { RefCell::new(0) };
    /// Copies of toy models made on this thread.
    static CLONES: RefCell<i64> = const { RefCell::new(0) };
}

fn clones() -> i64 {
    CLONES.with(|l| *l.borrow())
}

fn live() -> i64 {
    LIVE.with(|l| *l.borrow())
}

#[derive(Debug)]
struct Toy {
    logger: Logger,
    u: f64,
    gain: f64,
    period: f64,
    mode: i32,
    offset: i32,
    enabled: bool,
    acc: f64,
    y: f64,
    samples: i32,
    iterations: i32,
    /// internal (not a declared variable): the index of the next sample
    k: u64,
    settling: bool,
}

impl Clone for Toy {
    fn clone(&self) -> Self {
        LIVE.with(|l| *l.borrow_mut() += 1);
        CLONES.with(|l| *l.borrow_mut() += 1);
        Toy { logger: self.logger.clone(), ..*self }
    }
}

impl Drop for Toy {
    fn drop(&mut self) {
        LIVE.with(|l| *l.borrow_mut() -= 1);
    }
}

fn spec(capabilities: Capabilities, interfaces: Interfaces, identifier: &'static str) -> DeclarationSpec<V> {
    DeclarationSpec {
        model_name: "toy",
        model_identifier: identifier,
        description: "sampled toy",
        version: "1",
        interfaces,
        capabilities,
        enumerations: vec![enumeration_type(
            "Mode",
            "what a sample does",
            &[
                ("sum", SUM, "one iteration"),
                ("settle", SETTLE, "two iterations"),
                ("stop_at_3", STOP_AT_3, "asks to end the simulation at the third sample"),
            ],
        )],
        units: vec![si_unit("s", 0, 0, 1, 0)],
        variables: vec![
            VarDecl::real("u", 0, V::U).input(Start::Real(0.0)),
            VarDecl::real("gain", 1, V::Gain).tunable_parameter(Start::Real(2.0)).min(0.0),
            VarDecl::real("sample_period", 2, V::Period).parameter(Start::Real(0.1)).min(1e-6).unit("s"),
            VarDecl::enumeration("mode", 0, "Mode", V::Mode).parameter(Start::Integer(SUM)),
            VarDecl::integer("offset", 1, V::Offset).parameter(Start::Integer(0)).min(-100.0).max(100.0),
            VarDecl::boolean("enabled", 0, V::Enabled).parameter(Start::Boolean(true)),
            VarDecl::real("acc", 3, V::Acc).discrete_state(Start::Real(0.0)),
            VarDecl::real("y", 4, V::Y).discrete_output(Dependencies::On(vec![0])),
            VarDecl::integer("samples", 2, V::Samples).discrete_output(Dependencies::On(vec![])),
            VarDecl::integer("iterations", 3, V::Iterations).discrete_output(Dependencies::On(vec![])),
        ],
        ..Default::default()
    }
}

/// The toy dispatches on its own binding.
impl fmi_export::Access<Toy> for V {}

impl Model for Toy {
    type Binding = V;

    declare_model!(V, {
        let caps = Capabilities { fmu_state: true, serialize_fmu_state: true, directional_derivatives: false };
        let both = Interfaces { model_exchange: true, co_simulation: true };
        spec(caps, both, "toy")
    });

    fn instantiate(context: &InstantiateContext) -> ModelResult<Self> {
        LIVE.with(|l| *l.borrow_mut() += 1);
        Ok(Toy {
            logger: context.logger.clone(),
            u: 0.0,
            gain: 0.0,
            period: 0.0,
            mode: 0,
            offset: 0,
            enabled: false,
            acc: 0.0,
            y: 0.0,
            samples: 0,
            iterations: 0,
            k: 0,
            settling: false,
        })
    }

    fn get_real(&mut self, b: V) -> ModelResult<f64> {
        Ok(match b {
            V::U => self.u,
            V::Gain => self.gain,
            V::Period => self.period,
            V::Acc => self.acc,
            V::Y => self.y,
            _ => return Err("not a Real".into()),
        })
    }

    fn set_real(&mut self, b: V, x: f64) -> ModelResult {
        match b {
            // refusals of the model itself (the layer's checks pass these values)
            V::Gain if x == 13.0 => {
                return Err(ModelError::Discard("gain = 13 refused: the toy is superstitious".into()))
            }
            V::Acc if x > 1e9 => return Err(format!("acc = {x} refused: beyond the toy's accumulator").into()),
            V::U => self.u = x,
            V::Gain => self.gain = x,
            V::Period => self.period = x,
            V::Acc => self.acc = x,
            V::Y => self.y = x,
            _ => return Err("not a Real".into()),
        }
        Ok(())
    }

    /// The input has no check of its own (gain and acc have).
    fn setter_may_refuse(b: V) -> bool {
        b != V::U
    }

    fn get_integer(&mut self, b: V) -> ModelResult<i32> {
        Ok(match b {
            V::Mode => self.mode,
            V::Offset => self.offset,
            V::Samples => self.samples,
            V::Iterations => self.iterations,
            _ => return Err("not an Integer".into()),
        })
    }

    fn set_integer(&mut self, b: V, x: i32) -> ModelResult {
        match b {
            V::Mode => self.mode = x,
            V::Offset => self.offset = x,
            V::Samples => self.samples = x,
            V::Iterations => self.iterations = x,
            _ => return Err("not an Integer".into()),
        }
        Ok(())
    }

    fn get_boolean(&mut self, b: V) -> ModelResult<bool> {
        match b {
            V::Enabled => Ok(self.enabled),
            _ => Err("not a Boolean".into()),
        }
    }

    fn set_boolean(&mut self, b: V, x: bool) -> ModelResult {
        match b {
            V::Enabled => self.enabled = x,
            _ => return Err("not a Boolean".into()),
        }
        Ok(())
    }

    fn event_update(&mut self, _time: f64) -> ModelResult<EventUpdate> {
        self.iterations += 1;
        if self.settling {
            self.settling = false;
            return Ok(EventUpdate::next_at((self.k as f64) * self.period));
        }
        if self.u > 100.0 {
            self.logger.warning(&format!("u = {} is beyond the toy's calibrated range", self.u));
        }
        if self.mode == STOP_AT_3 && self.samples == 2 {
            return Ok(EventUpdate { terminate_simulation: true, ..Default::default() });
        }
        let y = if self.enabled { self.gain * self.u + self.acc + self.offset as f64 } else { 0.0 };
        if y.abs() > 1e6 {
            return Err(ModelError::Discard(format!("y = {y} would saturate the toy")));
        }
        self.y = y;
        self.acc += self.period * self.u;
        self.samples += 1;
        self.k += 1;
        if self.mode == SETTLE {
            self.settling = true;
            return Ok(EventUpdate {
                new_discrete_states_needed: true,
                ..EventUpdate::next_at(self.k as f64 * self.period)
            });
        }
        Ok(EventUpdate::next_at(self.k as f64 * self.period))
    }

    fn save_internal(&self, out: &mut Vec<f64>) {
        out.push(self.k as f64);
        out.push(self.settling as u8 as f64);
    }

    fn load_internal(&mut self, data: &[f64]) -> ModelResult {
        let [k, settling] = data else { return Err("toy internal data: 2 numbers expected".into()) };
        if !(*k >= 0.0 && k.fract() == 0.0 && *k < 1e15) || !(*settling == 0.0 || *settling == 1.0) {
            return Err(format!("toy internal data {data:?} refused").into());
        }
        self.k = *k as u64;
        self.settling = *settling == 1.0;
        Ok(())
    }
}

/// The Model methods of a newtype `$wrapper` around the toy that are the toy's own:
/// instantiate, the typed gets and sets, event_update.
macro_rules! toy_methods {
    ($wrapper:ident) => {
        fn instantiate(context: &InstantiateContext) -> ModelResult<Self> {
            Toy::instantiate(context).map($wrapper)
        }
        fn event_update(&mut self, t: f64) -> ModelResult<EventUpdate> {
            self.0.event_update(t)
        }
        toy_methods!(@typed get_real set_real f64, get_integer set_integer i32, get_boolean set_boolean bool);
    };
    (@typed $($get:ident $set:ident $value:ty),*) => {
        $(
            fn $get(&mut self, b: V) -> ModelResult<$value> {
                self.0.$get(b)
            }
            fn $set(&mut self, b: V, x: $value) -> ModelResult {
                self.0.$set(b, x)
            }
        )*
    };
}

/// The same toy with no optional capability and Co-Simulation only.
#[derive(Clone, Debug)]
struct Bare(Toy);

/// The toy dispatches on its own binding.
impl fmi_export::Access<Bare> for V {}

impl Model for Bare {
    type Binding = V;
    declare_model!(V, {
        let cs = Interfaces { model_exchange: false, co_simulation: true };
        spec(Capabilities::default(), cs, "bare")
    });
    toy_methods!(Bare);
}

/// The toy with its own FMU-state format (the override): only its internal numbers.
#[derive(Clone, Debug)]
struct Own(Toy);

/// The toy dispatches on its own binding.
impl fmi_export::Access<Own> for V {}

impl Model for Own {
    type Binding = V;
    const SAVE_DECLARED_VARIABLES: bool = false;
    declare_model!(V, {
        let caps = Capabilities { fmu_state: true, serialize_fmu_state: true, directional_derivatives: false };
        let cs = Interfaces { model_exchange: false, co_simulation: true };
        spec(caps, cs, "own")
    });
    toy_methods!(Own);
    fn save_internal(&self, out: &mut Vec<f64>) {
        let t = &self.0;
        out.extend([t.u, t.gain, t.period, t.acc, t.y, t.samples as f64, t.k as f64]);
    }
    fn load_internal(&mut self, data: &[f64]) -> ModelResult {
        let [u, gain, period, acc, y, samples, k] = data else { return Err("7 numbers expected".into()) };
        let t = &mut self.0;
        (t.u, t.gain, t.period, t.acc, t.y, t.samples, t.k) =
            (*u, *gain, *period, *acc, *y, *samples as i32, *k as u64);
        Ok(())
    }
}

// The macro must expand for a model with Integer/Boolean/Enumeration and defaults only.
export_fmi!(Toy);

// ------------------------------------------------------------------ the importer

/// The layer's in-process importer (`fmi_export::testing`) with the toy tests'
/// conventions: `last_error` is the last message at Discard or worse, `init` takes the
/// stop time.
struct Fmu<M: Model>(testing::Fmu<M>);

impl<M: Model> std::ops::Deref for Fmu<M> {
    type Target = testing::Fmu<M>;
    fn deref(&self) -> &testing::Fmu<M> {
        &self.0
    }
}

impl<M: Model> Fmu<M> {
    fn cs() -> Self {
        Fmu(testing::Fmu::cs())
    }
    fn me() -> Self {
        Fmu(testing::Fmu::me())
    }
    fn last_error(&self) -> String {
        self.0.last_message()
    }
    fn init(&self, stop: Option<f64>) {
        self.0.init_until(0.0, stop)
    }
}

mod vr {
    pub const U: u32 = 0;
    pub const GAIN: u32 = 1;
    pub const PERIOD: u32 = 2;
    pub const ACC: u32 = 3;
    pub const Y: u32 = 4;
    pub const MODE: u32 = 0;
    pub const OFFSET: u32 = 1;
    pub const SAMPLES: u32 = 2;
    pub const ITERATIONS: u32 = 3;
    pub const ENABLED: u32 = 0;
}

// ------------------------------------------------------------------ tests

#[test]
fn description_has_enumerations_tunables_discrete_outputs_and_the_declared_capabilities() {
    let md = Toy::declaration().model_description();
    let xml = Toy::declaration().xml();
    assert_eq!(md.type_definitions[0].name, "Mode");
    assert_eq!(md.type_definitions[0].items.len(), 3);
    assert!(xml.contains(r#"<Item name="settle" value="2" description="two iterations"/>"#), "{xml}");
    let var = |n: &str| md.model_variables.iter().find(|v| v.name == n).unwrap();
    assert!(
        matches!(&var("mode").variable_type, VariableType::Enumeration { declared_type, start: Some(1), .. } if declared_type == "Mode")
    );
    assert_eq!(var("gain").variability, Variability::Tunable);
    assert_eq!(var("sample_period").variability, Variability::Fixed);
    assert_eq!((var("y").causality, var("y").variability), (Causality::Output, Variability::Discrete));
    // y depends on u directly (feed-through at a sample): index of u is 1
    assert_eq!(md.model_structure.outputs[0].dependencies, Some(vec![1]));
    let cs = md.co_simulation.as_ref().unwrap();
    assert!(cs.can_get_and_set_fmu_state && cs.can_serialize_fmu_state && !cs.provides_directional_derivative);
    assert!(!xml.contains("providesDirectionalDerivative"));
    assert!(md.validate().is_empty());

    let bare = Bare::declaration().model_description();
    assert!(bare.model_exchange.is_none());
    let xml = Bare::declaration().xml();
    for flag in ["canGetAndSetFMUstate", "canSerializeFMUstate", "providesDirectionalDerivative"] {
        assert!(!xml.contains(flag), "{flag} in {xml}");
    }
    // the saved rows are the parameters, the input and the discrete variables
    let saved: Vec<&str> = Toy::declaration().saved_rows.iter().map(|&r| Toy::declaration().variable(r).name).collect();
    assert_eq!(saved, ["u", "gain", "sample_period", "mode", "offset", "enabled", "acc", "y", "samples", "iterations"]);
}

/// y_k and acc after samples with inputs `u[k]` (independent of the layer).
fn expected(gain: f64, period: f64, u: &[f64]) -> (f64, f64) {
    let mut acc = 0.0;
    let mut y = 0.0;
    for &uk in u {
        y = gain * uk + acc;
        acc += period * uk;
    }
    (y, acc)
}

#[test]
fn co_simulation_runs_the_samples_inside_do_step_with_the_inputs_of_their_instant() {
    let f = Fmu::<Toy>::cs();
    f.init(None);
    assert_eq!(f.set_real(vr::U, 1.0), OK);
    // one step over three samples: t = 0, 0.1, 0.2 run inside, 0.3 is later
    assert_eq!(f.step(0.0, 0.25), OK);
    assert_eq!(f.int(vr::SAMPLES), 3);
    let (y, acc) = expected(2.0, 0.1, &[1.0, 1.0, 1.0]);
    assert_eq!(f.real(vr::Y), y);
    assert_eq!(f.real(vr::ACC), acc);
    // a step ending on the sample at 0.3: that sample waits for the inputs of t = 0.3
    assert_eq!(f.step(0.25, 0.05), OK);
    assert_eq!(f.set_real(vr::U, 2.0), OK);
    assert_eq!(f.real(vr::Y), expected(2.0, 0.1, &[1.0, 1.0, 1.0, 2.0]).0, "sample at 0.3 sees u(0.3) = 2");
    assert_eq!(f.int(vr::SAMPLES), 4);
    // the master corrects the input at the same instant (an algebraic-loop iteration):
    // the sample is redone, not run twice
    assert_eq!(f.set_real(vr::U, 3.0), OK);
    assert_eq!(f.real(vr::Y), expected(2.0, 0.1, &[1.0, 1.0, 1.0, 3.0]).0);
    assert_eq!(f.int(vr::SAMPLES), 4);
    // a tunable gain set at the same instant counts for that instant's sample too
    assert_eq!(f.set_real(vr::GAIN, 5.0), OK);
    let acc3 = 0.1 * (1.0 + 1.0 + 1.0);
    assert_eq!(f.step(0.3, 0.05), OK);
    assert_eq!(f.real(vr::Y), 5.0 * 3.0 + acc3);
    assert_eq!(f.int(vr::SAMPLES), 4);
    // held until the next sample, whatever the input does meanwhile
    assert_eq!(f.set_real(vr::U, -1.0), OK);
    assert_eq!(f.real(vr::Y), 5.0 * 3.0 + acc3);
    assert_eq!(f.step(0.35, 0.1), OK);
    assert_eq!(f.int(vr::SAMPLES), 5);
    let acc4 = acc3 + 0.1 * 3.0;
    assert_eq!(f.real(vr::Y), -5.0 + acc4, "gain 5 times u(0.4) = -1");
}

#[test]
fn model_exchange_reports_the_next_time_event_and_iterates() {
    let f = Fmu::<Toy>::me();
    unsafe {
        assert_eq!(abi::setup_experiment::<Toy>(Function::SetupExperiment, f.c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK);
        assert_eq!(f.set_int(vr::MODE, SETTLE), OK);
        assert_eq!(abi::exit_initialization_mode::<Toy>(Function::ExitInitializationMode, f.c), OK);
        assert_eq!(f.set_real(vr::U, 1.0), OK);
        let mut info = Fmi2EventInfo {
            new_discrete_states_needed: 0,
            terminate_simulation: 0,
            nominals_of_continuous_states_changed: 0,
            values_of_continuous_states_changed: 0,
            next_event_time_defined: 0,
            next_event_time: 0.0,
        };
        let mut t = 0.0;
        for k in 1..=3 {
            // the event iteration: settle asks once for another round
            assert_eq!(abi::new_discrete_states::<Toy>(Function::NewDiscreteStates, f.c, &mut info), OK);
            assert_eq!(info.new_discrete_states_needed, FMI2_TRUE);
            assert_eq!(abi::new_discrete_states::<Toy>(Function::NewDiscreteStates, f.c, &mut info), OK);
            assert_eq!(info.new_discrete_states_needed, FMI2_FALSE);
            assert_eq!(info.next_event_time_defined, FMI2_TRUE);
            assert_eq!(info.next_event_time, k as f64 * 0.1);
            assert_eq!(f.int(vr::SAMPLES), k);
            assert_eq!(f.int(vr::ITERATIONS), 2 * k);
            // zero continuous states: nx = 0 everywhere
            assert_eq!(abi::enter_continuous_time_mode::<Toy>(Function::EnterContinuousTimeMode, f.c), OK);
            assert_eq!(abi::get_derivatives::<Toy>(Function::GetDerivatives, f.c, null_mut(), 0), OK);
            assert_eq!(abi::set_continuous_states::<Toy>(Function::SetContinuousStates, f.c, std::ptr::null(), 0), OK);
            // integrating up to just before the event changes nothing
            assert_eq!(abi::set_time::<Toy>(Function::SetTime, f.c, info.next_event_time - 1e-3), OK);
            let (mut enter, mut term) = (7, 7);
            assert_eq!(
                abi::completed_integrator_step::<Toy>(Function::CompletedIntegratorStep, f.c, 1, &mut enter, &mut term),
                OK
            );
            assert_eq!((enter, term), (FMI2_FALSE, FMI2_FALSE));
            assert_eq!(f.int(vr::SAMPLES), k);
            t = info.next_event_time;
            assert_eq!(abi::set_time::<Toy>(Function::SetTime, f.c, t), OK);
            assert_eq!(abi::enter_event_mode::<Toy>(Function::EnterEventMode, f.c), OK);
        }
        assert_eq!(t, 0.30000000000000004);
        // a Co-Simulation call on a Model Exchange instance
        assert_eq!(f.step(t, 0.1), ERR);
        assert!(
            f.last_error().contains("fmi2DoStep") && f.last_error().contains("ModelExchange"),
            "{}",
            f.last_error()
        );
    }
    // the same model in Co-Simulation runs both iterations per sample inside the step
    let g = Fmu::<Toy>::cs();
    unsafe {
        assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, g.c), OK);
        assert_eq!(g.set_int(vr::MODE, SETTLE), OK);
        assert_eq!(abi::exit_initialization_mode::<Toy>(Function::ExitInitializationMode, g.c), OK);
    }
    assert_eq!(g.set_real(vr::U, 1.0), OK);
    assert_eq!(g.step(0.0, 0.25), OK);
    assert_eq!((g.int(vr::SAMPLES), g.int(vr::ITERATIONS)), (3, 6));
}

#[test]
fn tunable_parameters_change_between_steps_fixed_ones_are_refused_naming_the_variable() {
    let f = Fmu::<Toy>::cs();
    f.init(None);
    assert_eq!(f.set_real(vr::GAIN, 3.0), OK);
    assert_eq!(f.set_real(vr::PERIOD, 0.2), ERR);
    let e = f.last_error();
    assert!(e.contains("fmi2SetReal") && e.contains("sample_period") && e.contains("fixed"), "{e}");
    assert_eq!(f.reset(), OK);
    // after reset the start values are back and everything works again
    unsafe { assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK) };
    assert_eq!(f.real(vr::GAIN), 2.0);
    // values cannot be read before initialization (FMI 2.0 state table)
    assert_eq!(f.reset(), OK);
    let (g, mut x) = (vr::GAIN, 0.0);
    assert_eq!(unsafe { abi::get::<Toy, abi::value::Real>(Function::GetReal, f.c, &g, 1, &mut x) }, ERR);
}

#[test]
fn bad_values_are_refused_naming_the_variable_and_reset_recovers() {
    let f = Fmu::<Toy>::cs();
    type Setter = Box<dyn Fn(&Fmu<Toy>) -> Fmi2Status>;
    let cases: [(&str, Setter); 5] = [
        ("mode", Box::new(|f| f.set_int(vr::MODE, 7))),
        ("gain", Box::new(|f| f.set_real(vr::GAIN, -1.0))),
        ("u", Box::new(|f| f.set_real(vr::U, f64::NAN))),
        ("offset", Box::new(|f| f.set_int(vr::OFFSET, 101))),
        ("sample_period", Box::new(|f| f.set_real(vr::PERIOD, f64::INFINITY))),
    ];
    for (name, bad) in cases {
        unsafe { assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK) };
        assert_eq!(bad(&f), ERR, "{name}");
        let e = f.last_error();
        assert!(e.contains(name) && e.contains("refused"), "{name}: {e}");
        // the error state: the next step is refused, reset brings it back
        assert_eq!(f.step(0.0, 0.1), ERR);
        assert_eq!(f.reset(), OK);
        f.init(None);
        assert_eq!(f.set_real(vr::U, 1.0), OK);
        assert_eq!(f.step(0.0, 0.05), OK);
        assert_eq!(f.real(vr::Y), 2.0);
        assert_eq!(f.reset(), OK);
    }
    // an enumeration out of range in a serialized state file is refused the same way
}

unsafe fn serialize<M: Model>(c: fmi2Component, s: fmi2FMUstate) -> Vec<u8> {
    let mut size = 0;
    assert_eq!(abi::serialized_fmu_state_size::<M>(Function::SerializedFMUstateSize, c, s, &mut size), OK);
    let mut bytes = vec![0u8; size];
    assert_eq!(
        abi::serialize_fmu_state::<M>(Function::SerializeFMUstate, c, s, bytes.as_mut_ptr() as *mut c_char, size),
        OK
    );
    bytes
}

#[test]
fn fmu_state_from_the_declaration_round_trips_bit_exactly_and_refuses_hostile_bytes() {
    let f = Fmu::<Toy>::cs();
    f.init(None);
    assert_eq!(f.set_real(vr::U, 0.3), OK);
    assert_eq!(f.set_real(vr::GAIN, 1.7), OK);
    assert_eq!(f.step(0.0, 0.25), OK);
    let mut state: fmi2FMUstate = null_mut();
    let bytes = unsafe {
        assert_eq!(abi::get_fmu_state::<Toy>(Function::GetFMUstate, f.c, &mut state), OK);
        serialize::<Toy>(f.c, state)
    };
    let run = |f: &Fmu<Toy>| -> Vec<u64> {
        let mut out = Vec::new();
        let mut t = 0.25;
        for k in 0..7 {
            assert_eq!(f.set_real(vr::U, 0.1 * k as f64 - 0.2), OK);
            assert_eq!(f.step(t, 0.07), OK);
            t += 0.07;
            out.extend([f.real(vr::Y), f.real(vr::ACC)].map(f64::to_bits));
            out.push(f.int(vr::SAMPLES) as u64);
        }
        out
    };
    let first = run(&f);
    // restore the in-memory state, and a deserialized copy in a second instance
    unsafe { assert_eq!(abi::set_fmu_state::<Toy>(Function::SetFMUstate, f.c, state), OK) };
    assert_eq!(run(&f), first);
    let g = Fmu::<Toy>::cs();
    let mut copy: fmi2FMUstate = null_mut();
    unsafe {
        assert_eq!(de_serialize(&g, &bytes, &mut copy), OK, "{}", g.last_error());
        assert_eq!(abi::set_fmu_state::<Toy>(Function::SetFMUstate, g.c, copy), OK);
    }
    assert_eq!(run(&g), first, "the sample counter (internal data) travels too");

    // hostile bytes: each one a single number changed, each refused with the reason
    let numbers_at = bytes.len() - 8 * (7 + 10 + 2);
    let patch = |index: usize, x: f64| {
        let mut b = bytes.clone();
        b[numbers_at + 8 * index..numbers_at + 8 * index + 8].copy_from_slice(&x.to_le_bytes());
        b
    };
    let cases = [
        (patch(7 + 1, -1.0), "gain"),
        (patch(7 + 3, 9.0), "mode"),
        (patch(7 + 5, 2.0), "enabled"),
        (patch(7 + 4, 0.5), "offset"),
        (patch(7 + 6, f64::NAN), "acc"),
        (patch(7 + 10, -3.0), "internal"),
        (patch(1, f64::INFINITY), "time"),
        (bytes[..bytes.len() - 1].to_vec(), "length"),
    ];
    for (bad, what) in cases {
        let mut s: fmi2FMUstate = null_mut();
        assert_eq!(unsafe { de_serialize(&g, &bad, &mut s) }, ERR, "{what}");
        assert!(s.is_null());
        assert!(g.last_error().contains("fmi2DeSerializeFMUstate"), "{}", g.last_error());
        assert_eq!(g.reset(), OK);
    }
    unsafe {
        assert_eq!(abi::free_fmu_state::<Toy>(Function::FreeFMUstate, f.c, &mut state), OK);
        assert!(state.is_null());
    }
}

unsafe fn de_serialize(f: &Fmu<Toy>, bytes: &[u8], s: &mut fmi2FMUstate) -> Fmi2Status {
    abi::deserialize_fmu_state::<Toy>(
        Function::DeSerializeFMUstate,
        f.c,
        bytes.as_ptr() as *const c_char,
        bytes.len(),
        s,
    )
}

#[test]
fn fmu_states_belong_to_their_instance_and_are_freed_with_it() {
    let before = live();
    {
        let f = Fmu::<Toy>::cs();
        let g = Fmu::<Toy>::cs();
        f.init(None);
        let mut states = [null_mut(); 3];
        for s in &mut states {
            unsafe { assert_eq!(abi::get_fmu_state::<Toy>(Function::GetFMUstate, f.c, s), OK) };
        }
        // a state of another instance, a freed one, a made-up pointer: refused, not used
        let mut foreign: fmi2FMUstate = null_mut();
        unsafe {
            assert_eq!(abi::set_fmu_state::<Toy>(Function::SetFMUstate, g.c, states[0]), ERR);
            assert!(g.last_error().contains("not made by this instance"), "{}", g.last_error());
            assert_eq!(abi::free_fmu_state::<Toy>(Function::FreeFMUstate, f.c, &mut states[2]), OK);
            let freed = states[1];
            assert_eq!(abi::free_fmu_state::<Toy>(Function::FreeFMUstate, f.c, &mut states[1]), OK);
            assert_eq!(f.reset(), OK);
            assert_eq!(abi::set_fmu_state::<Toy>(Function::SetFMUstate, f.c, freed), ERR);
            let mut made_up = 0x1234usize as fmi2FMUstate;
            assert_eq!(f.reset(), OK);
            assert_eq!(abi::free_fmu_state::<Toy>(Function::FreeFMUstate, f.c, &mut made_up), ERR);
            assert_eq!(abi::get_fmu_state::<Toy>(Function::GetFMUstate, g.c, &mut foreign), OK);
        }
        // f still owns states[0], g owns `foreign`: freeing the instances frees them
        assert!(live() > before + 2);
    }
    assert_eq!(live(), before, "every model clone (instances and FMU states) was dropped");
}

#[test]
fn capabilities_not_declared_are_refused_as_not_supported() {
    let f = Fmu::<Bare>::cs();
    f.init(None);
    let mut s: fmi2FMUstate = null_mut();
    unsafe {
        assert_eq!(abi::get_fmu_state::<Bare>(Function::GetFMUstate, f.c, &mut s), ERR);
        assert!(f.last_error().contains("fmi2GetFMUstate: not supported"), "{}", f.last_error());
        assert_eq!(f.reset(), OK);
    }
    // Model Exchange is not offered: instantiation fails with the reason
    let log = testing::Log::environment();
    let callbacks = log.callbacks();
    let guid = CString::new(Bare::declaration().guid()).unwrap();
    let c = unsafe {
        abi::instantiate::<Bare>(Function::Instantiate, c"x".as_ptr(), 0, guid.as_ptr(), null_mut(), &callbacks, 0, 0)
    };
    assert!(c.is_null());
    assert!(log.0.borrow()[0].2.contains("does not offer ModelExchange"));
    // the toy has FMU state but not directional derivatives
    let t = Fmu::<Toy>::cs();
    t.init(None);
    let (vy, vu, dv) = (vr::Y, vr::U, 1.0);
    let mut out = 0.0;
    unsafe {
        assert_eq!(
            abi::get_directional_derivative::<Toy>(
                Function::GetDirectionalDerivative,
                t.c,
                &vy,
                1,
                &vu,
                1,
                &dv,
                &mut out
            ),
            ERR
        );
    }
    assert!(t.last_error().contains("fmi2GetDirectionalDerivative: not supported"), "{}", t.last_error());
}

#[test]
fn warning_and_discard_and_step_failed() {
    let f = Fmu::<Toy>::cs();
    f.init(None);
    let mut saved: fmi2FMUstate = null_mut();
    unsafe { assert_eq!(abi::get_fmu_state::<Toy>(Function::GetFMUstate, f.c, &mut saved), OK) };
    assert_eq!(f.set_real(vr::U, 200.0), OK);
    assert_eq!(f.step(0.0, 0.05), Fmi2Status::Warning);
    assert!(f.log.0.borrow().iter().any(|r| r.0 == 1 && r.1 == "logStatusWarning" && r.2.contains("u = 200")));
    assert_eq!(f.step(0.05, 0.1), Fmi2Status::Warning);
    // a sample that cannot be computed: Discard, stepFailed, the last good time
    assert_eq!(f.set_real(vr::U, 1e7), OK);
    assert_eq!(f.step(0.15, 0.1), Fmi2Status::Discard);
    assert!(f.last_error().contains("fmi2DoStep: y = "), "{}", f.last_error());
    let (mut t, mut status) = (f64::NAN, -1);
    unsafe {
        assert_eq!(abi::get_real_status::<Toy>(Function::GetRealStatus, f.c, FMI2_LAST_SUCCESSFUL_TIME, &mut t), OK);
        assert_eq!(abi::get_status::<Toy>(Function::GetStatus, f.c, FMI2_DO_STEP_STATUS, &mut status), OK);
    }
    assert_eq!(t, 0.15 + 0.05, "the sample at 0.2 failed");
    assert_eq!(status, Fmi2Status::Discard as c_int);
    assert_eq!(f.real(vr::Y), 2.0 * 200.0 + 0.1 * 200.0, "outputs of the last good sample (0.1)");
    // stepFailed: the saved state continues (as the standard says)
    unsafe { assert_eq!(abi::set_fmu_state::<Toy>(Function::SetFMUstate, f.c, saved), OK) };
    assert_eq!(f.set_real(vr::U, 1.0), OK);
    assert_eq!(f.step(0.0, 0.1), OK);
    assert_eq!(f.real(vr::Y), 2.0 + 0.1, "the sample at the step's end, t = 0.1, with u(0.1)");
    // and stepFailed refuses steps and sets
    assert_eq!(f.set_real(vr::U, 1e7), OK);
    assert_eq!(f.step(0.1, 0.1), Fmi2Status::Discard);
    assert_eq!(f.set_real(vr::U, 1.0), ERR, "no set in stepFailed");
    assert!(f.last_error().contains("not allowed in state StepFailed"), "{}", f.last_error());
    assert_eq!(f.reset(), OK);
    f.init(None);
    assert_eq!(f.step(0.0, 0.1), OK);
}

#[test]
fn stop_time_is_enforced_and_setup_refuses_non_finite_numbers() {
    let f = Fmu::<Toy>::cs();
    f.init(Some(0.3));
    assert_eq!(f.step(0.0, 0.2), OK);
    assert_eq!(f.step(0.2, 0.1), OK);
    assert_eq!(f.step(0.3, 0.1), ERR);
    assert!(f.last_error().contains("stopTime 0.3"), "{}", f.last_error());
    for (tol, start, stop) in
        [(f64::NAN, 0.0, 1.0), (1e-6, f64::INFINITY, 1.0), (1e-6, 0.0, f64::NAN), (1e-6, 1.0, 0.5)]
    {
        assert_eq!(f.reset(), OK);
        assert_eq!(
            unsafe { abi::setup_experiment::<Toy>(Function::SetupExperiment, f.c, 1, tol, start, 1, stop) },
            ERR,
            "{tol} {start} {stop}"
        );
    }
    let g = Fmu::<Toy>::me();
    unsafe {
        assert_eq!(abi::setup_experiment::<Toy>(Function::SetupExperiment, g.c, 0, 0.0, 0.0, 1, 1.0), OK);
        assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, g.c), OK);
        assert_eq!(
            abi::set_time::<Toy>(Function::SetTime, g.c, 0.5),
            ERR,
            "SetTime is not allowed in Initialization Mode"
        );
        assert_eq!(g.reset(), OK);
        g.init(Some(1.0));
        // Model Exchange: integrators evaluate past the output time; a warning, not an error
        assert_eq!(abi::set_time::<Toy>(Function::SetTime, g.c, 1.5), Fmi2Status::Warning);
        assert!(g.log.0.borrow().iter().any(|r| r.0 == 1 && r.2.contains("after the stopTime 1")));
    }
}

#[test]
fn booleans_and_integers_read_back_and_enabled_switch_acts() {
    let f = Fmu::<Toy>::cs();
    unsafe {
        assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK);
        let (b, off) = (FMI2_FALSE, 5);
        assert_eq!(abi::set::<Toy, abi::value::Boolean>(Function::SetBoolean, f.c, &vr::ENABLED, 1, &b), OK);
        assert_eq!(f.set_int(vr::OFFSET, off), OK);
        let mut back = 9;
        assert_eq!(abi::get::<Toy, abi::value::Boolean>(Function::GetBoolean, f.c, &vr::ENABLED, 1, &mut back), OK);
        assert_eq!(back, FMI2_FALSE);
        assert_eq!(f.int(vr::OFFSET), 5);
        assert_eq!(abi::exit_initialization_mode::<Toy>(Function::ExitInitializationMode, f.c), OK);
    }
    assert_eq!(f.set_real(vr::U, 1.0), OK);
    assert_eq!(f.step(0.0, 0.1), OK);
    assert_eq!(f.real(vr::Y), 0.0, "disabled");
    // a fixed Boolean after initialization: refused
    let t = FMI2_TRUE;
    assert_eq!(unsafe { abi::set::<Toy, abi::value::Boolean>(Function::SetBoolean, f.c, &vr::ENABLED, 1, &t) }, ERR);
    assert!(f.last_error().contains("enabled"), "{}", f.last_error());
}

#[test]
fn a_model_can_override_the_fmu_state_format() {
    let f = Fmu::<Own>::cs();
    f.init(None);
    assert_eq!(f.set_real(vr::U, 1.5), OK);
    assert_eq!(f.step(0.0, 0.25), OK);
    let mut s: fmi2FMUstate = null_mut();
    let bytes = unsafe {
        assert_eq!(abi::get_fmu_state::<Own>(Function::GetFMUstate, f.c, &mut s), OK);
        let mut size = 0;
        assert_eq!(abi::serialized_fmu_state_size::<Own>(Function::SerializedFMUstateSize, f.c, s, &mut size), OK);
        let mut b = vec![0u8; size];
        assert_eq!(
            abi::serialize_fmu_state::<Own>(Function::SerializeFMUstate, f.c, s, b.as_mut_ptr() as *mut c_char, size),
            OK
        );
        b
    };
    // the layer's 12 numbers (the sample clock among them) and the model's own 7, no declared variables
    let guid = Own::declaration().guid().len();
    assert_eq!(bytes.len(), 8 + 4 + 4 + guid + 8 + 8 * (12 + 7));
    let g = Fmu::<Own>::cs();
    assert_eq!(g.restore_serialized(&bytes), OK, "{}", g.last_error());
    assert_eq!(g.step(0.25, 0.1), OK);
    assert_eq!(f.step(0.25, 0.1), OK);
    assert_eq!(g.real(vr::Y).to_bits(), f.real(vr::Y).to_bits());
    assert_eq!(g.int(vr::SAMPLES), 4);
}

#[test]
fn a_model_can_ask_to_end_the_simulation() {
    // Co-Simulation: the step is discarded and fmi2Terminated reports it
    let f = Fmu::<Toy>::cs();
    unsafe {
        assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK);
        assert_eq!(f.set_int(vr::MODE, STOP_AT_3), OK);
        assert_eq!(abi::exit_initialization_mode::<Toy>(Function::ExitInitializationMode, f.c), OK);
    }
    let mut terminated = -1;
    assert_eq!(f.step(0.0, 0.15), OK);
    unsafe {
        assert_eq!(
            abi::get_boolean_status::<Toy>(Function::GetBooleanStatus, f.c, FMI2_TERMINATED, &mut terminated),
            OK
        )
    };
    assert_eq!(terminated, FMI2_FALSE);
    assert_eq!(f.step(0.15, 0.1), Fmi2Status::Discard);
    assert!(f.last_error().contains("asked to terminate"), "{}", f.last_error());
    unsafe {
        assert_eq!(
            abi::get_boolean_status::<Toy>(Function::GetBooleanStatus, f.c, FMI2_TERMINATED, &mut terminated),
            OK
        )
    };
    assert_eq!(terminated, FMI2_TRUE);
    unsafe { assert_eq!(abi::terminate::<Toy>(Function::Terminate, f.c), OK) };
    // Model Exchange: fmi2NewDiscreteStates says terminateSimulation
    let g = Fmu::<Toy>::me();
    let mut info = Fmi2EventInfo {
        new_discrete_states_needed: 0,
        terminate_simulation: 0,
        nominals_of_continuous_states_changed: 0,
        values_of_continuous_states_changed: 0,
        next_event_time_defined: 0,
        next_event_time: 0.0,
    };
    unsafe {
        assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, g.c), OK);
        assert_eq!(g.set_int(vr::MODE, STOP_AT_3), OK);
        assert_eq!(abi::exit_initialization_mode::<Toy>(Function::ExitInitializationMode, g.c), OK);
        for k in 0..3 {
            assert_eq!(abi::new_discrete_states::<Toy>(Function::NewDiscreteStates, g.c, &mut info), OK);
            assert_eq!(info.terminate_simulation, (k == 2) as c_int, "sample {k}");
            if k < 2 {
                assert_eq!(abi::enter_continuous_time_mode::<Toy>(Function::EnterContinuousTimeMode, g.c), OK);
                assert_eq!(abi::set_time::<Toy>(Function::SetTime, g.c, info.next_event_time), OK);
                assert_eq!(abi::enter_event_mode::<Toy>(Function::EnterEventMode, g.c), OK);
            }
        }
        assert_eq!(abi::terminate::<Toy>(Function::Terminate, g.c), OK);
    }
}

/// `fmi2SetReal` is all or nothing without copying the model: a batch whose 3rd value the
/// model refuses leaves the first two unchanged (Discard: the instance goes on; Error: the
/// values read in the error state are the earlier ones), also when the call is longer
/// than the layer's undo buffer (then it copies the model once).
#[test]
fn a_value_the_model_refuses_rolls_back_the_earlier_values_of_the_same_call() {
    let f = Fmu::<Toy>::cs();
    unsafe { assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK) };
    let set = |vrs: &[u32], xs: &[f64]| unsafe {
        abi::set::<Toy, abi::value::Real>(Function::SetReal, f.c, vrs.as_ptr(), vrs.len(), xs.as_ptr())
    };
    assert_eq!(set(&[vr::U, vr::ACC], &[0.5, 0.25]), OK);
    let before = (f.real(vr::U), f.real(vr::ACC), f.real(vr::GAIN));
    assert_eq!(before, (0.5, 0.25, 2.0));
    let copies = clones();
    assert_eq!(set(&[vr::U, vr::ACC, vr::GAIN], &[5.0, 7.0, 13.0]), Fmi2Status::Discard);
    assert_eq!(clones(), copies, "no copy of the model for a short call");
    let e = f.last_error();
    assert!(e.contains("fmi2SetReal") && e.contains("gain") && e.contains("superstitious"), "{e}");
    assert_eq!((f.real(vr::U), f.real(vr::ACC), f.real(vr::GAIN)), before);
    // the same variables several times, longer than the undo buffer: back to the values before
    let mut vrs: Vec<u32> = (0..39).map(|k| if k % 2 == 0 { vr::U } else { vr::ACC }).collect();
    let mut xs: Vec<f64> = (0..39).map(|k| k as f64 + 10.0).collect();
    vrs.push(vr::GAIN);
    xs.push(13.0);
    assert_eq!(set(&vrs, &xs), Fmi2Status::Discard);
    assert_eq!(clones(), copies + 1, "one copy, at the 33rd value");
    assert_eq!((f.real(vr::U), f.real(vr::ACC), f.real(vr::GAIN)), before);
    // a call of inputs only (which the model never refuses) keeps nothing and applies
    assert_eq!(set(&[vr::U, vr::U], &[0.75, 0.5]), OK);
    assert_eq!(clones(), copies + 1);
    // the instance goes on as if the refused calls never happened
    unsafe { assert_eq!(abi::exit_initialization_mode::<Toy>(Function::ExitInitializationMode, f.c), OK) };
    assert_eq!(set(&[vr::U, vr::GAIN], &[1.0, 3.0]), OK);
    assert_eq!(f.step(0.0, 0.05), OK);
    assert_eq!(f.real(vr::Y), 3.0 + 0.25); // gain 3 u 1 + acc 0.25
                                           // an Error refusal: the error state, whose diagnostic reads show the earlier values
    let g = Fmu::<Toy>::cs();
    unsafe { assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, g.c), OK) };
    let (vrs, xs) = ([vr::U, vr::GAIN, vr::ACC], [9.0, 4.0, 2e9]);
    assert_eq!(unsafe { abi::set::<Toy, abi::value::Real>(Function::SetReal, g.c, vrs.as_ptr(), 3, xs.as_ptr()) }, ERR);
    let e = g.last_error();
    assert!(e.contains("acc") && e.contains("beyond the toy's accumulator"), "{e}");
    assert_eq!((g.real(vr::U), g.real(vr::GAIN), g.real(vr::ACC)), (0.0, 2.0, 0.0));
    assert_eq!(g.step(0.0, 0.05), ERR);
}

/// The layer keeps the lookups of the last `fmi2GetReal`/`fmi2SetReal` arrays (a master
/// sends the same ones every step): every check still runs on every value of a repeated
/// array, in the instance's current state.
#[test]
fn repeated_value_reference_arrays_are_checked_every_time() {
    let f = Fmu::<Toy>::cs();
    unsafe { assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK) };
    let set = |vrs: &[u32], xs: &[f64]| unsafe {
        abi::set::<Toy, abi::value::Real>(Function::SetReal, f.c, vrs.as_ptr(), vrs.len(), xs.as_ptr())
    };
    let get = |vrs: &[u32]| {
        let mut out = vec![f64::NAN; vrs.len()];
        let s = unsafe {
            abi::get::<Toy, abi::value::Real>(Function::GetReal, f.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        };
        (s, out)
    };
    let vrs = [vr::U, vr::PERIOD, vr::GAIN];
    assert_eq!(set(&vrs, &[1.0, 0.1, 3.0]), OK);
    assert_eq!(set(&vrs, &[2.0, 0.1, 4.0]), OK);
    assert_eq!(get(&vrs), (OK, vec![2.0, 0.1, 4.0]));
    assert_eq!(get(&vrs), (OK, vec![2.0, 0.1, 4.0]));
    // out of bounds the second time round: refused naming the variable, nothing applied
    assert_eq!(set(&vrs, &[3.0, 0.1, -1.0]), ERR);
    assert!(f.last_error().contains("gain = -1 refused: below its minimum 0"), "{}", f.last_error());
    assert_eq!(get(&vrs), (OK, vec![2.0, 0.1, 4.0]));
    assert_eq!(f.reset(), OK);
    unsafe { assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK) };
    assert_eq!(set(&vrs, &[1.0, 0.1, 3.0]), OK);
    unsafe { assert_eq!(abi::exit_initialization_mode::<Toy>(Function::ExitInitializationMode, f.c), OK) };
    // the same array after initialization: the fixed parameter is refused now
    assert_eq!(set(&vrs, &[1.0, 0.1, 3.0]), ERR);
    assert!(f.last_error().contains("sample_period cannot be set after initialization"), "{}", f.last_error());
    assert_eq!(f.reset(), OK);
    unsafe { assert_eq!(abi::enter_initialization_mode::<Toy>(Function::EnterInitializationMode, f.c), OK) };
    // a known array then one with an unknown value reference at the end
    assert_eq!(get(&[vr::U, vr::GAIN]).0, OK);
    assert_eq!(get(&[vr::U, 99]).0, ERR);
    assert!(f.last_error().contains("unknown Real value reference 99"), "{}", f.last_error());
}

// ------------------------------------------------------------------ FMI 3.0

use fmi_export::testing::{Fmu3, DISCARD3, ERR3, OK3};

/// FMI 3.0 value references of the toy: `time` 0, declaration row r at r + 1.
mod vr3 {
    pub const TIME: u32 = 0;
    pub const U: u32 = 1;
    pub const GAIN: u32 = 2;
    pub const MODE: u32 = 4;
    pub const OFFSET: u32 = 5;
    pub const ENABLED: u32 = 6;
    pub const ACC: u32 = 7;
    pub const Y: u32 = 8;
    pub const SAMPLES: u32 = 9;
}

#[test]
fn fmi3_description_has_the_same_variables_typed_and_validates_in_its_structure() {
    use fmi_export::model_description::fmi3::ValueType;
    let d = Toy::declaration();
    let md3 = d.model_description3();
    let types: Vec<(&str, u32, ValueType)> =
        md3.model_variables.iter().map(|v| (v.name.as_str(), v.value_reference, v.value_type)).collect();
    assert_eq!(types[vr3::MODE as usize], ("mode", 4, ValueType::Enumeration));
    assert_eq!(types[vr3::OFFSET as usize], ("offset", 5, ValueType::Int32));
    assert_eq!(types[vr3::ENABLED as usize], ("enabled", 6, ValueType::Boolean));
    assert_eq!(types[vr3::Y as usize], ("y", 8, ValueType::Float64));
    assert_eq!(md3.instantiation_token, d.guid());
    let xml = d.xml3();
    assert!(xml.contains(r#"<EnumerationType name="Mode" description="what a sample does">"#), "{xml}");
    assert!(xml.contains(r#"<Output valueReference="8" dependencies="1"/>"#), "{xml}");
    let cs = md3.co_simulation.as_ref().unwrap();
    assert!(cs.common.can_get_and_set_fmu_state && !cs.common.provides_adjoint_derivatives && !cs.has_event_mode);
}

/// The same run through both ABIs: every output equal to the bit, the step's FMI 3.0
/// outputs as the standard says for an FMU without Event Mode and early return.
#[test]
fn fmi3_co_simulation_equals_the_fmi2_run_bit_for_bit() {
    let f2 = Fmu::<Toy>::cs();
    f2.init(Some(1.0));
    let f3 = Fmu3::<Toy>::cs();
    f3.init_until(0.0, Some(1.0));
    let (mut t, h) = (0.0, 0.03);
    for k in 0..30 {
        let u = (k as f64 * 0.7).sin();
        assert_eq!(f2.set_real(vr::U, u), OK);
        assert_eq!(f3.set_float64(&[vr3::U], &[u]), OK3);
        assert_eq!(f2.step(t, h), OK);
        let s = f3.step(t, h);
        assert_eq!(s.status, OK3, "{}", f3.last_error());
        assert!(!s.event_handling_needed && !s.early_return && !s.terminate_simulation);
        t += h;
        assert_eq!(s.last_successful_time.to_bits(), t.to_bits());
        assert_eq!(f3.float64(vr3::TIME).to_bits(), t.to_bits());
        assert_eq!(f2.real(vr::Y).to_bits(), f3.float64(vr3::Y).to_bits());
        assert_eq!(f2.real(vr::ACC).to_bits(), f3.float64(vr3::ACC).to_bits());
        assert_eq!(f2.int(vr::SAMPLES), f3.int32(vr3::SAMPLES));
    }
    assert_eq!(f3.terminate(), OK3);
}

#[test]
fn fmi3_model_exchange_updates_discrete_states_at_the_time_events() {
    let f = Fmu3::<Toy>::me();
    f.init_until(0.0, None);
    assert_eq!(f.set_float64(&[vr3::U], &[1.0]), OK3);
    let first = f.update_discrete_states();
    assert_eq!(first.next_event_time, Some(0.1));
    assert!(!first.discrete_states_need_update && !first.terminate_simulation);
    assert_eq!(f.int32(vr3::SAMPLES), 1);
    assert_eq!(f.enter_continuous_time_mode(), OK3);
    assert!(f.continuous_states().is_empty() && f.derivatives().is_empty());
    assert_eq!(f.set_time(0.1), OK3);
    assert_eq!(f.enter_event_mode(), OK3);
    assert_eq!(f.update_discrete_states().next_event_time, Some(0.2));
    assert_eq!(f.float64(vr3::Y), expected(2.0, 0.1, &[1.0, 1.0]).0);
    let mut n = 7usize;
    unsafe {
        assert_eq!(
            abi::fmi3::get_number_of_continuous_states::<Toy>(Function::Fmi3GetNumberOfContinuousStates, f.c, &mut n),
            OK3
        );
        assert_eq!(n, 0);
        assert_eq!(
            abi::fmi3::get_number_of_event_indicators::<Toy>(Function::Fmi3GetNumberOfEventIndicators, f.c, &mut n),
            OK3
        );
        assert_eq!(n, 0);
    }
}

#[test]
fn fmi3_values_of_the_wrong_type_count_or_range_are_refused_naming_the_reason() {
    // each refusal puts the instance in the error state: a fresh one in Initialization Mode
    let fresh = || {
        let f = Fmu3::<Toy>::cs();
        assert_eq!(f.enter_init(0.0, None), OK3);
        f
    };
    let mut f = fresh();
    // Int32 of a Float64, Float64 of an Enumeration, a type the toy has none of
    let mut i = [0i32];
    assert_eq!(
        unsafe {
            abi::fmi3::get::<Toy, abi::fmi3::value::Int32>(Function::Fmi3GetInt32, f.c, &vr3::U, 1, i.as_mut_ptr(), 1)
        },
        ERR3
    );
    assert!(f.last_error().contains("value reference 1 is u, a Float64 variable, not a Int32"), "{}", f.last_error());
    f = fresh();
    let mut x = [0.0];
    assert_eq!(f.get_float64(&[vr3::MODE], &mut x), ERR3);
    assert!(f.last_error().contains("mode, a Enumeration variable, not a Float64"), "{}", f.last_error());
    f = fresh();
    let mut g = [0.0f32];
    assert_eq!(
        unsafe {
            abi::fmi3::get::<Toy, abi::fmi3::value::Float32>(
                Function::Fmi3GetFloat32,
                f.c,
                &vr3::U,
                1,
                g.as_mut_ptr(),
                1,
            )
        },
        ERR3
    );
    assert!(f.last_error().starts_with("fmi3GetFloat32:") && f.last_error().contains("not a Float32"));
    f = fresh();
    let mut active = 0;
    assert_eq!(
        unsafe { abi::fmi3::get_clock::<Toy>(Function::Fmi3GetClock, f.c, &vr3::ENABLED, 1, &mut active) },
        ERR3
    );
    // the FMU declares no Clock: fmi3GetClock is refused as a feature it lacks
    assert!(f.last_error().contains("not supported: no clocks are declared"), "{}", f.last_error());
    f = fresh();
    // an empty call of such a type is fine
    assert_eq!(
        unsafe {
            abi::fmi3::get::<Toy, abi::fmi3::value::Float32>(
                Function::Fmi3GetFloat32,
                f.c,
                std::ptr::null(),
                0,
                std::ptr::null_mut(),
                0,
            )
        },
        OK3
    );
    // unknown value reference, bad nValues
    assert_eq!(f.set_float64(&[99], &[1.0]), ERR3);
    assert!(f.last_error().contains("unknown value reference 99"), "{}", f.last_error());
    f = fresh();
    assert_eq!(f.set_float64(&[vr3::U, vr3::GAIN], &[1.0]), ERR3);
    assert!(f.last_error().contains("nValues = 1") && f.last_error().contains("nValues must be 2"));
    f = fresh();
    // NaN, below the minimum, not an enumeration item, outside 32 bits
    assert_eq!(f.set_float64(&[vr3::GAIN], &[f64::NAN]), ERR3);
    assert!(f.last_error().contains("gain = NaN refused"), "{}", f.last_error());
    f = fresh();
    assert_eq!(f.set_float64(&[vr3::GAIN], &[-1.0]), ERR3);
    assert!(f.last_error().contains("below its minimum"), "{}", f.last_error());
    f = fresh();
    assert_eq!(f.set_int64(vr3::MODE, 7), ERR3);
    assert!(f.last_error().contains("not an item of Mode"), "{}", f.last_error());
    f = fresh();
    assert_eq!(f.set_int64(vr3::MODE, 1 << 40), ERR3);
    assert!(f.last_error().contains("outside the 32-bit range"), "{}", f.last_error());
    f = fresh();
    // time is read, never set
    assert_eq!(f.set_float64(&[vr3::TIME], &[1.0]), ERR3);
    assert!(f.last_error().contains("independent variable"), "{}", f.last_error());
    f = fresh();
    // the good values go through: Int64 enumerations, Int32, Boolean
    assert_eq!(f.set_int64(vr3::MODE, SETTLE as i64), OK3);
    assert_eq!(f.set_int32(vr3::OFFSET, -3), OK3);
    assert_eq!(f.set_boolean(vr3::ENABLED, false), OK3);
    assert_eq!(f.exit_init(), OK3);
    assert_eq!((f.int64(vr3::MODE), f.int32(vr3::OFFSET), f.boolean(vr3::ENABLED)), (SETTLE as i64, -3, false));
}

#[test]
fn fmi3_instantiation_checks_the_token_event_mode_and_interface() {
    let log = Fmu3::<Toy>::try_cs("{00000000-0000-0000-0000-000000000000}", false).err().unwrap();
    let msg = log.0.borrow().last().unwrap().2.clone();
    assert!(msg.starts_with("fmi3InstantiateCoSimulation: instantiationToken"), "{msg}");
    let log = Fmu3::<Toy>::try_cs(Toy::declaration().guid(), true).err().unwrap();
    assert!(log.0.borrow().last().unwrap().2.contains("eventModeUsed = true refused"));
    let log = Fmu3::<Bare>::try_me(Bare::declaration().guid()).err().unwrap();
    assert!(log.0.borrow().last().unwrap().2.contains("does not offer ModelExchange"));
    // Scheduled Execution: NULL and the reason
    let log = Box::<testing::Log>::default();
    let token = CString::new(Toy::declaration().guid()).unwrap();
    let c = unsafe {
        abi::fmi3::instantiate_scheduled_execution::<Toy>(
            Function::Fmi3InstantiateScheduledExecution,
            c"toy".as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            1,
            &*log as *const testing::Log as *mut std::ffi::c_void,
            Some(testing::log_message),
            None,
            None,
            None,
        )
    };
    assert!(c.is_null());
    let msg = log.0.borrow().last().unwrap().2.clone();
    assert!(
        msg.starts_with(
            "fmi3InstantiateScheduledExecution: toy does not offer ScheduledExecution (it declares no clock)"
        ),
        "{msg}"
    );
    // no logger given: still NULL, nothing to crash on
    let c = unsafe {
        abi::fmi3::instantiate_model_exchange::<Toy>(
            Function::Fmi3InstantiateModelExchange,
            std::ptr::null(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            1,
            null_mut(),
            None,
        )
    };
    assert!(c.is_null());
}

/// Every function of a feature the toy does not declare: fmi3Error and a message naming
/// the function and what is missing, in every state reached here; a function of the other
/// generation on an FMI 3.0 instance too.
#[test]
fn fmi3_undeclared_features_and_illegal_orders_are_errors_with_a_message() {
    for f in Function::FMI3.into_iter().filter(|f| f.undeclared_feature().is_some()) {
        let fmu = Fmu3::<Toy>::cs();
        assert_eq!(unsafe { abi::fmi3::undeclared::<Toy>(f, fmu.c) }, ERR3);
        let msg = fmu.last_error();
        assert!(msg.starts_with(&format!("{}: not supported", f.name())), "{msg}");
    }
    let f = Fmu3::<Toy>::cs();
    assert_eq!(f.enter_event_mode(), ERR3);
    assert!(f.last_error().contains("hasEventMode is false"), "{}", f.last_error());
    let f = Fmu3::<Toy>::cs();
    assert_eq!(f.step(0.0, 0.1).status, ERR3);
    assert!(f.last_error().starts_with("fmi3DoStep: not allowed in state Instantiated"), "{}", f.last_error());
    assert_eq!(f.exit_init(), ERR3, "the error state allows no mode change");
    assert_eq!(f.reset(), OK3);
    assert_eq!(f.exit_init(), ERR3);
    assert!(f.last_error().contains("not allowed in state Instantiated"));
    assert_eq!(f.reset(), OK3);
    // an fmi2 function on an FMI 3.0 instance
    assert_eq!(unsafe { abi::do_step::<Toy>(Function::DoStep, f.c, 0.0, 0.1, 0) }, ERR);
    assert!(f.last_error().contains("created by an fmi3Instantiate function"), "{}", f.last_error());
    // ME only functions on a CS instance
    assert_eq!(f.reset(), OK3);
    assert_eq!(f.set_time(0.0), ERR3);
    assert!(f.last_error().contains("created for CoSimulation"), "{}", f.last_error());
    // a null instance
    assert_eq!(unsafe { abi::fmi3::status3(abi::terminate::<Toy>(Function::Fmi3Terminate, null_mut())) }, ERR3);
}

#[test]
fn fmi3_fmu_state_round_trips_and_refuses_truncated_or_foreign_bytes() {
    let f = Fmu3::<Toy>::cs();
    f.init_until(0.0, None);
    assert_eq!(f.set_float64(&[vr3::U], &[1.5]), OK3);
    assert_eq!(f.step(0.0, 0.25).status, OK3);
    let bytes = f.serialized_state();
    let y = f.float64(vr3::Y);
    assert_eq!(f.step(0.25, 0.25).status, OK3);
    assert_ne!(f.float64(vr3::Y), y);
    assert_eq!(f.restore_serialized(&bytes), OK3, "{}", f.last_error());
    assert_eq!(f.float64(vr3::Y).to_bits(), y.to_bits());
    assert_eq!(f.float64(vr3::TIME), 0.25);
    // the same bytes restore into an FMI 2.0 instance of the same library (one format)
    let f2 = Fmu::<Toy>::cs();
    assert_eq!(f2.restore_serialized(&bytes), OK, "{}", f2.last_error());
    assert_eq!(f2.real(vr::Y).to_bits(), y.to_bits());
    for cut in [0, 1, bytes.len() / 2, bytes.len() - 1] {
        let g = Fmu3::<Toy>::cs();
        assert_eq!(g.restore_serialized(&bytes[..cut]), ERR3, "truncated to {cut}");
        assert!(g.last_error().starts_with("fmi3DeserializeFMUState:"), "{}", g.last_error());
    }
    let mut foreign = bytes.clone();
    for (k, b) in foreign.iter_mut().enumerate() {
        *b = b.wrapping_mul(31).wrapping_add(k as u8);
    }
    let g = Fmu3::<Toy>::cs();
    assert_eq!(g.restore_serialized(&foreign), ERR3);
    // a state pointer the instance never made
    let mut fake = 0x1000usize as *mut std::ffi::c_void;
    assert_eq!(unsafe { abi::fmi3::status3(abi::set_fmu_state::<Toy>(Function::Fmi3SetFMUState, g.c, fake)) }, ERR3);
    assert_eq!(g.reset(), OK3);
    assert_eq!(
        unsafe { abi::fmi3::status3(abi::free_fmu_state::<Toy>(Function::Fmi3FreeFMUState, g.c, &mut fake)) },
        ERR3
    );
}

#[test]
fn fmi3_variable_dependencies_are_the_model_structure() {
    let f = Fmu3::<Toy>::cs();
    f.init_until(0.0, None);
    let mut n = 7usize;
    assert_eq!(
        unsafe {
            abi::fmi3::get_number_of_variable_dependencies::<Toy>(
                Function::Fmi3GetNumberOfVariableDependencies,
                f.c,
                vr3::Y,
                &mut n,
            )
        },
        OK3
    );
    assert_eq!(n, 1);
    let (mut e, mut on, mut eon, mut kind) = ([9usize], [9u32], [9usize], [9i32]);
    let s = unsafe {
        abi::fmi3::get_variable_dependencies::<Toy>(
            Function::Fmi3GetVariableDependencies,
            f.c,
            vr3::Y,
            e.as_mut_ptr(),
            on.as_mut_ptr(),
            eon.as_mut_ptr(),
            kind.as_mut_ptr(),
            1,
        )
    };
    assert_eq!(s, OK3, "{}", f.last_error());
    assert_eq!((e, on, eon, kind), ([0], [vr3::U], [0], [fmi_export::fmi_sys::fmi3::FMI3_DEPENDENT]));
    // wrong count, not an unknown
    let s = unsafe {
        abi::fmi3::get_variable_dependencies::<Toy>(
            Function::Fmi3GetVariableDependencies,
            f.c,
            vr3::Y,
            e.as_mut_ptr(),
            on.as_mut_ptr(),
            eon.as_mut_ptr(),
            kind.as_mut_ptr(),
            2,
        )
    };
    assert_eq!(s, ERR3);
    assert!(f.last_error().contains("nDependencies = 2"), "{}", f.last_error());
    assert_eq!(f.reset(), OK3);
    assert_eq!(
        unsafe {
            abi::fmi3::get_number_of_variable_dependencies::<Toy>(
                Function::Fmi3GetNumberOfVariableDependencies,
                f.c,
                vr3::GAIN,
                &mut n,
            )
        },
        ERR3
    );
    assert!(f.last_error().contains("gain (value reference 2) is no unknown"), "{}", f.last_error());
}

/// The model's request to end the run: a Discard with terminateSimulation, as FMI 2.0's
/// Discard with fmi2Terminated; lastSuccessfulTime where the model stopped.
#[test]
fn fmi3_the_model_ending_the_run_sets_terminate_simulation() {
    let f = Fmu3::<Toy>::cs();
    assert_eq!(f.set_int64(vr3::MODE, STOP_AT_3 as i64), OK3);
    f.init_until(0.0, None);
    let s = f.step(0.0, 0.5);
    assert_eq!(s.status, DISCARD3, "{}", f.last_error());
    assert!(s.terminate_simulation);
    assert_eq!(s.last_successful_time, 0.2);
    assert_eq!(f.step(0.2, 0.1).status, ERR3, "no step after a discarded one");
    let g = Fmu::<Toy>::cs();
    assert_eq!(g.set_int(vr::MODE, STOP_AT_3), OK);
    g.init(None);
    assert_eq!(g.step(0.0, 0.5), testing::DISCARD);
    assert!(g.terminated());
    assert_eq!(g.last_successful_time(), s.last_successful_time);
}
