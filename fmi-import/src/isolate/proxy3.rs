//! The FMI 3.0 function table of an isolated instance: each function, its instance being
//! the instance's [`Channel`], carried to the host as one call (the host calls the FMU's
//! FMI 3.0 function; see `host.rs`). The Booleans, typed values and strings go through the
//! region as for FMI 2.0 (`proxy.rs`); sets of scalars are queued for the next call as
//! FMI 2.0's are (a set of array values is a call), and Reals are read with a call (no
//! prefetch).

#![allow(clippy::missing_safety_doc)] // called only by `Instance` through the function table

use super::channel::Channel;
use super::protocol::{clock_arrays, fmi3_type_code, fmi3_width, Op};
use super::proxy::{ch, fits, plain, slice, slice_mut, state_call, vrs_into};
use fmi_sys::fmi3::{
    fmi3Boolean, fmi3Clock, fmi3FMUState, fmi3Instance, fmi3IntervalQualifier, fmi3Status, fmi3String, Fmi3Functions,
};
use model_description::fmi3::ValueType;
use std::ffi::{c_char, CStr};

type Component = fmi3Instance;

unsafe extern "C" fn get_version() -> *const c_char {
    c"3.0".as_ptr()
}

/// `fmi3InstantiateCoSimulation` (`event_mode`: `eventModeUsed`) or, `None`,
/// `fmi3InstantiateModelExchange` in the host of `channel`; the fmi3 status.
pub(crate) fn instantiate_in(
    channel: &mut Channel,
    name: &CStr,
    token: &CStr,
    resources: &CStr,
    event_mode: Option<bool>,
) -> i32 {
    let (op, flag) = match event_mode {
        Some(event_mode) => (Op::Instantiate3, i64::from(event_mode)),
        None => (Op::InstantiateModelExchange3, 0),
    };
    super::proxy::instantiate_with(channel, op, [name, token, resources], flag)
}

unsafe extern "C" fn free_instance(c: Component) {
    let _ = ch(c).call(Op::Free);
}

unsafe extern "C" fn enter_initialization_mode(
    c: Component,
    tol_defined: fmi3Boolean,
    tol: f64,
    start: f64,
    stop_defined: fmi3Boolean,
    stop: f64,
) -> fmi3Status {
    super::proxy::experiment(c, Op::EnterInitializationMode3, [tol_defined != 0, stop_defined != 0], [tol, start, stop])
}

plain!(exit_initialization_mode, Op::ExitInitializationMode3);
plain!(terminate, Op::Terminate3);
plain!(reset, Op::Reset3);
plain!(enter_event_mode, Op::EnterEventMode3);
plain!(enter_step_mode, Op::EnterStepMode3);
plain!(enter_continuous_time_mode, Op::EnterContinuousTimeMode3);

/// A typed get or set of `n_values` values of `ty` at n references, in one call.
unsafe fn typed(
    c: Component,
    vr: *const u32,
    n: usize,
    values: *mut u8,
    n_values: usize,
    ty: ValueType,
    set: bool,
) -> fmi3Status {
    let channel = ch(c);
    let bytes = fmi3_width(ty) * n_values;
    if !fits(channel, (4 * n).div_ceil(8) * 8 + bytes) {
        return 3;
    }
    let at = vrs_into(channel, slice(vr, n));
    if set {
        channel.data()[at..at + bytes].copy_from_slice(slice(values as *const u8, bytes));
    }
    let h = channel.header();
    h.n = n as u64;
    h.i = [fmi3_type_code(ty), n_values as i64, 0, 0];
    let s = channel.call(if set { Op::Set3 } else { Op::Get3 });
    if !set {
        slice_mut(values, bytes).copy_from_slice(&channel.data()[at..at + bytes]);
    }
    s
}

/// The kind of a queued FMI 3.0 set of `ty` (FMI 2.0's kinds are 0, 1, 2).
pub(super) const QUEUED_FMI3: u32 = 16;

