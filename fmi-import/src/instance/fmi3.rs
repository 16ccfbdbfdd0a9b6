//! An instance's calls of the FMI 3.0 C API, the FMI 3.0 view included: the view's Reals,
//! Integers and Booleans of the other FMI 3.0 types and the elements of arrays (see
//! [`crate::fmi3`]) go by their own getters and setters, an array element set alone with
//! the array's other elements as set before; `fmi3DoStep`'s early returns, events and
//! `terminateSimulation` become the step FMI 2.0 reports.

use std::collections::HashMap;
use std::ffi::{c_char, c_int, c_void, CString};
use std::sync::Arc;

use super::clocked::HeldNumber;
use super::core::{call, Calls, ClockCalls, Core, FreeInstanceFunction, FreeStateFunction, ResetFunction, Seed};
use crate::c_types::{Component, EventInfo};
use crate::error::{Error, Result};
use crate::fmi3::{Access, Fmi3Abi};
use crate::fmu::{Fmu, Interface};
use crate::instance::core::InstanceState;
use crate::log::LogSink;
use crate::status::Status;

/// The FMI 3.0 calls: the library's table and description, and what an instance keeps
/// that FMI 2.0 has no place for.
pub(crate) struct Fmi3 {
    pub(super) a: Arc<Fmi3Abi>,
    /// What `setup_experiment` was given (tolerance, start, stop), passed on by
    /// `fmi3EnterInitializationMode`.
    experiment: (Option<f64>, f64, Option<f64>),
    /// The time `fmi3DoStep` reported `terminateSimulation` at.
    terminate_requested: Option<f64>,
    /// Booleans as the bytes the ABI has (reused).
    bytes: Vec<u8>,
    /// The values of arrays set element by element, by value reference.
    arrays: HashMap<u32, Vec<f64>>,
    /// Those of the Int64 and UInt64 arrays, as the integers themselves (an f64 holds them
    /// exactly only up to 2^53).
    wide_arrays: HashMap<u32, Vec<i128>>,
    /// The arrays whose size now is not the view's (a structural parameter changed in
    /// Reconfiguration Mode, or to be): by the FMU's value reference, the view's dimensions
    /// and those of now (`structural::resized_arrays`); empty almost always.
    pub(super) resized: HashMap<u32, (Vec<u64>, Vec<u64>)>,
    /// The structural parameters whose value now is not the view's (value reference, value).
    pub(super) sizes_now: Vec<(u32, f64)>,
    /// Co-Simulation with `eventModeUsed` (an FMU with `hasEventMode`; false again when the
    /// FMU refused to be instantiated with it and accepted without).
    event_mode: std::cell::Cell<bool>,
    /// The FMU's output clocks (value references), read by `fmi3GetClock` in every event.
    pub(super) output_clocks: Vec<u32>,
    /// The output clocks' ticks not yet taken (`instance/clocks.rs`).
    pub(super) output_ticks: Vec<super::core::OutputTick>,
    /// The input clocks whose interval the FMU gives (tunable, changing, countdown), read
    /// by `fmi3GetIntervalDecimal` in every event.
    interval_clocks: Vec<u32>,
    /// The fixed input clocks: their interval read in the first event of a run (the one
    /// that ends initialization) only, as it cannot change afterwards.
    fixed_clocks: Vec<u32>,
    /// The fixed clocks' intervals were read in this run.
    fixed_read: bool,
    /// What the FMU said of their intervals, not yet taken: (event time, clock, interval).
    pub(super) intervals: Vec<(f64, u32, super::core::Interval)>,
    /// Scheduled Execution: the environment of the FMU's callbacks (boxed: its address is
    /// the FMU's for as long as the instance lives).
    scheduled: Option<Box<super::callbacks::ScheduledEnvironment>>,
    /// The clocked variables: held between their clocks' ticks, sets queued to the next
    /// (`clocked.rs`).
    pub(super) clocked: super::clocked::ClockedExchange,
    /// The input clocks set (`fmi3SetClock`) in the current event: their clocked variables
    /// are read when it settles.
    pub(super) ticked_inputs: Vec<u32>,
    /// The output clocks `fmi3GetClock` reported active as the current event opened (an FMU
    /// may activate one in `fmi3SetClock`): counted then, their variables read from the FMU
    /// while it is open, not counted again when it settles.
    pub(super) opened_outputs: Vec<u32>,
}

/// A function of the FMI 3.0 table that may be absent, or the error naming it.
macro_rules! f3 {
    ($core:expr, $a:expr, $field:ident, $name:literal) => {
        $core.optional($a.functions.$field, $name)?
    };
}

impl Fmi3 {
    pub(crate) fn new(a: Arc<Fmi3Abi>, interface: Interface) -> Fmi3 {
        let event_mode = interface == Interface::CoSimulation
            && a.description.co_simulation.as_ref().is_some_and(|cs| cs.has_event_mode);
        use crate::clocks::{ClockCausality, ClockKind};
        // Scheduled Execution runs the clocks through its own calls (`scheduled.rs`)
        let clocks = if interface == Interface::ScheduledExecution {
            Vec::new()
        } else {
            crate::clocks::clocks_of(&a.description)
        };
        let output_clocks =
            clocks.iter().filter(|c| c.causality == ClockCausality::Output).map(|c| c.value_reference).collect();
        let given = |fixed: bool| -> Vec<u32> {
            clocks
                .iter()
                .filter(|c| {
                    c.causality == ClockCausality::Input
                        && !matches!(c.kind, ClockKind::Constant | ClockKind::Triggered)
                        && (c.kind == ClockKind::Fixed) == fixed
                })
                .map(|c| c.value_reference)
                .collect()
        };
        let (interval_clocks, fixed_clocks) = (given(false), given(true));
        Fmi3 {
            experiment: (None, 0.0, None),
            terminate_requested: None,
            bytes: Vec::new(),
            arrays: HashMap::new(),
            wide_arrays: HashMap::new(),
            resized: HashMap::new(),
            sizes_now: Vec::new(),
            event_mode: std::cell::Cell::new(event_mode),
            output_clocks,
            output_ticks: Vec::new(),
            interval_clocks,
            fixed_clocks,
            fixed_read: false,
            intervals: Vec::new(),
            scheduled: (interface == Interface::ScheduledExecution).then(Box::default),
            clocked: super::clocked::ClockedExchange::new(&a.description, &a.special),
            ticked_inputs: Vec::new(),
            opened_outputs: Vec::new(),
            a,
        }
    }

    /// The FMU's table and description.
    pub(super) fn abi(&self) -> &Fmi3Abi {
        &self.a
    }

    /// The access of the view's variable `vr` when it is not a plain scalar.
    #[inline]
    fn special(&self, vr: u32) -> Option<Access> {
        if self.a.special.is_empty() {
            return None;
        }
        self.a.special.get(&vr).copied()
    }

    /// Whether some of `vrs` are not plain scalars: they go one by one.
    #[inline]
    fn any_special(&self, vrs: &[u32]) -> bool {
        !self.a.special.is_empty() && vrs.iter().any(|vr| self.a.special.contains_key(vr))
    }

