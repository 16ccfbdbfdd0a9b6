//! The function table of an isolated instance: each fmi2 function of the FMI 2.0 C API,
//! its component being the instance's [`Channel`], carried to the host as one call
//! (`fmi2Set*` queued for the next one, `fmi2GetReal` after a step answered from the
//! host's prefetch when it asks for the same Reals as after the previous step).

#![allow(clippy::missing_safety_doc)] // called only by `Instance` through the function table

use super::channel::Channel;
use super::protocol::Op;
use crate::c_types::{CallbackFunctions, EventInfo, Functions};
use std::ffi::{c_char, c_int, c_void, CStr, CString};

type Component = *mut c_void;

/// The channel, with any call posted on it answered first (the region is the master's
/// again).
///
/// # Safety
/// `c` is the address of the live channel of the instance calling (proxy table).
pub(super) unsafe fn ch<'a>(c: Component) -> &'a mut Channel {
    let channel = &mut *(c as *mut Channel);
    channel.settle();
    channel
}

pub(super) fn vrs_into(channel: &mut Channel, vrs: &[u32]) -> usize {
    let data = channel.data();
    for (k, vr) in vrs.iter().enumerate() {
        data[4 * k..4 * k + 4].copy_from_slice(&vr.to_ne_bytes());
    }
    (4 * vrs.len()).div_ceil(8) * 8
}

/// Whether a call whose data take `bytes` fits the region; if not, the channel keeps the
/// sizes for the error ([`Channel::over_limit`]: the master's limit, not the FMU's error).
pub(super) fn fits(channel: &mut Channel, bytes: usize) -> bool {
    let available = channel.data().len();
    if bytes > available {
        channel.over_limit = Some((bytes, available));
    }
    bytes <= available
}

/// A getter's request of `n` values: when `room` bytes fit in the channel, the value
/// references written and `op` called; its status and where the values start in the data
/// (`None`: they do not fit, the status is Error).
fn ask(channel: &mut Channel, (vrs, n): (&[u32], usize), room: usize, op: Op) -> Option<(c_int, usize)> {
    if !fits(channel, room) {
        return None;
    }
    let at = vrs_into(channel, vrs);
    channel.header().n = n as u64;
    Some((channel.call(op), at))
}

pub(super) unsafe fn slice<'a, T>(p: *const T, n: usize) -> &'a [T] {
    if n == 0 || p.is_null() {
        &[]
    } else {
        std::slice::from_raw_parts(p, n)
    }
}

pub(super) unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> &'a mut [T] {
    if n == 0 || p.is_null() {
        &mut []
    } else {
        std::slice::from_raw_parts_mut(p, n)
    }
}

unsafe extern "C" fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

unsafe extern "C" fn instantiate(
    _: *const c_char,
    _: c_int,
    _: *const c_char,
    _: *const c_char,
    _: *const CallbackFunctions,
    _: c_int,
    _: c_int,
) -> Component {
    // isolated instances are made by `Instance::new_isolated`, which calls `instantiate_in`
    std::ptr::null_mut()
}

/// `fmi2Instantiate` in the host of `channel`; the fmi2 status.
pub(crate) fn instantiate_in(channel: &mut Channel, name: &CStr, fmi_type: c_int, guid: &CStr, uri: &CStr) -> i32 {
    instantiate_with(channel, Op::Instantiate, [name, guid, uri], fmi_type as i64)
}

/// An instantiation (`op`) with its three strings in the data area, one after the other,
/// and its one flag in `i[0]`; the status.
pub(super) fn instantiate_with(channel: &mut Channel, op: Op, strings: [&CStr; 3], flag: i64) -> i32 {
    let bytes: Vec<u8> = strings.iter().flat_map(|s| s.to_bytes_with_nul()).copied().collect();
    if !fits(channel, bytes.len()) {
        return 3;
    }
    channel.data()[..bytes.len()].copy_from_slice(&bytes);
    channel.header().i = [flag, 0, 0, 0];
    channel.call(op)
}

unsafe extern "C" fn free_instance(c: Component) {
    let _ = ch(c).call(Op::Free);
}