/// The typed getters, and the setters: a set of scalars (as many values as references) is
/// queued for the next call as FMI 2.0's sets are, one of array values is a call.
macro_rules! typed_functions {
    ($($get:ident, $set:ident, $t:ty, $ty:ident, $set_name:literal;)*) => {$(
        unsafe extern "C" fn $get(c: Component, vr: *const u32, n: usize, v: *mut $t, nv: usize) -> fmi3Status {
            typed(c, vr, n, v as *mut u8, nv, ValueType::$ty, false)
        }
        unsafe extern "C" fn $set(c: Component, vr: *const u32, n: usize, v: *const $t, nv: usize) -> fmi3Status {
            if nv != n {
                return typed(c, vr, n, v as *mut u8, nv, ValueType::$ty, true);
            }
            let kind = QUEUED_FMI3 + fmi3_type_code(ValueType::$ty) as u32;
            let bytes = slice(v as *const u8, std::mem::size_of::<$t>() * n);
            super::proxy::queue(c, kind, $set_name, vr, n, bytes)
        }
    )*};
}

typed_functions! {
    get_float64, set_float64, f64, Float64, "fmi3SetFloat64";
    get_float32, set_float32, f32, Float32, "fmi3SetFloat32";
    get_int8, set_int8, i8, Int8, "fmi3SetInt8";
    get_uint8, set_uint8, u8, UInt8, "fmi3SetUInt8";
    get_int16, set_int16, i16, Int16, "fmi3SetInt16";
    get_uint16, set_uint16, u16, UInt16, "fmi3SetUInt16";
    get_int32, set_int32, i32, Int32, "fmi3SetInt32";
    get_uint32, set_uint32, u32, UInt32, "fmi3SetUInt32";
    get_int64, set_int64, i64, Int64, "fmi3SetInt64";
    get_uint64, set_uint64, u64, UInt64, "fmi3SetUInt64";
    get_boolean, set_boolean, fmi3Boolean, Boolean, "fmi3SetBoolean";
}

/// Strings of scalars only (the view holds no String arrays): `nValues` other than the
/// number of references is an error.
unsafe extern "C" fn get_string(c: Component, vr: *const u32, n: usize, v: *mut fmi3String, nv: usize) -> fmi3Status {
    if nv != n {
        return 3;
    }
    super::proxy::get_strings(c, vr, n, v, Op::GetString3)
}

unsafe extern "C" fn set_string(c: Component, vr: *const u32, n: usize, v: *const fmi3String, nv: usize) -> fmi3Status {
    if nv != n {
        return 3;
    }
    super::proxy::set_strings(c, vr, n, v, Op::SetString3)
}

/// The values are kept in the channel until its next `fmi3GetBinary`.
unsafe extern "C" fn get_binary(
    c: Component,
    vr: *const u32,
    n: usize,
    sizes: *mut usize,
    values: *mut *const u8,
    nv: usize,
) -> fmi3Status {
    let channel = ch(c);
    if !fits(channel, (4 * n).div_ceil(8) * 8 + 8 * nv) {
        return 3;
    }
    let at = vrs_into(channel, slice(vr, n));
    let h = channel.header();
    h.n = n as u64;
    h.i = [0, nv as i64, 0, 0];
    let s = channel.call(Op::GetBinary3);
    let mut binaries = Vec::with_capacity(nv);
    {
        let data = channel.data();
        let mut p = at + 8 * nv;
        for k in 0..nv {
            let size = u64::from_ne_bytes(data[at + 8 * k..at + 8 * k + 8].try_into().unwrap_or([0; 8])) as usize;
            let end = (p + size).min(data.len());
            binaries.push(data[p..end].to_vec());
            p = end;
        }
    }
    channel.binaries = binaries;
    for ((size, value), b) in slice_mut(sizes, nv).iter_mut().zip(slice_mut(values, nv)).zip(&channel.binaries) {
        *size = b.len();
        *value = b.as_ptr();
    }
    s
}

#[allow(clippy::too_many_arguments)]
unsafe extern "C" fn do_step(
    c: Component,
    t: f64,
    h: f64,
    no_set_prior: fmi3Boolean,
    event: *mut fmi3Boolean,
    terminate: *mut fmi3Boolean,
    early: *mut fmi3Boolean,
    reached: *mut f64,
) -> fmi3Status {
    let s = super::proxy::step(c, Op::DoStep3, t, h, no_set_prior != 0);
    let channel = &mut *(c as *mut Channel);
    let hdr = channel.header();
    // the host wrote them with the answer (on a failure they are not read)
    *event = u8::from(hdr.i[1] != 0);
    *terminate = u8::from(hdr.i[2] != 0);
    *early = u8::from(hdr.i[3] != 0);
    *reached = hdr.f[2];
    s
}

