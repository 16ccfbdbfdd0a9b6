//! One FMU instance in safe Rust: the FMI 2.0 state machine, variable access checks and
//! FMU state handling. The C ABI in [`crate::abi`] only translates pointers to slices.

use crate::decl::{BaseType, Causality, Declaration, Initial, Variability};
use crate::model::{InstantiateContext, Interface, Model};

/// The FMI 2.0 instance states (standard sections 3.2.3 and 4.2.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Machine {
    Instantiated,
    InitializationMode,
    /// Co-Simulation, between steps.
    StepComplete,
    /// Model Exchange.
    EventMode,
    /// Model Exchange.
    ContinuousTimeMode,
    Terminated,
    /// After any `fmi2Error`: only reset, free, FMU state restore and diagnostic gets.
    Error,
}

impl Machine {
    fn code(self) -> f64 {
        self as u8 as f64
    }
    fn from_code(c: f64) -> Option<Machine> {
        use Machine::*;
        [Instantiated, InitializationMode, StepComplete, EventMode, ContinuousTimeMode, Terminated, Error]
            .into_iter()
            .find(|m| m.code() == c)
    }
}

/// Result of the fallible instance operations: the message is logged by the ABI layer.
pub type OpResult<T = ()> = Result<T, String>;

/// A saved FMU state (`fmi2FMUstate`): model data and the layer's own, never the callbacks.
#[derive(Clone)]
pub struct SavedState<M> {
    machine: Machine,
    time: f64,
    model: M,
}

/// One instance of model `M`.
pub struct Instance<M: Model> {
    pub context: InstantiateContext,
    pub machine: Machine,
    pub time: f64,
    pub stop_time: Option<f64>,
    pub model: M,
}

/// The states from `fmi2EnterInitializationMode` on, short of the error state.
const INITIALIZING_OR_LATER: [Machine; 5] = [
    Machine::InitializationMode,
    Machine::StepComplete,
    Machine::EventMode,
    Machine::ContinuousTimeMode,
    Machine::Terminated,
];

const SERIAL_MAGIC: &[u8; 8] = b"NIGELFMU";
const SERIAL_VERSION: u32 = 1;

fn decl<M: Model>() -> &'static Declaration<M::Binding> {
    M::declaration()
}

impl<M: Model> Instance<M> {
    /// A new instance with every declared start value applied.
    pub fn new(context: InstantiateContext) -> OpResult<Self> {
        let model = Self::fresh_model(&context)?;
        Ok(Instance { context, machine: Machine::Instantiated, time: 0.0, stop_time: None, model })
    }

    fn fresh_model(context: &InstantiateContext) -> OpResult<M> {
        let mut model = M::instantiate(context)?;
        for v in &decl::<M>().spec.variables {
            let r = match v.start {
                crate::decl::Start::None => Ok(()),
                crate::decl::Start::Real(x) => model.set_real(v.binding, x),
                crate::decl::Start::Integer(x) => model.set_integer(v.binding, x),
                crate::decl::Start::Boolean(x) => model.set_boolean(v.binding, x),
            };
            r.map_err(|e| format!("start value of {} refused: {e}", v.name))?;
        }
        Ok(model)
    }

    fn require(&self, allowed: &[Machine], what: &str) -> OpResult {
        if allowed.contains(&self.machine) {
            Ok(())
        } else {
            Err(format!("{what} is not allowed in state {:?}", self.machine))
        }
    }