    /// The number of elements `access`'s variable has now, and which of them `access` is
    /// (`None`: an element the array does not have now): the view's unless a structural
    /// parameter sizes the array otherwise now.
    #[inline]
    fn now(&self, access: Access) -> (usize, Option<usize>) {
        if self.resized.is_empty() {
            return (access.count, Some(access.element));
        }
        match self.resized.get(&access.vr) {
            None => (access.count, Some(access.element)),
            Some((view, dims)) => {
                (dims.iter().product::<u64>() as usize, crate::structural::element_now(view, dims, access.element))
            }
        }
    }

    /// The structural parameters have the values `now` (value reference, value) where they
    /// are not the view's: the arrays they size are read and set with their sizes now.
    pub(super) fn resize(&mut self, now: Vec<(u32, f64)>) {
        self.resized = crate::structural::resized_arrays(&self.a.description, &now);
        self.sizes_now = now;
        let resized = &self.resized;
        self.arrays.retain(|vr, _| !resized.contains_key(vr));
        self.wide_arrays.retain(|vr, _| !resized.contains_key(vr));
    }

    /// All values of the FMI 3.0 variable of `access` (as many as it has now), as f64
    /// (64-bit integers the nearest, exact up to 2^53; Booleans 0 or 1, a Binary its size in
    /// bytes).
    fn get_all(&mut self, core: &mut Core, access: Access) -> Result<Vec<f64>> {
        use model_description::fmi3::ValueType as T;
        let n = self.now(access).0;
        let c = core.component;
        let a = &*self.a;
        let vr = access.vr;
        macro_rules! get {
            ($field:ident, $name:literal, $t:ty) => {{
                let f = f3!(core, a, $field, $name);
                let mut buf: Vec<$t> = vec![<$t>::default(); n];
                call!(core, $name, None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
                buf
            }};
        }
        Ok(match access.value_type {
            T::Float64 => {
                let f = a.functions.get_float64;
                let mut buf = vec![0.0; n];
                call!(core, "fmi3GetFloat64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
                buf
            }
            T::Float32 => get!(get_float32, "fmi3GetFloat32", f32).into_iter().map(f64::from).collect(),
            T::Int8 => get!(get_int8, "fmi3GetInt8", i8).into_iter().map(f64::from).collect(),
            T::UInt8 => get!(get_uint8, "fmi3GetUInt8", u8).into_iter().map(f64::from).collect(),
            T::Int16 => get!(get_int16, "fmi3GetInt16", i16).into_iter().map(f64::from).collect(),
            T::UInt16 => get!(get_uint16, "fmi3GetUInt16", u16).into_iter().map(f64::from).collect(),
            T::Int32 => get!(get_int32, "fmi3GetInt32", i32).into_iter().map(f64::from).collect(),
            T::UInt32 => get!(get_uint32, "fmi3GetUInt32", u32).into_iter().map(f64::from).collect(),
            // the nearest f64 (exact up to 2^53); `get_exact` reads the integer itself
            T::Int64 | T::Enumeration => get!(get_int64, "fmi3GetInt64", i64).into_iter().map(|x| x as f64).collect(),
            T::UInt64 => get!(get_uint64, "fmi3GetUInt64", u64).into_iter().map(|x| x as f64).collect(),
            T::Boolean => get!(get_boolean, "fmi3GetBoolean", u8).into_iter().map(|b| (b != 0) as i32 as f64).collect(),
            T::Binary => {
                let f = f3!(core, a, get_binary, "fmi3GetBinary");
                let mut sizes = vec![0usize; n];
                let mut data: Vec<*const u8> = vec![std::ptr::null(); n];
                call!(core, "fmi3GetBinary", None, f(c, &vr, 1, sizes.as_mut_ptr(), data.as_mut_ptr(), n))?;
                sizes.into_iter().map(|s| s as f64).collect()
            }
            T::String | T::Clock => unreachable!("not in the view as a number"),
        })
    }

    /// Element `access` within one get call, whose last array read is `array`: an array is
    /// read once per call, not once per element (the elements of one array are asked
    /// together, a row of the results, and the FMU does not change in between), so that
    /// a row costs time linear in the elements.
    fn element_of_call(&mut self, core: &mut Core, access: Access, array: &mut Option<(u32, Vec<f64>)>) -> Result<f64> {
        if access.count <= 1 {
            return self.get_element(core, access);
        }
        if array.as_ref().is_none_or(|(read, _)| *read != access.vr) {
            *array = Some((access.vr, self.get_all(core, access)?));
        }
        let element = self.now(access).1;
        Ok(array.as_ref().zip(element).and_then(|((_, all), k)| all.get(k)).copied().unwrap_or(f64::NAN))
    }

    /// One element; NaN for one its array does not have now.
    fn get_element(&mut self, core: &mut Core, access: Access) -> Result<f64> {
        let all = self.get_all(core, access)?;
        Ok(self.now(access).1.and_then(|k| all.get(k)).copied().unwrap_or(f64::NAN))
    }

    /// Sets all values of the FMI 3.0 variable of `access` from f64 (integers must be
    /// whole and in their type's range).
    pub(super) fn set_all(&mut self, core: &mut Core, access: Access, values: &[f64]) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        let c = core.component;
        let name = core
            .fmu
            .description
            .model_variables
            .iter()
            .find(|v| v.value_reference == access.vr)
            .map(|v| v.name.clone());
        let a = &*self.a;
        let (vr, n) = (access.vr, values.len());
        let instance = core.name.clone();
        let variable = || format!("{instance}.{}", name.clone().unwrap_or_else(|| format!("<vr {vr}>")));
        macro_rules! set_int {
            ($field:ident, $name:literal, $t:ty) => {{
                let f = f3!(core, a, $field, $name);
                let mut buf: Vec<$t> = Vec::with_capacity(n);
                for x in values {
                    let wide = *x as i128;
                    let fits = wide as f64 == *x && wide >= <$t>::MIN as i128 && wide <= <$t>::MAX as i128;
                    if !fits {
                        return Err(Error::InvalidValue {
                            variable: variable(),
                            value: x.to_string(),
                            reason: format!("not a whole number of {}", stringify!($t)),
                        });
                    }
                    buf.push(wide as $t);
                }
                call!(core, $name, None, f(c, &vr, 1, buf.as_ptr(), n))
            }};
        }
        match access.value_type {
            T::Float64 => {
                let f = a.functions.set_float64;
                call!(core, "fmi3SetFloat64", None, f(c, &vr, 1, values.as_ptr(), n))
            }
            T::Float32 => {
                let f = f3!(core, a, set_float32, "fmi3SetFloat32");
                let buf: Vec<f32> = values.iter().map(|x| *x as f32).collect();
                call!(core, "fmi3SetFloat32", None, f(c, &vr, 1, buf.as_ptr(), n))
            }
            T::Int8 => set_int!(set_int8, "fmi3SetInt8", i8),
            T::UInt8 => set_int!(set_uint8, "fmi3SetUInt8", u8),
            T::Int16 => set_int!(set_int16, "fmi3SetInt16", i16),
            T::UInt16 => set_int!(set_uint16, "fmi3SetUInt16", u16),
            T::Int32 => set_int!(set_int32, "fmi3SetInt32", i32),
            T::UInt32 => set_int!(set_uint32, "fmi3SetUInt32", u32),
            T::Int64 | T::Enumeration => set_int!(set_int64, "fmi3SetInt64", i64),
            T::UInt64 => set_int!(set_uint64, "fmi3SetUInt64", u64),
            T::Boolean => {
                let f = f3!(core, a, set_boolean, "fmi3SetBoolean");
                let buf: Vec<u8> = values.iter().map(|x| (*x != 0.0) as u8).collect();
                call!(core, "fmi3SetBoolean", None, f(c, &vr, 1, buf.as_ptr(), n))
            }
            T::Binary | T::String | T::Clock => Err(Error::InvalidValue {
                variable: variable(),
                value: values.first().map(|x| x.to_string()).unwrap_or_default(),
                reason: "a Binary is recorded as its size and cannot be set".into(),
            }),
        }
    }

    /// Sets element `access.element` of its variable: the other elements keep the values
    /// set or read before (the start values at first).
    fn set_element(&mut self, core: &mut Core, access: Access, value: f64) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        if access.count == 1 {
            return self.set_all(core, access, &[value]);
        }
        // a 64-bit array keeps its elements as integers: set through the same values
        if matches!(access.value_type, T::Int64 | T::UInt64) {
            let whole = value as i128;
            if whole as f64 != value {
                let name = self.a.description.variable(access.vr).map_or("?", |v| v.name.as_str());
                return Err(Error::InvalidValue {
                    variable: format!("{}.{name}", core.name),
                    value: value.to_string(),
                    reason: format!("not a whole number of {:?}", access.value_type),
                });
            }
            return self.set_wide_element(core, access, whole);
        }
        let (n, element) = self.now(access);
        let Some(element) = element else {
            return Err(self.absent_element(core, access, n, value.to_string()));
        };
        let mut values = match self.arrays.remove(&access.vr) {
            Some(v) if v.len() == n => v,
            _ => self.array_start(core, access)?,
        };
        values[element] = value;
        let result = self.set_all(core, access, &values);
        self.arrays.insert(access.vr, values);
        result
    }