unsafe extern "C" fn setup_experiment(
    c: Component,
    tol_defined: c_int,
    tol: f64,
    start: f64,
    stop_defined: c_int,
    stop: f64,
) -> c_int {
    experiment(c, Op::SetupExperiment, [tol_defined != 0, stop_defined != 0], [tol, start, stop])
}

/// The call (`op`) that gives the experiment: tolerance and stop time defined, the
/// tolerance, start and stop time.
pub(super) unsafe fn experiment(c: Component, op: Op, defined: [bool; 2], [tol, start, stop]: [f64; 3]) -> c_int {
    let channel = ch(c);
    let h = channel.header();
    h.i = [i64::from(defined[0]), i64::from(defined[1]), 0, 0];
    h.f = [tol, start, stop, 0.0];
    channel.last_time = start;
    channel.call(op)
}

/// A proxy function of the instance alone: one call of `$op`.
macro_rules! plain {
    ($name:ident, $op:expr) => {
        unsafe extern "C" fn $name(c: *mut std::ffi::c_void) -> std::ffi::c_int {
            super::proxy::ch(c).call($op)
        }
    };
}
pub(super) use plain;
plain!(enter_initialization_mode, Op::EnterInitializationMode);
plain!(exit_initialization_mode, Op::ExitInitializationMode);
plain!(terminate, Op::Terminate);
plain!(reset, Op::Reset);
plain!(enter_event_mode, Op::EnterEventMode);
plain!(enter_continuous_time_mode, Op::EnterContinuousTimeMode);

unsafe extern "C" fn get_real(c: Component, vr: *const u32, n: usize, v: *mut f64) -> c_int {
    let channel = ch(c);
    let (vrs, out) = (slice(vr, n), slice_mut(v, n));
    if channel.prefetched_reals(vrs, out) {
        return 0;
    }
    let Some((s, at)) = ask(channel, (vrs, n), 12 * n + 8, Op::GetReal) else { return 3 };
    let data = channel.data();
    for (k, x) in out.iter_mut().enumerate() {
        *x = f64::from_ne_bytes(data[at + 8 * k..at + 8 * k + 8].try_into().unwrap_or([0; 8]));
    }
    s
}

unsafe fn get_ints(c: Component, vr: *const u32, n: usize, v: *mut c_int, op: Op) -> c_int {
    let channel = ch(c);
    let (vrs, out) = (slice(vr, n), slice_mut(v, n));
    let Some((s, at)) = ask(channel, (vrs, n), 8 * n + 8, op) else { return 3 };
    let data = channel.data();
    for (k, x) in out.iter_mut().enumerate() {
        *x = c_int::from_ne_bytes(data[at + 4 * k..at + 4 * k + 4].try_into().unwrap_or([0; 4]));
    }
    s
}

unsafe extern "C" fn get_integer(c: Component, vr: *const u32, n: usize, v: *mut c_int) -> c_int {
    get_ints(c, vr, n, v, Op::GetInteger)
}

unsafe extern "C" fn get_boolean(c: Component, vr: *const u32, n: usize, v: *mut c_int) -> c_int {
    get_ints(c, vr, n, v, Op::GetBoolean)
}

unsafe extern "C" fn get_string(c: Component, vr: *const u32, n: usize, v: *mut *const c_char) -> c_int {
    get_strings(c, vr, n, v, Op::GetString)
}

/// A string getter (`op`: the fmi2 or the fmi3 one) of n scalars; the strings stay in the
/// channel until its next string read.
pub(super) unsafe fn get_strings(c: Component, vr: *const u32, n: usize, v: *mut *const c_char, op: Op) -> c_int {
    let channel = ch(c);
    let (vrs, out) = (slice(vr, n), slice_mut(v, n));
    let Some((s, at)) = ask(channel, (vrs, n), 4 * n + 8, op) else { return 3 };
    let mut strings = Vec::with_capacity(n);
    {
        let data = channel.data();
        let mut p = at;
        for _ in 0..n {
            let end = data[p..].iter().position(|b| *b == 0).map_or(data.len(), |e| p + e);
            strings.push(CString::new(&data[p..end]).unwrap_or_default());
            p = (end + 1).min(data.len());
        }
    }
    channel.strings = strings;
    for (o, s) in out.iter_mut().zip(&channel.strings) {
        *o = s.as_ptr();
    }
    s
}