unsafe extern "C" fn update_discrete_states(
    c: Component,
    need_update: *mut fmi3Boolean,
    terminate: *mut fmi3Boolean,
    nominals_changed: *mut fmi3Boolean,
    values_changed: *mut fmi3Boolean,
    next_defined: *mut fmi3Boolean,
    next_time: *mut f64,
) -> fmi3Status {
    let channel = ch(c);
    let r = channel.call(Op::UpdateDiscreteStates3);
    // the host wrote the five Booleans as bytes 0..5 and nextEventTime at byte 8
    let data = channel.data();
    for (k, out) in [need_update, terminate, nominals_changed, values_changed, next_defined].into_iter().enumerate() {
        *out = u8::from(data[k] != 0);
    }
    *next_time = f64::from_ne_bytes(data[8..16].try_into().unwrap_or([0; 8]));
    r
}

unsafe extern "C" fn completed_integrator_step(
    c: Component,
    no_set_prior: fmi3Boolean,
    event: *mut fmi3Boolean,
    terminate: *mut fmi3Boolean,
) -> fmi3Status {
    let channel = ch(c);
    channel.header().i = [i64::from(no_set_prior), 0, 0, 0];
    let r = channel.call(Op::CompletedIntegratorStep3);
    *event = u8::from(channel.header().i[1] != 0);
    *terminate = u8::from(channel.header().i[2] != 0);
    r
}

unsafe extern "C" fn set_time(c: Component, t: f64) -> fmi3Status {
    super::proxy::time_call(c, t, Op::SetTime3)
}

unsafe extern "C" fn set_continuous_states(c: Component, x: *const f64, n: usize) -> fmi3Status {
    super::proxy::set_vector(c, x, n, Op::SetContinuousStates3)
}

/// The Model Exchange getters of a vector of Reals.
macro_rules! vector_getters {
    ($($name:ident => $op:ident;)*) => {$(
        unsafe extern "C" fn $name(c: Component, x: *mut f64, n: usize) -> fmi3Status {
            super::proxy::get_vector(c, x, n, Op::$op)
        }
    )*};
}

vector_getters! {
    get_continuous_state_derivatives => GetContinuousStateDerivatives3;
    get_event_indicators => GetEventIndicators3;
    get_continuous_states => GetContinuousStates3;
    get_nominals_of_continuous_states => GetNominalsOfContinuousStates3;
}

/// One clock call (`op`) on n references and the arrays of n values each: (bytes per
/// value, the caller's array, whether it goes to the FMU) in the function's order, laid out
/// by [`clock_arrays`]; the arrays that do not go to the FMU are its answers.
unsafe fn clock_call<const K: usize>(
    c: Component,
    vr: *const u32,
    n: usize,
    op: Op,
    arrays: [(usize, *mut u8, bool); K],
) -> fmi3Status {
    let channel = ch(c);
    let (offsets, bytes) = clock_arrays(n, arrays.map(|a| a.0));
    if !fits(channel, bytes) {
        return 3;
    }
    vrs_into(channel, slice(vr, n));
    for (&(width, values, given), at) in arrays.iter().zip(offsets) {
        if given {
            channel.data()[at..at + width * n].copy_from_slice(slice(values as *const u8, width * n));
        }
    }
    channel.header().n = n as u64;
    let s = channel.call(op);
    for (&(width, values, given), at) in arrays.iter().zip(offsets) {
        if !given {
            slice_mut(values, width * n).copy_from_slice(&channel.data()[at..at + width * n]);
        }
    }
    s
}

unsafe extern "C" fn set_clock(c: Component, vr: *const u32, n: usize, v: *const fmi3Clock) -> fmi3Status {
    clock_call(c, vr, n, Op::SetClock3, [(1, v as *mut u8, true)])
}

unsafe extern "C" fn get_clock(c: Component, vr: *const u32, n: usize, v: *mut fmi3Clock) -> fmi3Status {
    clock_call(c, vr, n, Op::GetClock3, [(1, v, false)])
}