    /// The error of a set of an element the array does not have now (`n` elements).
    fn absent_element(&self, core: &Core, access: Access, n: usize, value: String) -> Error {
        let name = self.a.description.variable(access.vr).map_or("?", |v| v.name.as_str());
        Error::InvalidValue {
            variable: format!("{}.{name}", core.name),
            value,
            reason: format!(
                "element {} of an array that has {n} elements now (a structural parameter sized it so)",
                access.element + 1
            ),
        }
    }

    /// Sets element `access.element` of an Int64 or UInt64 array to the integer `value`
    /// exactly: the other elements keep the integers set or read before (the start values
    /// at first).
    fn set_wide_element(&mut self, core: &mut Core, access: Access, value: i128) -> Result<()> {
        let (n, element) = self.now(access);
        let Some(element) = element else {
            return Err(self.absent_element(core, access, n, value.to_string()));
        };
        let mut values = match self.wide_arrays.remove(&access.vr) {
            Some(v) if v.len() == n => v,
            _ => self.wide_array_start(core, access)?,
        };
        values[element] = value;
        let result = self.set_wide(core, access, &values);
        self.wide_arrays.insert(access.vr, values);
        result
    }

    /// The integers a 64-bit array starts from for element-wise sets: its start values,
    /// else what the FMU holds.
    fn wide_array_start(&mut self, core: &mut Core, access: Access) -> Result<Vec<i128>> {
        use model_description::fmi3::{ValueType as T, Values};
        let n = self.now(access).0;
        if !self.resized.contains_key(&access.vr) {
            if let Some(Values::Int(v)) = self.a.description.variable(access.vr).and_then(|v| v.start.clone()) {
                if v.len() == n {
                    return Ok(v);
                }
                if v.len() == 1 {
                    return Ok(vec![v[0]; n]);
                }
            }
        }
        let (c, a, vr) = (core.component, &*self.a, access.vr);
        Ok(if access.value_type == T::UInt64 {
            let f = f3!(core, a, get_uint64, "fmi3GetUInt64");
            let mut buf = vec![0u64; n];
            call!(core, "fmi3GetUInt64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
            buf.into_iter().map(i128::from).collect()
        } else {
            let f = f3!(core, a, get_int64, "fmi3GetInt64");
            let mut buf = vec![0i64; n];
            call!(core, "fmi3GetInt64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
            buf.into_iter().map(i128::from).collect()
        })
    }

    /// Sets all values of the Int64 or UInt64 variable of `access` to the integers
    /// `values`, each checked against the type's range (an error names the variable).
    fn set_wide(&mut self, core: &mut Core, access: Access, values: &[i128]) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        let (c, vr, n) = (core.component, access.vr, values.len());
        // the FMU's own name of the variable (the view's element names are not its)
        let name = self.a.description.variable(vr).map_or_else(|| format!("<vr {vr}>"), |v| v.name.clone());
        let out_of_range = |core: &Core, value: i128, ty: &str| Error::InvalidValue {
            variable: format!("{}.{name}", core.name),
            value: value.to_string(),
            reason: format!("outside the range of {ty}"),
        };
        if access.value_type == T::Int64 {
            let buf = values
                .iter()
                .map(|x| i64::try_from(*x).map_err(|_| out_of_range(core, *x, "Int64")))
                .collect::<Result<Vec<i64>>>()?;
            let f = f3!(core, self.a, set_int64, "fmi3SetInt64");
            call!(core, "fmi3SetInt64", None, f(c, &vr, 1, buf.as_ptr(), n))
        } else {
            let buf = values
                .iter()
                .map(|x| u64::try_from(*x).map_err(|_| out_of_range(core, *x, "UInt64")))
                .collect::<Result<Vec<u64>>>()?;
            let f = f3!(core, self.a, set_uint64, "fmi3SetUInt64");
            call!(core, "fmi3SetUInt64", None, f(c, &vr, 1, buf.as_ptr(), n))
        }
    }

    /// The values an array starts from for element-wise sets: its start values, else what
    /// the FMU holds.
    fn array_start(&mut self, core: &mut Core, access: Access) -> Result<Vec<f64>> {
        use model_description::fmi3::Values;
        // a resized array: what the FMU holds (its start values are the view's size)
        let start = match self.resized.contains_key(&access.vr) {
            true => None,
            false => self.a.description.variable(access.vr).and_then(|v| v.start.clone()),
        };
        let n = self.now(access).0;
        let spread = |v: Vec<f64>| if v.len() == 1 { vec![v[0]; n] } else { v };
        match start {
            Some(Values::Float(v)) if v.len() == n || v.len() == 1 => Ok(spread(v)),
            Some(Values::Int(v)) if v.len() == n || v.len() == 1 => {
                Ok(spread(v.into_iter().map(|x| x as f64).collect()))
            }
            Some(Values::Boolean(v)) if v.len() == n || v.len() == 1 => {
                Ok(spread(v.into_iter().map(|x| x as i32 as f64).collect()))
            }
            _ => self.get_all(core, access),
        }
    }

    /// `terminateSimulation` from `function` (called at `at`) at the time `reached`,
    /// reported as FMI 2.0 reports it: a Discard, with `terminated_status` true and
    /// `last_successful_time` `reached`.
    pub(super) fn terminated_at(&mut self, core: &mut Core, function: &'static str, at: f64, reached: f64) -> Error {
        core.time = reached;
        self.terminate_requested = Some(reached);
        Error::Fmi {
            instance: core.name.clone(),
            function,
            status: Status::Discard,
            time: Some(at),
            log: format!("terminateSimulation at t = {reached} s"),
        }
    }

    /// The event a Co-Simulation `fmi3DoStep` asked for (`eventHandlingNeeded`) at `time`:
    /// Event Mode, `fmi3UpdateDiscreteStates` until no new discrete states are needed (at
    /// most 1000 times), back to Step Mode. `Some(time)` when the FMU asked to terminate.
    fn cs_event(&mut self, core: &mut Core, time: f64) -> Result<Option<f64>> {
        self.enter_event_mode(core)?;
        self.settle_event(core, time)
    }

    /// In Event Mode at `time`: `fmi3UpdateDiscreteStates` until no new discrete states are
    /// needed (at most 1000 times), then `fmi3EnterStepMode`. `Some(time)` when the FMU asked
    /// to terminate.
    pub(super) fn settle_event(&mut self, core: &mut Core, time: f64) -> Result<Option<f64>> {
        for _ in 0..1000 {
            let info = self.new_discrete_states(core)?;
            if info.terminate_simulation != 0 {
                return Ok(Some(time));
            }
            if info.new_discrete_states_needed == 0 {
                let f = f3!(core, self.a, enter_step_mode, "fmi3EnterStepMode");
                let c = core.component;
                call!(core, "fmi3EnterStepMode", Some(time), f(c))?;
                return Ok(None);
            }
        }
        core.state = InstanceState::Errored;
        Err(core.error(
            "fmi3UpdateDiscreteStates",
            time,
            "asked for new discrete states 1000 times in one event".into(),
        ))
    }
}

impl Fmi3 {
    #[inline]
    fn fmu_get_real(&mut self, core: &mut Core, vrs: &[u32], values: &mut [f64]) -> Result<()> {
        let (c, f) = (core.component, self.a.functions.get_float64);
        if !self.any_special(vrs) {
            return call!(
                core,
                "fmi3GetFloat64",
                None,
                f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len())
            );
        }
        let mut array = None;
        for (vr, value) in vrs.iter().zip(values.iter_mut()) {
            match self.special(*vr) {
                Some(access) => *value = self.element_of_call(core, access, &mut array)?,
                None => call!(core, "fmi3GetFloat64", None, f(c, vr, 1, value, 1))?,
            }
        }
        Ok(())
    }