pub(super) unsafe fn queue(
    c: Component,
    kind: u32,
    function: &'static str,
    vr: *const u32,
    n: usize,
    bytes: &[u8],
) -> c_int {
    let channel = ch(c);
    let vrs = slice(vr, n);
    if channel.queue_set(kind, function, vrs, bytes) {
        return 0;
    }
    // the queue is full: send it, then queue again
    let s = channel.call(Op::Flush);
    if s > 1 {
        return s;
    }
    if channel.queue_set(kind, function, vrs, bytes) {
        0
    } else {
        3
    }
}

unsafe extern "C" fn set_real(c: Component, vr: *const u32, n: usize, v: *const f64) -> c_int {
    let bytes = std::slice::from_raw_parts(v as *const u8, if n == 0 || v.is_null() { 0 } else { 8 * n });
    queue(c, 0, "fmi2SetReal", vr, n, bytes)
}

unsafe extern "C" fn set_integer(c: Component, vr: *const u32, n: usize, v: *const c_int) -> c_int {
    let bytes = std::slice::from_raw_parts(v as *const u8, if n == 0 || v.is_null() { 0 } else { 4 * n });
    queue(c, 1, "fmi2SetInteger", vr, n, bytes)
}

unsafe extern "C" fn set_boolean(c: Component, vr: *const u32, n: usize, v: *const c_int) -> c_int {
    let bytes = std::slice::from_raw_parts(v as *const u8, if n == 0 || v.is_null() { 0 } else { 4 * n });
    queue(c, 2, "fmi2SetBoolean", vr, n, bytes)
}

unsafe extern "C" fn set_string(c: Component, vr: *const u32, n: usize, v: *const *const c_char) -> c_int {
    set_strings(c, vr, n, v, Op::SetString)
}

/// A string setter (`op`: the fmi2 or the fmi3 one) of n scalars.
pub(super) unsafe fn set_strings(c: Component, vr: *const u32, n: usize, v: *const *const c_char, op: Op) -> c_int {
    let channel = ch(c);
    let vrs = slice(vr, n);
    let values = slice(v, n);
    let mut bytes = Vec::new();
    for p in values {
        if !p.is_null() {
            bytes.extend_from_slice(CStr::from_ptr(*p).to_bytes());
        }
        bytes.push(0);
    }
    if !fits(channel, 4 * n + 8 + bytes.len()) {
        return 3;
    }
    let at = vrs_into(channel, vrs);
    channel.data()[at..at + bytes.len()].copy_from_slice(&bytes);
    channel.header().n = n as u64;
    channel.call(op)
}

/// `fmi2DoStep(t, h)` or `fmi3DoStep(t, h)` (`op`) posted to the host (see
/// [`Channel::post`]); `do_step` with the same arguments collects it.
pub(crate) fn post_step(channel: &mut Channel, op: Op, t: f64, h: f64) {
    channel.settle();
    let hdr = channel.header();
    hdr.f = [t, h, 0.0, 0.0];
    hdr.i = [1, 0, 0, 0];
    channel.last_time = t;
    channel.posted_step = Some((t, h));
    channel.post(op);
}

unsafe extern "C" fn do_step(c: Component, t: f64, h: f64, no_set_prior: c_int) -> c_int {
    step(c, Op::DoStep, t, h, no_set_prior != 0)
}

/// A step (`op`: `fmi2DoStep` or `fmi3DoStep`) from `t` over `h`: the answer to the one
/// posted with these arguments, or a call of its own.
pub(super) unsafe fn step(c: Component, op: Op, t: f64, h: f64, no_set_prior: bool) -> c_int {
    let channel = &mut *(c as *mut Channel);
    if channel.is_pending(op) && channel.posted_step == Some((t, h)) && no_set_prior {
        channel.posted_step = None;
        return channel.collect();
    }
    channel.settle();
    let hdr = channel.header();
    hdr.f = [t, h, 0.0, 0.0];
    hdr.i = [i64::from(no_set_prior), 0, 0, 0];
    channel.last_time = t;
    channel.call(op)
}