unsafe extern "C" fn get_interval_decimal(
    c: Component,
    vr: *const u32,
    n: usize,
    intervals: *mut f64,
    qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    clock_call(c, vr, n, Op::GetIntervalDecimal3, [(8, intervals as *mut u8, false), (4, qualifiers as *mut u8, false)])
}

unsafe extern "C" fn get_interval_fraction(
    c: Component,
    vr: *const u32,
    n: usize,
    counters: *mut u64,
    resolutions: *mut u64,
    qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    let arrays =
        [(8, counters as *mut u8, false), (8, resolutions as *mut u8, false), (4, qualifiers as *mut u8, false)];
    clock_call(c, vr, n, Op::GetIntervalFraction3, arrays)
}

unsafe extern "C" fn get_shift_decimal(c: Component, vr: *const u32, n: usize, shifts: *mut f64) -> fmi3Status {
    clock_call(c, vr, n, Op::GetShiftDecimal3, [(8, shifts as *mut u8, false)])
}

unsafe extern "C" fn get_shift_fraction(
    c: Component,
    vr: *const u32,
    n: usize,
    counters: *mut u64,
    resolutions: *mut u64,
) -> fmi3Status {
    clock_call(c, vr, n, Op::GetShiftFraction3, [(8, counters as *mut u8, false), (8, resolutions as *mut u8, false)])
}

unsafe extern "C" fn set_interval_decimal(c: Component, vr: *const u32, n: usize, intervals: *const f64) -> fmi3Status {
    clock_call(c, vr, n, Op::SetIntervalDecimal3, [(8, intervals as *mut u8, true)])
}

unsafe extern "C" fn get_fmu_state(c: Component, s: *mut fmi3FMUState) -> fmi3Status {
    state_call(c, s, Op::GetFmuState3)
}

unsafe extern "C" fn set_fmu_state(c: Component, mut s: fmi3FMUState) -> fmi3Status {
    state_call(c, &mut s, Op::SetFmuState3)
}

unsafe extern "C" fn free_fmu_state(c: Component, s: *mut fmi3FMUState) -> fmi3Status {
    state_call(c, s, Op::FreeFmuState3)
}