    #[inline]
    fn fmu_get_integer(&mut self, core: &mut Core, vrs: &[u32], values: &mut [i32]) -> Result<()> {
        let c = core.component;
        if !self.any_special(vrs) {
            let f = f3!(core, self.a, get_int32, "fmi3GetInt32");
            return call!(core, "fmi3GetInt32", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len()));
        }
        let get32 = self.a.functions.get_int32;
        let mut array = None;
        for (vr, value) in vrs.iter().zip(values.iter_mut()) {
            match self.special(*vr) {
                Some(access) => {
                    let x = self.element_of_call(core, access, &mut array)?;
                    // the view's Integers are Int8 .. Int32 and Enumerations of i32 items
                    *value = i32::try_from(x as i64).map_err(|_| Error::Fmi {
                        instance: core.name.clone(),
                        function: "fmi3GetInt64",
                        status: Status::Error,
                        time: Some(core.time),
                        log: format!("value {x} of value reference {} is outside the Integer range", access.vr),
                    })?;
                }
                None => {
                    let f = core.optional(get32, "fmi3GetInt32")?;
                    call!(core, "fmi3GetInt32", None, f(c, vr, 1, value, 1))?
                }
            }
        }
        Ok(())
    }

    #[inline]
    fn fmu_get_boolean(&mut self, core: &mut Core, vrs: &[u32], values: &mut [i32]) -> Result<()> {
        if self.any_special(vrs) {
            let mut array = None;
            for (vr, value) in vrs.iter().zip(values.iter_mut()) {
                *value = match self.special(*vr) {
                    Some(access) => self.element_of_call(core, access, &mut array)? as i32,
                    None => {
                        let mut one = [0];
                        self.fmu_get_boolean(core, &[*vr], &mut one)?;
                        one[0]
                    }
                };
            }
            return Ok(());
        }
        let c = core.component;
        let f = f3!(core, self.a, get_boolean, "fmi3GetBoolean");
        let mut bytes = std::mem::take(&mut self.bytes);
        bytes.clear();
        bytes.resize(vrs.len(), 0);
        let r = call!(core, "fmi3GetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), bytes.as_mut_ptr(), bytes.len()));
        for (v, b) in values.iter_mut().zip(&bytes) {
            *v = (*b != 0) as i32;
        }
        self.bytes = bytes;
        r
    }

    #[inline]
    fn fmu_set_real(&mut self, core: &mut Core, vrs: &[u32], values: &[f64]) -> Result<()> {
        let (c, f) = (core.component, self.a.functions.set_float64);
        if !self.any_special(vrs) {
            return call!(core, "fmi3SetFloat64", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()));
        }
        for (vr, value) in vrs.iter().zip(values) {
            match self.special(*vr) {
                Some(access) => self.set_element(core, access, *value)?,
                None => call!(core, "fmi3SetFloat64", None, f(c, vr, 1, value, 1))?,
            }
        }
        Ok(())
    }

    #[inline]
    fn fmu_set_integer(&mut self, core: &mut Core, vrs: &[u32], values: &[i32]) -> Result<()> {
        let c = core.component;
        if !self.any_special(vrs) {
            let f = f3!(core, self.a, set_int32, "fmi3SetInt32");
            return call!(core, "fmi3SetInt32", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()));
        }
        let set32 = self.a.functions.set_int32;
        for (vr, value) in vrs.iter().zip(values) {
            match self.special(*vr) {
                Some(access) => self.set_element(core, access, *value as f64)?,
                None => {
                    let f = core.optional(set32, "fmi3SetInt32")?;
                    call!(core, "fmi3SetInt32", None, f(c, vr, 1, value, 1))?
                }
            }
        }
        Ok(())
    }

    #[inline]
    fn fmu_set_boolean(&mut self, core: &mut Core, vrs: &[u32], values: &[i32]) -> Result<()> {
        if self.any_special(vrs) {
            for (vr, value) in vrs.iter().zip(values) {
                match self.special(*vr) {
                    Some(access) => self.set_element(core, access, (*value != 0) as i32 as f64)?,
                    None => self.fmu_set_boolean(core, &[*vr], &[*value])?,
                }
            }
            return Ok(());
        }
        let c = core.component;
        let f = f3!(core, self.a, set_boolean, "fmi3SetBoolean");
        let mut bytes = std::mem::take(&mut self.bytes);
        bytes.clear();
        bytes.extend(values.iter().map(|v| (*v != 0) as u8));
        let r = call!(core, "fmi3SetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), bytes.as_ptr(), bytes.len()));
        self.bytes = bytes;
        r
    }

    /// A get of the view's `vrs` on an FMU with clocked variables: while running, a
    /// clocked variable's value is the one held since its clocks' last activation (the
    /// FMU refuses the access outside it); the others are read from the FMU by `fmu_get`,
    /// in one call. In Initialization Mode everything is read, the clocked values kept as
    /// held.
    fn get_held<T: HeldNumber>(
        &mut self,
        core: &mut Core,
        vrs: &[u32],
        values: &mut [T],
        fmu_get: fn(&mut Fmi3, &mut Core, &[u32], &mut [T]) -> Result<()>,
    ) -> Result<()> {
        let at = |me: &Fmi3, vr: u32| me.clocked.clocked(vr, me.special(vr));
        if core.state != InstanceState::Running {
            fmu_get(self, core, vrs, values)?;
            for (vr, value) in vrs.iter().zip(values.iter()) {
                if let Some((slot, element)) = at(self, *vr) {
                    self.clocked.hold_element(slot, element, value.to_held());
                }
            }
            return Ok(());
        }
        // a clocked variable is answered from its held value unless one of its clocks is
        // active (then read, and held); the rest (no allocation when nothing is held: the
        // common case of a plain read, or of the reads in an open clock event)
        let held = |me: &Fmi3, vr: u32| {
            at(me, vr)
                .filter(|(slot, _)| !me.clocked.is_active(*slot))
                .and_then(|(slot, element)| me.clocked.held(slot, element))
        };
        if vrs.iter().all(|vr| held(self, *vr).is_none()) {
            fmu_get(self, core, vrs, values)?;
            self.hold_read(vrs, values);
            return Ok(());
        }
        let (mut free_vrs, mut free_at) = (Vec::new(), Vec::new());
        for (k, vr) in vrs.iter().enumerate() {
            match held(self, *vr) {
                Some(held) => values[k] = T::from_held(held),
                None => {
                    free_vrs.push(*vr);
                    free_at.push(k);
                }
            }
        }
        let mut free_values: Vec<T> = free_at.iter().map(|k| values[*k]).collect();
        fmu_get(self, core, &free_vrs, &mut free_values)?;
        self.hold_read(&free_vrs, &free_values);
        for (k, value) in free_at.into_iter().zip(free_values) {
            values[k] = value;
        }
        Ok(())
    }

    /// The clocked variables among `vrs` whose clocks are active, just read from or set
    /// to the FMU, held.
    fn hold_read<T: HeldNumber>(&mut self, vrs: &[u32], values: &[T]) {
        if self.ticked_inputs.is_empty() {
            return;
        }
        for (vr, value) in vrs.iter().zip(values) {
            if let Some((slot, element)) = self.clocked.clocked(*vr, self.special(*vr)) {
                if self.clocked.is_active(slot) {
                    self.clocked.hold_element(slot, element, value.to_held());
                }
            }
        }
    }

    /// A set of the view's `vrs` on an FMU with clocked variables: while running, a set of
    /// a clocked input is queued to its clocks' next activation (the FMU refuses it
    /// outside one); the others are set by `fmu_set`, in one call. In Initialization Mode
    /// everything is set, the clocked values kept as held.
    fn set_queued<T: HeldNumber>(
        &mut self,
        core: &mut Core,
        vrs: &[u32],
        values: &[T],
        fmu_set: fn(&mut Fmi3, &mut Core, &[u32], &[T]) -> Result<()>,
    ) -> Result<()> {
        let at = |me: &Fmi3, vr: u32| me.clocked.clocked(vr, me.special(vr));
        if core.state != InstanceState::Running {
            fmu_set(self, core, vrs, values)?;
            for (vr, value) in vrs.iter().zip(values) {
                if let Some((slot, element)) = at(self, *vr) {
                    self.clocked.hold_element(slot, element, value.to_held());
                }
            }
            return Ok(());
        }
        // no settable clocked variable (a sampled controller's clocked outputs, say): nothing
        // to queue or hold, the set goes to the FMU without a lookup per value reference
        if !self.clocked.has_settable() {
            return fmu_set(self, core, vrs, values);
        }
        // a clocked input whose clocks are inactive is queued; every other variable set (a
        // clocked input of an active clock, in an open clock event, held too)
        let queued = |me: &Fmi3, vr: u32| {
            at(me, vr).filter(|(slot, _)| me.clocked.is_input(*slot) && !me.clocked.is_active(*slot))
        };
        if vrs.iter().all(|vr| queued(self, *vr).is_none()) {
            fmu_set(self, core, vrs, values)?;
            self.hold_read(vrs, values);
            return Ok(());
        }
        let (mut free_vrs, mut free_values) = (Vec::new(), Vec::new());
        for (vr, value) in vrs.iter().zip(values) {
            match queued(self, *vr) {
                Some((slot, element)) => self.clocked.queue(slot, element, value.to_held()),
                None => {
                    free_vrs.push(*vr);
                    free_values.push(*value);
                }
            }
        }
        if free_vrs.is_empty() {
            return Ok(());
        }
        fmu_set(self, core, &free_vrs, &free_values)?;
        self.hold_read(&free_vrs, &free_values);
        Ok(())
    }

    /// The queued sets of the clocked inputs of the clocks `active` applied (each as one
    /// set of the whole variable), the values held.
    pub(super) fn apply_queued(&mut self, core: &mut Core, active: &[u32]) -> Result<()> {
        if self.clocked.is_empty() || active.is_empty() {
            return Ok(());
        }
        for (slot, access, values) in self.clocked.take_queued(active) {
            self.set_all(core, access, &values)?;
            self.clocked.hold(slot, values);
        }
        Ok(())
    }

    /// The clocked variables of the clocks `active` that the master reads (all but inputs)
    /// read and held until the next activation.
    pub(super) fn read_clocked(&mut self, core: &mut Core, active: &[u32]) -> Result<()> {
        if self.clocked.is_empty() || active.is_empty() {
            return Ok(());
        }
        let mut plan = self.clocked.take_plan(active);
        let outcome = self.read_planned(core, &mut plan);
        self.clocked.put_plan(plan);
        outcome
    }

    fn read_planned(&mut self, core: &mut Core, plan: &mut super::clocked::ReadPlan) -> Result<()> {
        if !plan.scalars.is_empty() {
            let (vrs, values) = (&plan.scalars, &mut plan.values);
            let (c, f) = (core.component, self.a.functions.get_float64);
            call!(core, "fmi3GetFloat64", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len()))?;
            for (slot, value) in plan.scalar_slots.iter().zip(values.iter()) {
                self.clocked.hold_element(*slot, 0, *value);
            }
        }
        for (slot, access) in plan.others.iter() {
            let values = self.get_all(core, *access)?;
            self.clocked.hold(*slot, values);
        }
        Ok(())
    }

    /// In Event Mode at `time`: which output clocks ticked (`fmi3GetClock`) and the
    /// intervals of the input clocks the FMU gives (`fmi3GetIntervalDecimal`), kept for
    /// `take_output_ticks` and `take_intervals`.
    fn read_output_clocks(&mut self, core: &mut Core, time: f64) -> Result<()> {
        let fixed = if self.fixed_read { &[][..] } else { &self.fixed_clocks[..] };
        if !self.interval_clocks.is_empty() || !fixed.is_empty() {
            let vrs: Vec<u32> = self.interval_clocks.iter().chain(fixed).copied().collect();
            self.fixed_read = true;
            let intervals = super::core::ClockCalls::get_intervals(self, core, &vrs, false)?;
            self.intervals.extend(vrs.into_iter().zip(intervals).map(|(vr, i)| (time, vr, i)));
        }
        if self.output_clocks.is_empty() {
            // (the list's buffer kept for the next event)
            let mut active = std::mem::take(&mut self.ticked_inputs);
            self.clocked.deactivate();
            let outcome = self.read_clocked(core, &active);
            active.clear();
            self.ticked_inputs = active;
            return outcome;
        }
        let vrs = self.output_clocks.clone();
        let mut ticks = vec![false; vrs.len()];
        ClockCalls::get_clocks(self, core, &vrs, &mut ticks)?;
        let opened = std::mem::take(&mut self.opened_outputs);
        let ticked: Vec<u32> =
            vrs.into_iter().zip(ticks).filter(|(vr, t)| *t && !opened.contains(vr)).map(|(vr, _)| vr).collect();
        for vr in &ticked {
            self.output_ticks.push(super::core::OutputTick { time, value_reference: *vr });
        }
        // the clocked variables of the clocks that ticked in this event, read as it settled
        let mut active = std::mem::take(&mut self.ticked_inputs);
        self.clocked.deactivate();
        active.extend(opened);
        active.extend(ticked);
        self.read_clocked(core, &active)
    }
}