/// A call on a saved state (`op`: get, set or free, of either generation): the host's
/// pointer to it goes there and back in `i[0]`.
pub(super) unsafe fn state_call(c: Component, s: *mut *mut c_void, op: Op) -> c_int {
    let channel = ch(c);
    channel.header().i[0] = *s as usize as i64;
    let r = channel.call(op);
    *s = channel.header().i[0] as usize as *mut c_void;
    r
}

unsafe extern "C" fn get_fmu_state(c: Component, s: *mut *mut c_void) -> c_int {
    state_call(c, s, Op::GetFmuState)
}

unsafe extern "C" fn set_fmu_state(c: Component, mut s: *mut c_void) -> c_int {
    state_call(c, &mut s, Op::SetFmuState)
}

unsafe extern "C" fn free_fmu_state(c: Component, s: *mut *mut c_void) -> c_int {
    state_call(c, s, Op::FreeFmuState)
}

unsafe extern "C" fn get_boolean_status(c: Component, kind: c_int, v: *mut c_int) -> c_int {
    let channel = ch(c);
    channel.header().i[0] = kind as i64;
    let r = channel.call(Op::GetBooleanStatus);
    *v = channel.header().i[1] as c_int;
    r
}

unsafe extern "C" fn get_real_status(c: Component, kind: c_int, v: *mut f64) -> c_int {
    let channel = ch(c);
    channel.header().i[0] = kind as i64;
    let r = channel.call(Op::GetRealStatus);
    *v = channel.header().f[0];
    r
}

unsafe extern "C" fn new_discrete_states(c: Component, info: *mut EventInfo) -> c_int {
    let channel = ch(c);
    let r = channel.call(Op::NewDiscreteStates);
    let data = channel.data();
    // SAFETY: the host wrote an EventInfo at the start of the data area (8-aligned).
    *info = std::ptr::read_unaligned(data.as_ptr() as *const EventInfo);
    r
}

unsafe extern "C" fn completed_integrator_step(
    c: Component,
    no_set_prior: c_int,
    event: *mut c_int,
    terminate: *mut c_int,
) -> c_int {
    let channel = ch(c);
    channel.header().i = [no_set_prior as i64, 0, 0, 0];
    let r = channel.call(Op::CompletedIntegratorStep);
    *event = channel.header().i[1] as c_int;
    *terminate = channel.header().i[2] as c_int;
    r
}

unsafe extern "C" fn set_time(c: Component, t: f64) -> c_int {
    time_call(c, t, Op::SetTime)
}

/// `fmi2SetTime` / `fmi3SetTime` (`op`).
pub(super) unsafe fn time_call(c: Component, t: f64, op: Op) -> c_int {
    let channel = ch(c);
    channel.header().f[0] = t;
    channel.last_time = t;
    channel.call(op)
}

unsafe extern "C" fn set_continuous_states(c: Component, x: *const f64, n: usize) -> c_int {
    set_vector(c, x, n, Op::SetContinuousStates)
}

/// A vector of n Reals to the host (`op`: either generation's `SetContinuousStates`).
pub(super) unsafe fn set_vector(c: Component, x: *const f64, n: usize, op: Op) -> c_int {
    let channel = ch(c);
    if !fits(channel, 8 * n) {
        return 3;
    }
    let src = slice(x, n);
    let data = channel.data();
    for (k, v) in src.iter().enumerate() {
        data[8 * k..8 * k + 8].copy_from_slice(&v.to_ne_bytes());
    }
    channel.header().n = n as u64;
    channel.call(op)
}