/// The proxy table for an FMI 3.0 FMU whose library has the functions `present` says it
/// has (an optional function is in the table where the library has it, so the
/// capabilities stay the FMU's). The instantiation is [`instantiate_in`] (made by
/// `Instance::new_isolated`); setting binaries (the view's Binaries are read-only),
/// setting shifts and fractional intervals (the master sets none), directional
/// derivatives, serialized states and Scheduled Execution are not carried to the host.
pub(crate) fn table(present: &dyn Fn(&str) -> bool) -> Fmi3Functions {
    macro_rules! optional {
        ($name:literal, $f:ident) => {
            present($name).then_some($f as _)
        };
    }
    Fmi3Functions {
        get_version,
        free_instance,
        enter_initialization_mode,
        exit_initialization_mode,
        terminate,
        get_float64,
        set_float64,
        set_debug_logging: None,
        instantiate_model_exchange: None,
        instantiate_co_simulation: None,
        instantiate_scheduled_execution: None,
        enter_event_mode: optional!("fmi3EnterEventMode", enter_event_mode),
        reset: optional!("fmi3Reset", reset),
        get_float32: optional!("fmi3GetFloat32", get_float32),
        get_int8: optional!("fmi3GetInt8", get_int8),
        get_uint8: optional!("fmi3GetUInt8", get_uint8),
        get_int16: optional!("fmi3GetInt16", get_int16),
        get_uint16: optional!("fmi3GetUInt16", get_uint16),
        get_int32: optional!("fmi3GetInt32", get_int32),
        get_uint32: optional!("fmi3GetUInt32", get_uint32),
        get_int64: optional!("fmi3GetInt64", get_int64),
        get_uint64: optional!("fmi3GetUInt64", get_uint64),
        get_boolean: optional!("fmi3GetBoolean", get_boolean),
        get_string: optional!("fmi3GetString", get_string),
        get_binary: optional!("fmi3GetBinary", get_binary),
        get_clock: optional!("fmi3GetClock", get_clock),
        set_float32: optional!("fmi3SetFloat32", set_float32),
        set_int8: optional!("fmi3SetInt8", set_int8),
        set_uint8: optional!("fmi3SetUInt8", set_uint8),
        set_int16: optional!("fmi3SetInt16", set_int16),
        set_uint16: optional!("fmi3SetUInt16", set_uint16),
        set_int32: optional!("fmi3SetInt32", set_int32),
        set_uint32: optional!("fmi3SetUInt32", set_uint32),
        set_int64: optional!("fmi3SetInt64", set_int64),
        set_uint64: optional!("fmi3SetUInt64", set_uint64),
        set_boolean: optional!("fmi3SetBoolean", set_boolean),
        set_string: optional!("fmi3SetString", set_string),
        set_binary: None,
        set_clock: optional!("fmi3SetClock", set_clock),
        get_number_of_variable_dependencies: None,
        get_variable_dependencies: None,
        get_fmu_state: optional!("fmi3GetFMUState", get_fmu_state),
        set_fmu_state: optional!("fmi3SetFMUState", set_fmu_state),
        free_fmu_state: optional!("fmi3FreeFMUState", free_fmu_state),
        serialized_fmu_state_size: None,
        serialize_fmu_state: None,
        deserialize_fmu_state: None,
        get_directional_derivative: None,
        get_adjoint_derivative: None,
        enter_configuration_mode: None,
        exit_configuration_mode: None,
        get_interval_decimal: optional!("fmi3GetIntervalDecimal", get_interval_decimal),
        get_interval_fraction: optional!("fmi3GetIntervalFraction", get_interval_fraction),
        get_shift_decimal: optional!("fmi3GetShiftDecimal", get_shift_decimal),
        get_shift_fraction: optional!("fmi3GetShiftFraction", get_shift_fraction),
        set_interval_decimal: optional!("fmi3SetIntervalDecimal", set_interval_decimal),
        set_interval_fraction: None,
        set_shift_decimal: None,
        set_shift_fraction: None,
        evaluate_discrete_states: None,
        update_discrete_states: optional!("fmi3UpdateDiscreteStates", update_discrete_states),
        enter_continuous_time_mode: optional!("fmi3EnterContinuousTimeMode", enter_continuous_time_mode),
        completed_integrator_step: optional!("fmi3CompletedIntegratorStep", completed_integrator_step),
        set_time: optional!("fmi3SetTime", set_time),
        set_continuous_states: optional!("fmi3SetContinuousStates", set_continuous_states),
        get_continuous_state_derivatives: optional!(
            "fmi3GetContinuousStateDerivatives",
            get_continuous_state_derivatives
        ),
        get_event_indicators: optional!("fmi3GetEventIndicators", get_event_indicators),
        get_continuous_states: optional!("fmi3GetContinuousStates", get_continuous_states),
        get_nominals_of_continuous_states: optional!(
            "fmi3GetNominalsOfContinuousStates",
            get_nominals_of_continuous_states
        ),
        get_number_of_event_indicators: None,
        get_number_of_continuous_states: None,
        enter_step_mode: optional!("fmi3EnterStepMode", enter_step_mode),
        get_output_derivatives: None,
        do_step: optional!("fmi3DoStep", do_step),
        activate_model_partition: None,
    }
}

#[cfg(test)]
mod tests {
    /// An optional function is there where the library has it and the host carries it;
    /// what the host does not carry is absent even where the library has it.
    #[test]
    fn the_table_has_what_the_library_has() {
        let t = super::table(&|s| s != "fmi3GetFMUState" && s != "fmi3GetInt8");
        assert!(t.has("fmi3DoStep") && t.has("fmi3SetFMUState") && t.has("fmi3GetFloat64") && t.has("fmi3SetInt8"));
        assert!(t.has("fmi3GetBinary") && t.has("fmi3UpdateDiscreteStates") && t.has("fmi3EnterStepMode"));
        assert!(!t.has("fmi3GetFMUState") && !t.has("fmi3GetInt8"));
        assert!(
            t.has("fmi3SetTime") && t.has("fmi3GetContinuousStateDerivatives") && t.has("fmi3CompletedIntegratorStep")
        );
        assert!(
            !t.has("fmi3SetBinary") && !t.has("fmi3GetDirectionalDerivative") && !t.has("fmi3ActivateModelPartition")
        );
        assert!(t.has("fmi3GetClock") && t.has("fmi3SetClock") && t.has("fmi3GetIntervalFraction"));
    }
}