/// The error of a Scheduled Execution call on an instance of another interface.
#[cold]
pub(super) fn not_scheduled(name: &str) -> Error {
    Error::Instance { name: name.into(), reason: "it is not instantiated for Scheduled Execution (--interface se)" }
}

/// The error of an exact read or set of `vr`, which is no 64-bit integer or Binary.
#[cold]
fn not_exact(core: &Core, vr: u32, value: String) -> Error {
    Error::InvalidValue {
        variable: format!("{}.<value reference {vr}>", core.name),
        value,
        reason: "not an Int64, UInt64 or Binary of the FMU's: its value is the view's".into(),
    }
}

/// The typed getters and setters of [`Calls`]: the FMU's own calls, but while the instance
/// runs with clocked variables, their values held between ticks (read) and queued until
/// their clock ticks (set). (getter, setter, value type, the FMU's getter and setter) a row.
macro_rules! get_set {
    ($($get:ident, $set:ident, $t:ty, $fmu_get:ident, $fmu_set:ident;)*) => {$(
        #[inline]
        fn $get(&mut self, core: &mut Core, vrs: &[u32], values: &mut [$t]) -> Result<()> {
            if !self.clocked.is_empty() && core.state == InstanceState::Running {
                return self.get_held(core, vrs, values, Self::$fmu_get);
            }
            self.$fmu_get(core, vrs, values)
        }

        #[inline]
        fn $set(&mut self, core: &mut Core, vrs: &[u32], values: &[$t]) -> Result<()> {
            if !self.clocked.is_empty() && core.state == InstanceState::Running {
                return self.set_queued(core, vrs, values, Self::$fmu_set);
            }
            self.$fmu_set(core, vrs, values)
        }
    )*};
}