    fn require_interface(&self, interface: Interface) -> OpResult {
        if self.context.interface == interface {
            Ok(())
        } else {
            Err(format!("this instance was created for {:?}, the call is {:?} only", self.context.interface, interface))
        }
    }

    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64, stop_time: Option<f64>) -> OpResult {
        self.require(&[Machine::Instantiated], "fmi2SetupExperiment")?;
        if !start_time.is_finite() {
            return Err(format!("startTime {start_time} is not finite"));
        }
        if let Some(stop) = stop_time {
            if !(stop >= start_time) {
                return Err(format!("stopTime {stop} is before startTime {start_time}"));
            }
        }
        if let Some(tol) = tolerance {
            if !(tol > 0.0) {
                return Err(format!("tolerance {tol} must be > 0"));
            }
        }
        self.time = start_time;
        self.stop_time = stop_time;
        self.model.set_time(start_time);
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> OpResult {
        self.require(&[Machine::Instantiated], "fmi2EnterInitializationMode")?;
        self.machine = Machine::InitializationMode;
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> OpResult {
        self.require(&[Machine::InitializationMode], "fmi2ExitInitializationMode")?;
        self.model.exit_initialization()?;
        self.machine = match self.context.interface {
            Interface::CoSimulation => Machine::StepComplete,
            Interface::ModelExchange => Machine::EventMode,
        };
        Ok(())
    }

    pub fn terminate(&mut self) -> OpResult {
        self.require(&[Machine::StepComplete, Machine::EventMode, Machine::ContinuousTimeMode], "fmi2Terminate")?;
        self.machine = Machine::Terminated;
        Ok(())
    }

    /// Back to `Instantiated` with the start values, keeping name, interface and callbacks.
    pub fn reset(&mut self) -> OpResult {
        self.model = Self::fresh_model(&self.context)?;
        self.machine = Machine::Instantiated;
        self.time = 0.0;
        self.stop_time = None;
        Ok(())
    }

    /// Whether variable `row` may be set in the current state (FMI 2.0 tables).
    fn settable(&self, row: usize) -> bool {
        let v = decl::<M>().variable(row);
        if v.variability == Variability::Constant || v.causality == Causality::Independent {
            return false;
        }
        let has_start = matches!(v.initial, Some(Initial::Exact) | Some(Initial::Approx));
        match self.machine {
            Machine::Instantiated | Machine::InitializationMode => has_start || v.causality == Causality::Input,
            Machine::StepComplete | Machine::EventMode => {
                v.causality == Causality::Input
                    || (v.causality == Causality::Parameter && v.variability == Variability::Tunable)
            }
            Machine::ContinuousTimeMode => v.causality == Causality::Input && v.variability == Variability::Continuous,
            Machine::Terminated | Machine::Error => false,
        }
    }

    fn rows(&self, base_type: BaseType, vrs: &[u32]) -> OpResult<Vec<usize>> {
        vrs.iter()
            .map(|&vr| {
                decl::<M>().row(base_type, vr).ok_or_else(|| format!("unknown {base_type:?} value reference {vr}"))
            })
            .collect()
    }

    fn check_get(&self) -> OpResult {
        // values can be read once initialization has started, and in the error state for diagnosis
        if self.machine == Machine::Error {
            return Ok(());
        }
        self.require(&INITIALIZING_OR_LATER, "getting values")
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> OpResult {
        self.check_get()?;
        let rows = self.rows(BaseType::Real, vrs)?;
        for (o, row) in out.iter_mut().zip(rows) {
            *o = self.finite_real(row)?;
        }
        Ok(())
    }

    /// A Real of the model, refusing a non-finite result (an overflowed state, say)
    /// rather than handing NaN or Inf to the importer's solver.
    fn finite_real(&mut self, row: usize) -> OpResult<f64> {
        let v = decl::<M>().variable(row);
        let x = self.model.get_real(v.binding)?;
        if x.is_finite() {
            Ok(x)
        } else {
            Err(format!("{} evaluated to {x} (the state or inputs are out of the model's range)", v.name))
        }
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> OpResult {
        self.check_get()?;
        let rows = self.rows(BaseType::Integer, vrs)?;
        for (o, row) in out.iter_mut().zip(rows) {
            *o = self.model.get_integer(decl::<M>().variable(row).binding)?;
        }
        Ok(())
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> OpResult {
        self.check_get()?;
        let rows = self.rows(BaseType::Boolean, vrs)?;
        for (o, row) in out.iter_mut().zip(rows) {
            *o = self.model.get_boolean(decl::<M>().variable(row).binding)?;
        }
        Ok(())
    }

    /// Sets all or nothing: every value reference, permission and value is checked first,
    /// and if the model refuses one value the earlier ones are rolled back.
    fn set_values<T: Copy>(
        &mut self,
        base_type: BaseType,
        vrs: &[u32],
        values: &[T],
        check: impl Fn(&str, T) -> OpResult,
        mut apply: impl FnMut(&mut M, M::Binding, T) -> OpResult,
    ) -> OpResult {
        let rows = self.rows(base_type, vrs)?;
        for (&row, &value) in rows.iter().zip(values) {
            let v = decl::<M>().variable(row);
            if !self.settable(row) {
                return Err(format!(
                    "{} ({:?}, {:?}) cannot be set in state {:?}",
                    v.name, v.causality, v.variability, self.machine
                ));
            }
            check(v.name, value)?;
        }
        let backup = self.model.clone();
        for (&row, &value) in rows.iter().zip(values) {
            let v = decl::<M>().variable(row);
            if let Err(e) = apply(&mut self.model, v.binding, value) {
                self.model = backup;
                return Err(format!("{}: {e}", v.name));
            }
        }
        Ok(())
    }

    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> OpResult {
        self.set_values(
            BaseType::Real,
            vrs,
            values,
            |name, x: f64| {
                if x.is_finite() {
                    Ok(())
                } else {
                    Err(format!("{name} = {x} refused: not a finite number"))
                }
            },
            |m, b, x| m.set_real(b, x),
        )
    }

    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> OpResult {
        self.set_values(BaseType::Integer, vrs, values, |_, _| Ok(()), |m, b, x| m.set_integer(b, x))
    }

    pub fn set_boolean(&mut self, vrs: &[u32], values: &[bool]) -> OpResult {
        self.set_values(BaseType::Boolean, vrs, values, |_, _| Ok(()), |m, b, x| m.set_boolean(b, x))
    }

    // ---------------------------------------------------------------- Co-Simulation

    pub fn do_step(&mut self, current_time: f64, step: f64) -> OpResult {
        self.require_interface(Interface::CoSimulation)?;
        self.require(&[Machine::StepComplete], "fmi2DoStep")?;
        if !(step > 0.0) || !step.is_finite() {
            return Err(format!("communicationStepSize {step} must be finite and > 0"));
        }
        let tolerance = 1e-9 * self.time.abs().max(1.0);
        if !current_time.is_finite() || (current_time - self.time).abs() > tolerance {
            return Err(format!(
                "currentCommunicationPoint {current_time} is not the end of the previous step ({})",
                self.time
            ));
        }
        self.model.do_step(self.time, step)?;
        self.time = current_time + step;
        Ok(())
    }

    // ---------------------------------------------------------------- Model Exchange

    pub fn set_time(&mut self, time: f64) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&[Machine::InitializationMode, Machine::EventMode, Machine::ContinuousTimeMode], "fmi2SetTime")?;
        if !time.is_finite() {
            return Err(format!("time {time} is not finite"));
        }
        self.time = time;
        self.model.set_time(time);
        Ok(())
    }

    pub fn enter_event_mode(&mut self) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&[Machine::EventMode, Machine::ContinuousTimeMode], "fmi2EnterEventMode")?;
        self.machine = Machine::EventMode;
        Ok(())
    }

    pub fn enter_continuous_time_mode(&mut self) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&[Machine::EventMode], "fmi2EnterContinuousTimeMode")?;
        self.machine = Machine::ContinuousTimeMode;
        Ok(())
    }

    /// `fmi2NewDiscreteStates`: these models have no discrete states or events.
    pub fn new_discrete_states(&mut self) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&[Machine::EventMode], "fmi2NewDiscreteStates")
    }

    pub fn completed_integrator_step(&mut self) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&[Machine::ContinuousTimeMode], "fmi2CompletedIntegratorStep")
    }

    fn check_state_count(&self, n: usize) -> OpResult {
        let expected = decl::<M>().number_of_states();
        if n == expected {
            Ok(())
        } else {
            Err(format!("nx = {n}, the model has {expected} continuous states"))
        }
    }

    const ME_READ: [Machine; 5] = [
        Machine::InitializationMode,
        Machine::EventMode,
        Machine::ContinuousTimeMode,
        Machine::Terminated,
        Machine::Error,
    ];

    pub fn get_continuous_states(&mut self, out: &mut [f64]) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&Self::ME_READ, "fmi2GetContinuousStates")?;
        self.check_state_count(out.len())?;
        self.read_rows(&decl::<M>().state_rows, out)
    }

    /// Reads the Reals of `rows` into `out` (the state or derivative vector).
    fn read_rows(&mut self, rows: &[usize], out: &mut [f64]) -> OpResult {
        for (o, &row) in out.iter_mut().zip(rows) {
            *o = self.finite_real(row)?;
        }
        Ok(())
    }

    pub fn set_continuous_states(&mut self, x: &[f64]) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&[Machine::EventMode, Machine::ContinuousTimeMode], "fmi2SetContinuousStates")?;
        self.check_state_count(x.len())?;
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(format!(
                "state {} = {} refused: not a finite number",
                decl::<M>().variable(decl::<M>().state_rows[i]).name,
                x[i]
            ));
        }
        let backup = self.model.clone();
        for (&value, &row) in x.iter().zip(&decl::<M>().state_rows) {
            if let Err(e) = self.model.set_real(decl::<M>().variable(row).binding, value) {
                self.model = backup;
                return Err(e);
            }
        }
        Ok(())
    }

    pub fn get_derivatives(&mut self, out: &mut [f64]) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&Self::ME_READ, "fmi2GetDerivatives")?;
        self.check_state_count(out.len())?;
        self.read_rows(&decl::<M>().derivative_rows, out)
    }

    pub fn get_nominals(&mut self, out: &mut [f64]) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&Self::ME_READ, "fmi2GetNominalsOfContinuousStates")?;
        self.check_state_count(out.len())?;
        for (o, &row) in out.iter_mut().zip(&decl::<M>().state_rows) {
            *o = decl::<M>().variable(row).nominal.unwrap_or(1.0);
        }
        Ok(())
    }

    pub fn get_event_indicators(&mut self, out: &mut [f64]) -> OpResult {
        self.require_interface(Interface::ModelExchange)?;
        self.require(&Self::ME_READ, "fmi2GetEventIndicators")?;
        if out.is_empty() {
            Ok(())
        } else {
            Err(format!("ni = {}, the model has no event indicators", out.len()))
        }
    }

    // ---------------------------------------------------------------- derivatives

    pub fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        out: &mut [f64],
    ) -> OpResult {
        self.require(&INITIALIZING_OR_LATER, "fmi2GetDirectionalDerivative")?;
        if let Some(x) = dv_known.iter().find(|x| !x.is_finite()) {
            return Err(format!("dvKnown contains {x}"));
        }
        let binding = |vr: u32| -> OpResult<M::Binding> {
            decl::<M>()
                .row(BaseType::Real, vr)
                .map(|r| decl::<M>().variable(r).binding)
                .ok_or_else(|| format!("unknown Real value reference {vr}"))
        };
        let u: Vec<_> = unknowns.iter().map(|&vr| binding(vr)).collect::<OpResult<_>>()?;
        let k: Vec<_> = knowns.iter().map(|&vr| binding(vr)).collect::<OpResult<_>>()?;
        self.model.directional_derivative(&u, &k, dv_known, out)
    }

    // ---------------------------------------------------------------- FMU state

    pub fn save_state(&self) -> OpResult<SavedState<M>> {
        if self.machine == Machine::Error {
            return Err("fmi2GetFMUstate: the instance is in the error state".into());
        }
        Ok(SavedState { machine: self.machine, time: self.time, model: self.model.clone() })
    }

    /// Restores a saved state (the callbacks stay the current instance's).
    pub fn restore_state(&mut self, state: &SavedState<M>) -> OpResult {
        let fits = match state.machine {
            Machine::StepComplete => self.context.interface == Interface::CoSimulation,
            Machine::EventMode | Machine::ContinuousTimeMode => self.context.interface == Interface::ModelExchange,
            _ => true,
        };
        if !fits {
            return Err(format!(
                "a state saved in {:?} cannot be restored into a {:?} instance",
                state.machine, self.context.interface
            ));
        }
        self.machine = state.machine;
        self.time = state.time;
        self.model = state.model.clone();
        Ok(())
    }

    /// Bytes of a saved state: magic, version, the GUID (a state belongs to one model),
    /// then machine state, time and the model's numbers, all little-endian.
    pub fn serialize(state: &SavedState<M>) -> Vec<u8> {
        let guid = decl::<M>().guid().as_bytes();
        let mut numbers = vec![state.machine.code(), state.time];
        state.model.save(&mut numbers);
        let mut out = Vec::with_capacity(8 + 4 + 4 + guid.len() + 8 + numbers.len() * 8);
        out.extend_from_slice(SERIAL_MAGIC);
        out.extend_from_slice(&SERIAL_VERSION.to_le_bytes());
        out.extend_from_slice(&(guid.len() as u32).to_le_bytes());
        out.extend_from_slice(guid);
        out.extend_from_slice(&(numbers.len() as u64).to_le_bytes());
        for x in numbers {
            out.extend_from_slice(&x.to_le_bytes());
        }
        out
    }

    /// Parses bytes from [`Instance::serialize`]; refuses anything else with the reason.
    pub fn deserialize(&self, bytes: &[u8]) -> OpResult<SavedState<M>> {
        let mut rest = bytes;
        let mut take = |n: usize| -> OpResult<&[u8]> {
            if rest.len() < n {
                return Err(format!("serialized state truncated ({} bytes)", bytes.len()));
            }
            let (head, tail) = rest.split_at(n);
            rest = tail;
            Ok(head)
        };
        if take(8)? != SERIAL_MAGIC {
            return Err("not a serialized FMU state of this layer (bad magic)".into());
        }
        let version = u32::from_le_bytes(take(4)?.try_into().unwrap_or_default());
        if version != SERIAL_VERSION {
            return Err(format!("serialized state version {version}, expected {SERIAL_VERSION}"));
        }
        let guid_len = u32::from_le_bytes(take(4)?.try_into().unwrap_or_default()) as usize;
        if guid_len > 256 {
            return Err("serialized state has an implausible GUID length".into());
        }
        if take(guid_len)? != decl::<M>().guid().as_bytes() {
            return Err("serialized state belongs to another model (GUID differs)".into());
        }
        let count = u64::from_le_bytes(take(8)?.try_into().unwrap_or_default());
        let expected_bytes = count.checked_mul(8).filter(|&n| n == (bytes.len() - (8 + 4 + 4 + guid_len + 8)) as u64);
        if expected_bytes.is_none() || count < 2 {
            return Err("serialized state length does not match its header".into());
        }
        let numbers: Vec<f64> = take(count as usize * 8)?
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
            .collect();
        let machine = Machine::from_code(numbers[0]).ok_or("serialized state has an unknown instance state")?;
        let time = numbers[1];
        if !time.is_finite() {
            return Err("serialized state has a non-finite time".into());
        }
        let mut model = self.model.clone();
        model.load(&numbers[2..])?;
        Ok(SavedState { machine, time, model })
    }
}