/// A vector of n Reals from the host (`op`: either generation's derivatives, event
/// indicators, states or nominals).
pub(super) unsafe fn get_vector(c: Component, x: *mut f64, n: usize, op: Op) -> c_int {
    let channel = ch(c);
    if !fits(channel, 8 * n) {
        return 3;
    }
    channel.header().n = n as u64;
    let r = channel.call(op);
    let out = slice_mut(x, n);
    let data = channel.data();
    for (k, v) in out.iter_mut().enumerate() {
        *v = f64::from_ne_bytes(data[8 * k..8 * k + 8].try_into().unwrap_or([0; 8]));
    }
    r
}

unsafe extern "C" fn get_derivatives(c: Component, x: *mut f64, n: usize) -> c_int {
    get_vector(c, x, n, Op::GetDerivatives)
}
unsafe extern "C" fn get_event_indicators(c: Component, x: *mut f64, n: usize) -> c_int {
    get_vector(c, x, n, Op::GetEventIndicators)
}
unsafe extern "C" fn get_continuous_states(c: Component, x: *mut f64, n: usize) -> c_int {
    get_vector(c, x, n, Op::GetContinuousStates)
}
unsafe extern "C" fn get_nominals(c: Component, x: *mut f64, n: usize) -> c_int {
    get_vector(c, x, n, Op::GetNominalsOfContinuousStates)
}

/// The proxy table for an FMU whose library has the fmi2 functions `present` says it has
/// (an optional function is in the table where the library has it, so the capabilities
/// stay the FMU's).
pub(crate) fn table(present: &dyn Fn(&str) -> bool) -> Functions {
    Functions {
        get_version,
        instantiate,
        free_instance,
        setup_experiment,
        enter_initialization_mode,
        exit_initialization_mode,
        terminate,
        get_real,
        get_integer,
        get_boolean,
        get_string,
        set_real,
        set_integer,
        set_boolean,
        set_string,
        reset: present("fmi2Reset").then_some(reset as _),
        get_fmu_state: present("fmi2GetFMUstate").then_some(get_fmu_state as _),
        set_fmu_state: present("fmi2SetFMUstate").then_some(set_fmu_state as _),
        free_fmu_state: present("fmi2FreeFMUstate").then_some(free_fmu_state as _),
        do_step: present("fmi2DoStep").then_some(do_step as _),
        get_boolean_status: present("fmi2GetBooleanStatus").then_some(get_boolean_status as _),
        get_real_status: present("fmi2GetRealStatus").then_some(get_real_status as _),
        enter_event_mode: present("fmi2EnterEventMode").then_some(enter_event_mode as _),
        new_discrete_states: present("fmi2NewDiscreteStates").then_some(new_discrete_states as _),
        enter_continuous_time_mode: present("fmi2EnterContinuousTimeMode").then_some(enter_continuous_time_mode as _),
        completed_integrator_step: present("fmi2CompletedIntegratorStep").then_some(completed_integrator_step as _),
        set_time: present("fmi2SetTime").then_some(set_time as _),
        set_continuous_states: present("fmi2SetContinuousStates").then_some(set_continuous_states as _),
        get_derivatives: present("fmi2GetDerivatives").then_some(get_derivatives as _),
        get_event_indicators: present("fmi2GetEventIndicators").then_some(get_event_indicators as _),
        get_continuous_states: present("fmi2GetContinuousStates").then_some(get_continuous_states as _),
        get_nominals_of_continuous_states: present("fmi2GetNominalsOfContinuousStates").then_some(get_nominals as _),
        // not offered through a host process
        get_types_platform: None,
        set_debug_logging: None,
        serialized_fmu_state_size: None,
        serialize_fmu_state: None,
        deserialize_fmu_state: None,
        get_directional_derivative: None,
        set_real_input_derivatives: None,
        get_real_output_derivatives: None,
        cancel_step: None,
        get_status: None,
        get_integer_status: None,
        get_string_status: None,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_table_has_what_the_library_has() {
        let t = super::table(&|s| s != "fmi2GetFMUstate" && s != "fmi2SetTime");
        assert!(t.has("fmi2DoStep") && t.has("fmi2SetFMUstate") && t.has("fmi2GetReal"));
        assert!(!t.has("fmi2GetFMUstate") && !t.has("fmi2SetTime") && !t.has("fmi2Unknown"));
    }
}