impl Calls for Fmi3 {
    /// The instantiate function of `interface`.
    fn instantiate_function(&self, interface: Interface) -> &'static str {
        match interface {
            Interface::CoSimulation => "fmi3InstantiateCoSimulation",
            Interface::ModelExchange => "fmi3InstantiateModelExchange",
            Interface::ScheduledExecution => "fmi3InstantiateScheduledExecution",
        }
    }

    /// `fmi3InstantiateCoSimulation` (early return allowed, event mode used when the FMU
    /// has it, no intermediate update) or `fmi3InstantiateModelExchange`, logging off, the
    /// messages to `log` (which outlives the instance).
    fn instantiate(
        &self,
        fmu: &Fmu,
        name: &str,
        name_c: &CString,
        _callbacks: &crate::c_types::CallbackFunctions,
        log: &LogSink,
    ) -> Result<Component> {
        let a = &self.a;
        let environment = log as *const LogSink as *mut c_void;
        let logger: Option<fmi_sys::fmi3::Fmi3LogMessageCallback> = Some(crate::log::log_message);
        let missing = |symbol| Error::MissingSymbol { path: fmu.source.clone(), symbol };
        let function = self.instantiate_function(fmu.interface);
        let component = match fmu.interface {
            Interface::CoSimulation => {
                let f = a.functions.instantiate_co_simulation.ok_or(missing(function))?;
                let _mark = crate::call_site::enter(name, &fmu.source, function, 0.0);
                // SAFETY: every pointer is valid for the call; the log outlives the instance.
                unsafe {
                    f(
                        name_c.as_ptr(),
                        a.token.as_ptr(),
                        a.resource_path.as_ptr(),
                        0,
                        0,
                        self.event_mode.get() as u8,
                        1,
                        std::ptr::null(),
                        0,
                        environment,
                        logger,
                        None,
                    )
                }
            }
            Interface::ModelExchange => {
                let f = a.functions.instantiate_model_exchange.ok_or(missing(function))?;
                let _mark = crate::call_site::enter(name, &fmu.source, function, 0.0);
                // SAFETY: as above.
                unsafe { f(name_c.as_ptr(), a.token.as_ptr(), a.resource_path.as_ptr(), 0, 0, environment, logger) }
            }
            Interface::ScheduledExecution => match self.scheduled.as_deref() {
                Some(scheduled) => self.instantiate_scheduled(fmu, name, name_c, log, scheduled)?,
                None => return Err(not_scheduled(name)),
            },
        };
        if component.is_null() && fmu.interface == Interface::CoSimulation && self.event_mode.get() {
            // an FMU that declares hasEventMode may still refuse eventModeUsed (the Reference
            // FMUs' Roberts does): a second try without it, the run then stepping without
            // Event Mode as for an FMU without it
            self.event_mode.set(false);
            return self.instantiate(fmu, name, name_c, _callbacks, log);
        }
        if component.is_null() {
            return Err(Error::Instantiate { instance: name.into(), function, log: log.recent_problems() });
        }
        Ok(component)
    }

    /// `fmi3Instantiate*` in the host of `channel`; the status.
    fn instantiate_in(
        &self,
        fmu: &Fmu,
        channel: &mut crate::isolate::channel::Channel,
        name_c: &CString,
    ) -> Result<i32> {
        if fmu.interface == Interface::ScheduledExecution {
            return Err(Error::Instance {
                name: String::from_utf8_lossy(name_c.as_bytes()).into_owned(),
                reason: "Scheduled Execution is not run in a host process: the FMU calls this process back (clockUpdate, lockPreemption) from inside fmi3ActivateModelPartition, and a host answers one call at a time: run it without isolation",
            });
        }
        let event_mode = (fmu.interface == Interface::CoSimulation).then_some(self.event_mode.get());
        Ok(crate::isolate::proxy3::instantiate_in(channel, name_c, &self.a.token, &self.a.resource_path, event_mode))
    }

    fn reset_name(&self) -> &'static str {
        "fmi3Reset"
    }

    fn configure(&mut self, core: &mut Core) -> Result<()> {
        self.configure_structural(core)
    }

    fn activate_model_partition(&mut self, core: &mut Core, clock: u32, time: f64) -> Result<bool> {
        let scheduled = self.scheduled.take().ok_or_else(|| not_scheduled(&core.name))?;
        let r = self.activate(core, &scheduled, clock, time);
        self.scheduled = Some(scheduled);
        r
    }

    fn reconfigure(&mut self, core: &mut Core, values: &[(&str, f64)]) -> Result<()> {
        self.reconfigure_between_steps(core, values)
    }

    fn absent_element(&self, vr: u32) -> bool {
        !self.resized.is_empty() && self.special(vr).is_some_and(|access| self.now(access).1.is_none())
    }

    fn countdown_interval(&mut self, core: &mut Core, clock: u32) -> Result<Option<f64>> {
        self.scheduled.as_ref().ok_or_else(|| not_scheduled(&core.name))?;
        self.changed_interval(core, clock)
    }

    fn output_clock_ticked(&mut self, core: &mut Core, clock: u32) -> Result<bool> {
        self.scheduled.as_ref().ok_or_else(|| not_scheduled(&core.name))?;
        self.clock_ticked(core, clock)
    }

    fn setup_function(&self) -> &'static str {
        "fmi3EnterInitializationMode"
    }

    fn setup_experiment(&mut self, _: &mut Core, tolerance: Option<f64>, start: f64, stop: Option<f64>) -> Result<()> {
        self.experiment = (tolerance, start, stop);
        Ok(())
    }

    fn enter_initialization_mode(&mut self, core: &mut Core) -> Result<()> {
        let (c, f) = (core.component, self.a.functions.enter_initialization_mode);
        let (tolerance, start, stop) = self.experiment;
        call!(
            core,
            "fmi3EnterInitializationMode",
            Some(start),
            f(c, tolerance.is_some() as u8, tolerance.unwrap_or(0.0), start, stop.is_some() as u8, stop.unwrap_or(0.0))
        )
    }

    fn exit_initialization_mode(&mut self, core: &mut Core) -> Result<()> {
        // the clocked variables the master reads hold what initialization computed until
        // their clocks' first ticks (read while Initialization Mode allows it)
        for (slot, access) in self.clocked.unheld() {
            let values = self.get_all(core, access)?;
            self.clocked.hold(slot, values);
        }
        let (c, f) = (core.component, self.a.functions.exit_initialization_mode);
        call!(core, "fmi3ExitInitializationMode", None, f(c))?;
        // instantiated with eventModeUsed, the FMU is in Event Mode now (FMI 3.0's
        // Co-Simulation state machine): its discrete states are settled and it enters Step
        // Mode before the first fmi3DoStep
        if self.event_mode.get() {
            let time = core.time;
            if let Some(t) = self.settle_event(core, time)? {
                return Err(self.terminated_at(core, "fmi3UpdateDiscreteStates", t, t));
            }
        }
        Ok(())
    }

    fn terminate(&mut self, core: &mut Core) -> Result<()> {
        let (c, f) = (core.component, self.a.functions.terminate);
        call!(core, "fmi3Terminate", None, f(c))
    }

    fn reset_function(&self, core: &Core) -> Result<ResetFunction> {
        core.optional(self.a.functions.reset, "fmi3Reset")
    }

    fn forget_run(&mut self) {
        self.clocked.forget_run(&self.a.description);
        self.ticked_inputs.clear();
        self.opened_outputs.clear();
        self.fixed_read = false;
        self.output_ticks.clear();
        self.intervals.clear();
        self.terminate_requested = None;
    }

    get_set! {
        get_real, set_real, f64, fmu_get_real, fmu_set_real;
        get_integer, set_integer, i32, fmu_get_integer, fmu_set_integer;
        get_boolean, set_boolean, i32, fmu_get_boolean, fmu_set_boolean;
    }

    fn get_string(&mut self, core: &mut Core, vr: u32) -> Result<*const c_char> {
        let mut p: *const c_char = std::ptr::null();
        let c = core.component;
        let f = f3!(core, self.a, get_string, "fmi3GetString");
        call!(core, "fmi3GetString", None, f(c, &vr, 1, &mut p, 1))?;
        Ok(p)
    }

    fn set_string(&mut self, core: &mut Core, vr: u32, p: *const c_char) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, set_string, "fmi3SetString");
        call!(core, "fmi3SetString", None, f(c, &vr, 1, &p, 1))
    }

    fn get_exact(&mut self, core: &mut Core, vr: u32) -> Result<crate::fmi3::Exact> {
        use crate::fmi3::Exact;
        use model_description::fmi3::ValueType as T;
        let Some(access) = self.special(vr) else { return Err(not_exact(core, vr, String::new())) };
        let (c, a, n, k) = (core.component, &*self.a, access.count, access.element);
        let fmu_vr = access.vr;
        Ok(match access.value_type {
            T::Int64 => {
                let f = f3!(core, a, get_int64, "fmi3GetInt64");
                let mut buf = vec![0i64; n];
                call!(core, "fmi3GetInt64", None, f(c, &fmu_vr, 1, buf.as_mut_ptr(), n))?;
                Exact::Integer(i128::from(buf[k]))
            }
            T::UInt64 => {
                let f = f3!(core, a, get_uint64, "fmi3GetUInt64");
                let mut buf = vec![0u64; n];
                call!(core, "fmi3GetUInt64", None, f(c, &fmu_vr, 1, buf.as_mut_ptr(), n))?;
                Exact::Integer(i128::from(buf[k]))
            }
            T::Binary => {
                let f = f3!(core, a, get_binary, "fmi3GetBinary");
                let mut sizes = vec![0usize; n];
                let mut data: Vec<*const u8> = vec![std::ptr::null(); n];
                call!(core, "fmi3GetBinary", None, f(c, &fmu_vr, 1, sizes.as_mut_ptr(), data.as_mut_ptr(), n))?;
                let (p, size) = (data[k], sizes[k]);
                if p.is_null() || size == 0 {
                    Exact::Bytes(Vec::new())
                } else {
                    // SAFETY: the FMU returned `size` bytes at `p`, valid until its next call.
                    Exact::Bytes(unsafe { std::slice::from_raw_parts(p, size) }.to_vec())
                }
            }
            _ => return Err(not_exact(core, vr, String::new())),
        })
    }

    fn set_exact_integer(&mut self, core: &mut Core, vr: u32, value: i128) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        match self.special(vr) {
            Some(a) if a.count == 1 && matches!(a.value_type, T::Int64 | T::UInt64) => self.set_wide(core, a, &[value]),
            Some(a) if matches!(a.value_type, T::Int64 | T::UInt64) => self.set_wide_element(core, a, value),
            _ => Err(not_exact(core, vr, value.to_string())),
        }
    }

    /// An early return (`earlyReturn` with `lastSuccessfulTime` before the step's end) is
    /// continued from the time reached until the step's end; a return that makes no
    /// progress is an error naming the time.
    fn do_step(&mut self, core: &mut Core, time: f64, step: f64) -> Result<()> {
        let f = f3!(core, self.a, do_step, "fmi3DoStep");
        let c = core.component;
        let end = time + step;
        let mut at = time;
        // each early return must make progress; a bound on the returns per step besides,
        // so that an FMU creeping forward by ulps cannot hold the run forever
        for _ in 0..1000 {
            let (mut event, mut terminate, mut early, mut reached) = (0u8, 0u8, 0u8, at);
            call!(
                core,
                "fmi3DoStep",
                Some(at),
                f(c, at, end - at, 1, &mut event, &mut terminate, &mut early, &mut reached)
            )?;
            if terminate != 0 {
                let reached = if early != 0 && reached.is_finite() { reached } else { end };
                return Err(self.terminated_at(core, "fmi3DoStep", at, reached));
            }
            if event != 0 && self.event_mode.get() {
                let reached = if early != 0 { reached } else { end };
                core.time = reached;
                if let Some(t) = self.cs_event(core, reached)? {
                    return Err(self.terminated_at(core, "fmi3UpdateDiscreteStates", t, t));
                }
            }
            if early == 0 {
                core.time = end;
                return Ok(());
            }
            // an early return at the time already reached is progress when it was to handle
            // an event there (Event Mode was entered and left above): the next fmi3DoStep
            // goes on from the settled discrete states
            let settled_here = event != 0 && self.event_mode.get() && reached == at;
            let progressed = settled_here || (reached > at && reached <= end);
            if !progressed {
                core.state = InstanceState::Errored;
                return Err(core.error(
                    "fmi3DoStep",
                    at,
                    format!(
                        "returned early at lastSuccessfulTime = {reached} s, no progress from {at} s toward the step's end {end} s"
                    ),
                ));
            }
            if reached == end {
                core.time = end;
                return Ok(());
            }
            at = reached;
        }
        core.state = InstanceState::Errored;
        Err(core.error("fmi3DoStep", at, format!("returned early 1000 times in the step from {time} s to {end} s")))
    }

    fn posted_step(&self, time: f64, step: f64) -> Option<(crate::isolate::protocol::Op, f64)> {
        // the arguments of the first fmi3DoStep of `do_step`
        self.a.functions.do_step.is_some().then_some((crate::isolate::protocol::Op::DoStep3, (time + step) - time))
    }

    fn get_state(&mut self, core: &mut Core, s: &mut *mut c_void) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, get_fmu_state, "fmi3GetFMUState");
        call!(core, "fmi3GetFMUState", None, f(c, s))
    }

    fn set_state(&mut self, core: &mut Core, s: *mut c_void) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, set_fmu_state, "fmi3SetFMUState");
        call!(core, "fmi3SetFMUState", None, f(c, s))
    }

    fn free_state(&mut self, core: &mut Core, s: &mut *mut c_void) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, free_fmu_state, "fmi3FreeFMUState");
        call!(core, "fmi3FreeFMUState", None, f(c, s))
    }

    #[inline]
    fn set_time(&mut self, core: &mut Core, time: f64) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, set_time, "fmi3SetTime");
        call!(core, "fmi3SetTime", Some(time), f(c, time))
    }

    #[inline]
    fn set_continuous_states(&mut self, core: &mut Core, x: &[f64]) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, set_continuous_states, "fmi3SetContinuousStates");
        call!(core, "fmi3SetContinuousStates", None, f(c, x.as_ptr(), x.len()))
    }

    fn get_continuous_states(&mut self, core: &mut Core, x: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, get_continuous_states, "fmi3GetContinuousStates");
        call!(core, "fmi3GetContinuousStates", None, f(c, x.as_mut_ptr(), x.len()))
    }

    #[inline]
    fn get_derivatives(&mut self, core: &mut Core, dx: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, get_continuous_state_derivatives, "fmi3GetContinuousStateDerivatives");
        call!(core, "fmi3GetContinuousStateDerivatives", None, f(c, dx.as_mut_ptr(), dx.len()))
    }

    #[inline]
    fn get_event_indicators(&mut self, core: &mut Core, z: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, get_event_indicators, "fmi3GetEventIndicators");
        call!(core, "fmi3GetEventIndicators", None, f(c, z.as_mut_ptr(), z.len()))
    }

    fn has_directional_derivative(&self) -> bool {
        self.a.functions.get_directional_derivative.is_some()
    }

    fn get_directional_derivative(&mut self, core: &mut Core, seed: Seed, dv_unknown: &mut [f64]) -> Result<()> {
        let Seed { unknowns, knowns, dv_known } = seed;
        let c = core.component;
        let f = f3!(core, self.a, get_directional_derivative, "fmi3GetDirectionalDerivative");
        call!(
            core,
            "fmi3GetDirectionalDerivative",
            None,
            f(
                c,
                unknowns.as_ptr(),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                dv_known.as_ptr(),
                dv_known.len(),
                dv_unknown.as_mut_ptr(),
                dv_unknown.len()
            )
        )
    }

    fn enter_event_mode(&mut self, core: &mut Core) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, enter_event_mode, "fmi3EnterEventMode");
        call!(core, "fmi3EnterEventMode", None, f(c))
    }

    /// `fmi3UpdateDiscreteStates`, its outputs as the FMI 2.0 event info
    /// (`discreteStatesNeedUpdate` is `newDiscreteStatesNeeded`).
    fn new_discrete_states(&mut self, core: &mut Core) -> Result<EventInfo> {
        let c = core.component;
        let mut info = EventInfo::default();
        let f = f3!(core, self.a, update_discrete_states, "fmi3UpdateDiscreteStates");
        let (mut update, mut terminate, mut nominals, mut values, mut defined) = (0u8, 0u8, 0u8, 0u8, 0u8);
        let mut next = 0.0;
        call!(
            core,
            "fmi3UpdateDiscreteStates",
            None,
            f(c, &mut update, &mut terminate, &mut nominals, &mut values, &mut defined, &mut next)
        )?;
        info.new_discrete_states_needed = (update != 0) as c_int;
        info.terminate_simulation = (terminate != 0) as c_int;
        info.nominals_of_continuous_states_changed = (nominals != 0) as c_int;
        info.values_of_continuous_states_changed = (values != 0) as c_int;
        info.next_event_time_defined = (defined != 0) as c_int;
        info.next_event_time = next;
        // the event settled: the output clocks and the intervals the FMU gives read while
        // still in Event Mode (both interface types)
        if update == 0 && terminate == 0 {
            let time = core.time;
            self.read_output_clocks(core, time)?;
        }
        Ok(info)
    }

    fn enter_continuous_time_mode(&mut self, core: &mut Core) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, enter_continuous_time_mode, "fmi3EnterContinuousTimeMode");
        call!(core, "fmi3EnterContinuousTimeMode", None, f(c))
    }

    fn completed_integrator_step(&mut self, core: &mut Core) -> Result<(bool, bool)> {
        let c = core.component;
        let f = f3!(core, self.a, completed_integrator_step, "fmi3CompletedIntegratorStep");
        let (mut event, mut terminate) = (0u8, 0u8);
        call!(core, "fmi3CompletedIntegratorStep", None, f(c, 1, &mut event, &mut terminate))?;
        Ok((event != 0, terminate != 0))
    }

    /// Whether the last `fmi3DoStep` said `terminateSimulation`.
    fn terminated_status(&mut self, _: &mut Core) -> Option<bool> {
        Some(self.terminate_requested.is_some())
    }

    /// The `lastSuccessfulTime` of the `fmi3DoStep` that said `terminateSimulation`.
    fn last_successful_time(&mut self, _: &mut Core) -> Option<f64> {
        self.terminate_requested
    }

    fn free_functions(&self) -> (Option<FreeStateFunction>, FreeInstanceFunction, &'static str) {
        (self.a.functions.free_fmu_state, self.a.functions.free_instance, "fmi3FreeInstance")
    }

    fn is_fmi3(&self) -> bool {
        true
    }

    fn clock_calls(&mut self) -> Option<&mut dyn ClockCalls> {
        Some(self)
    }
}
