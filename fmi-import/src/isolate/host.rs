//! The host process of an isolated instance (`cosim-host FD SIZE LIBRARY`): maps the
//! region the master shares (descriptor `FD`, `SIZE` bytes), loads the FMU's library (FMI
//! 2.0 or FMI 3.0, as the header says) and answers the master's calls until the instance is
//! freed, then exits 0. Whatever the FMU
//! does to this process (a crash, `exit`, a call that never returns) the master sees as
//! the host's end.

use super::protocol::{clock_arrays, fmi3_type, publish, wait_for, Header, Layout, Op, SpinGauge};
use crate::c_types::{EventInfo, Functions};
use crate::library::{load_functions, load_library};
use crate::log::{callbacks_for, LogSink};
use fmi_sys::fmi3::Fmi3Functions;
use model_description::fmi3::ValueType;
use std::ffi::{c_char, c_int, c_void, CStr};
use std::path::Path;
use std::time::Duration;

struct Region {
    base: *mut u8,
    layout: Layout,
}

impl Region {
    #[allow(clippy::mut_from_ref)] // the region is memory the master shares, not a Rust object
    fn header(&self) -> &mut Header {
        // SAFETY: the mapping starts with the Header; the master does not touch it while
        // it is the host's turn.
        unsafe { &mut *(self.base as *mut Header) }
    }
    /// The call's array arguments: their count `n`, the data area, the references at its
    /// start, and the offset of what follows them (8-aligned).
    fn call_arrays(&self) -> (usize, *mut u8, *const u32, usize) {
        let n = self.header().n as usize;
        let data: *mut u8 = self.at(self.layout.data);
        (n, data, data as *const u32, (4 * n).div_ceil(8) * 8)
    }

    /// The three NUL-ended strings of an instantiation at the start of the data area.
    ///
    /// # Safety
    /// The master wrote them there (`proxy::instantiate_with`).
    unsafe fn three_strings(&self) -> [&CStr; 3] {
        let first = CStr::from_ptr(self.at::<c_char>(self.layout.data));
        let second_at = self.at::<u8>(self.layout.data).add(first.to_bytes().len() + 1);
        let second = CStr::from_ptr(second_at as *const c_char);
        let third = CStr::from_ptr(second_at.add(second.to_bytes().len() + 1) as *const c_char);
        [first, second, third]
    }

    fn at<T>(&self, offset: usize) -> *mut T {
        // SAFETY: offsets within the mapping (Layout), 8-aligned where f64 are read.
        unsafe { self.base.add(offset) as *mut T }
    }
}

/// Runs the host with the process arguments; returns the exit code.
pub fn run(args: &[std::ffi::OsString]) -> i32 {
    let (Some(fd), Some(size), Some(library)) = (args.get(1), args.get(2), args.get(3)) else {
        eprintln!("cosim-host: started by the master (cosim --isolate), not by hand");
        return 2;
    };
    let Ok(size) = size.to_string_lossy().parse::<usize>() else {
        eprintln!("cosim-host: bad arguments");
        return 2;
    };
    let base = match super::os::map_inherited(&fd.to_string_lossy(), size) {
        Ok(base) => base,
        Err(e) => {
            eprintln!("cosim-host: {e}");
            return 2;
        }
    };
    // the layout the master chose, from the header it wrote before starting the host
    // SAFETY: the mapping starts with the Header, written before this process started.
    let arrays = unsafe { (*(base as *const Header)).arrays } as usize;
    let layout = Layout::with_area(arrays);
    if layout.total != size {
        eprintln!("cosim-host: the region's size {size} is not that of its layout ({})", layout.total);
        return 2;
    }
    let region = Region { base, layout };
    let log = Box::<LogSink>::default();
    let library = Path::new(library);
    let fmi3 = region.header().fmi3 == 1;
    let loaded = load_library(library, library, &library.display().to_string()).and_then(|lib| {
        // SAFETY: the library is of the generation the master read in its model description.
        let functions = if fmi3 {
            unsafe { Fmi3Functions::load(&lib) }
                .map(Generation::Fmi3)
                .map_err(|m| crate::error::Error::MissingSymbol { path: library.into(), symbol: m.0 })
        } else {
            unsafe { load_functions(&lib, library) }.map(Generation::Fmi2)
        };
        functions.map(|f| (lib, f))
    });
    let mut seen = 0u32;
    let mut gauge = SpinGauge::new();
    let (_lib, functions) = match loaded {
        Ok(x) => x,
        Err(e) => {
            // answer the first call with the reason
            wait_next(&region, &mut seen, &mut gauge);
            write_log_text(&region, 3, &e.to_string());
            region.header().status = 3;
            answer(&region, seen);
            return 0;
        }
    };
    let mut host = Host { lib: functions, c: std::ptr::null_mut(), log, _callbacks: None, strings: Vec::new() };
    loop {
        wait_next(&region, &mut seen, &mut gauge);
        let h = region.header();
        h.log_count = 0;
        h.log_bytes = 0;
        let op = Op::from_u32(h.op);
        let mut status = host.queued(&region);
        let mut free = false;
        if status <= 1 {
            status = match op {
                Some(Op::Flush) => 0,
                Some(Op::Free) => {
                    free = true;
                    host.free();
                    0
                }
                Some(op) => host.call(op, &region),
                None => 3,
            };
        }
        if let (Some(Op::DoStep), true, Generation::Fmi2(f)) = (op, status <= 1 && h.prefetch > 0, &host.lib) {
            // each batch: its count, its references, room for its values (channel::record_len)
            let mut at = 0usize;
            let mut ok = true;
            for _ in 0..h.prefetch {
                let record: *mut u8 = region.at(layout.prefetch + at);
                // SAFETY: the master wrote the batch inside the prefetch area (learn_prefetch).
                let n = unsafe { *(record as *const u32) } as usize;
                if at + super::channel::record_len(n) > layout.prefetch_len {
                    ok = false;
                    break;
                }
                let vrs = unsafe { record.add(8) } as *const u32;
                let values = unsafe { record.add(8 + (4 * n).div_ceil(8) * 8) } as *mut f64;
                // SAFETY: live component; n references and n values inside the prefetch area.
                ok &= unsafe { (f.get_real)(host.c, vrs, n, values) } <= 1;
                at += super::channel::record_len(n);
            }
            h.prefetched = ok as u32;
        }
        host.drain_log(&region);
        h.status = status;
        answer(&region, seen);
        if free {
            return 0;
        }
    }
}

/// Calls an FMU-state function (get or free, either generation) on the state handle the
/// header carries and writes back the handle the call leaves there.
fn state_handle(slot: &mut i64, call: impl FnOnce(&mut *mut c_void) -> i32) -> i32 {
    let mut state = *slot as usize as *mut c_void;
    let status = call(&mut state);
    *slot = state as usize as i64;
    status
}

fn wait_next(region: &Region, seen: &mut u32, gauge: &mut SpinGauge) {
    let h = region.header();
    let spin = Duration::from_nanos(u64::from(h.host_spin_ns));
    let gauge = (h.host_adaptive == 1).then_some(gauge);
    let _ = wait_for::<()>(
        &h.request,
        *seen,
        &h.host_sleeping,
        spin,
        h.host_yield_every,
        gauge,
        Duration::from_secs(1),
        || Ok(()),
    );
    *seen = h.request.load(std::sync::atomic::Ordering::Acquire);
}

fn answer(region: &Region, seq: u32) {
    let h = region.header();
    publish(&h.response, seq, &h.master_sleeping);
}

fn write_log_text(region: &Region, status: i32, text: &str) {
    write_log_record(region, status, b"host", text.as_bytes());
}

/// Appends one log record (status, category, message) to the region's log area; false when
/// the area is full.
fn write_log_record(region: &Region, status: i32, cat: &[u8], msg: &[u8]) -> bool {
    let h = region.header();
    let l = region.layout;
    let mut p = h.log_bytes as usize;
    if p + 12 + cat.len() + msg.len() > l.log_len {
        return false;
    }
    let area: *mut u8 = region.at(l.log);
    // SAFETY: within the log area (checked above).
    unsafe {
        let dst = std::slice::from_raw_parts_mut(area.add(p), 12 + cat.len() + msg.len());
        dst[0..4].copy_from_slice(&status.to_ne_bytes());
        dst[4..8].copy_from_slice(&(cat.len() as u32).to_ne_bytes());
        dst[8..12].copy_from_slice(&(msg.len() as u32).to_ne_bytes());
        dst[12..12 + cat.len()].copy_from_slice(cat);
        dst[12 + cat.len()..].copy_from_slice(msg);
    }
    p += 12 + cat.len() + msg.len();
    h.log_bytes = p as u32;
    h.log_count += 1;
    true
}

/// The library's functions, of its generation.
#[allow(clippy::large_enum_variant)] // one per host process, never moved
enum Generation {
    Fmi2(Functions),
    Fmi3(Fmi3Functions),
}

struct Host {
    lib: Generation,
    c: *mut c_void,
    log: Box<LogSink>,
    _callbacks: Option<Box<crate::c_types::CallbackFunctions>>,
    strings: Vec<std::ffi::CString>,
}

impl Host {
    /// The queued sets, in order; the status of the first that failed (the rest skipped).
    fn queued(&mut self, region: &Region) -> i32 {
        let h = region.header();
        let l = region.layout;
        let mut p = 0usize;
        for k in 0..h.queued {
            let base: *mut u8 = region.at(l.sets + p);
            // SAFETY: the master wrote the record inside the set area (queue_set).
            let (kind, n) = unsafe { (*(base as *const u32), *(base.add(4) as *const u32) as usize) };
            let vrs = unsafe { base.add(8) } as *const u32;
            let values = unsafe { base.add(8 + 4 * n) };
            // SAFETY: live component; n references and n values of the kind's type.
            let (s, width) = unsafe {
                match (&self.lib, kind) {
                    (Generation::Fmi2(f), 0) => ((f.set_real)(self.c, vrs, n, values as *const f64), 8),
                    (Generation::Fmi2(f), 1) => ((f.set_integer)(self.c, vrs, n, values as *const c_int), 4),
                    (Generation::Fmi2(f), _) => ((f.set_boolean)(self.c, vrs, n, values as *const c_int), 4),
                    // FMI 3.0: QUEUED_FMI3 + the type's code (proxy3.rs), as many values as references
                    (Generation::Fmi3(f), _) => {
                        match kind.checked_sub(super::proxy3::QUEUED_FMI3).and_then(|k| fmi3_type(i64::from(k))) {
                            Some(ty) => {
                                (typed(f, ty, true, self.c, vrs, n, values, n), super::protocol::fmi3_width(ty))
                            }
                            None => (3, 0),
                        }
                    }
                }
            };
            p += (8 + 4 * n + width * n).div_ceil(8) * 8;
            if s > 1 {
                h.queued_failed = k;
                h.queued_status = s;
                return s;
            }
        }
        0
    }

    fn free(&mut self) {
        if !self.c.is_null() {
            // SAFETY: the component from the instantiation, freed once.
            unsafe {
                match &self.lib {
                    Generation::Fmi2(f) => (f.free_instance)(self.c),
                    Generation::Fmi3(f) => (f.free_instance)(self.c),
                }
            };
            self.c = std::ptr::null_mut();
        }
    }

    fn drain_log(&mut self, region: &Region) {
        for r in self.log.take() {
            if !write_log_record(region, r.status.to_raw(), r.category.as_bytes(), r.message.as_bytes()) {
                return;
            }
        }
    }

    /// One call with its arguments from the region, results into it, to the library's
    /// generation (an op of the other generation is an error).
    fn call(&mut self, op: Op, region: &Region) -> i32 {
        match &self.lib {
            Generation::Fmi2(f) => {
                let f = *f;
                self.call2(&f, op, region)
            }
            Generation::Fmi3(f) => {
                let f = *f;
                self.call3(&f, op, region)
            }
        }
    }

    /// One fmi2 call.
    fn call2(&mut self, f: &Functions, op: Op, region: &Region) -> i32 {
        let h = region.header();
        let (n, data, vrs, after_vrs) = region.call_arrays();
        let c = self.c;
        let missing = 3;
        // SAFETY: every pointer is inside the data area, laid out by the proxy for this
        // op (proxy.rs); the component is live (the master's state machine orders calls).
        unsafe {
            match op {
                Op::Instantiate => {
                    let [name, guid, uri] = region.three_strings();
                    let callbacks = callbacks_for(&self.log);
                    self.c = (f.instantiate)(
                        name.as_ptr(),
                        h.i[0] as c_int,
                        guid.as_ptr(),
                        uri.as_ptr(),
                        &*callbacks,
                        h.i[1] as c_int,
                        h.i[2] as c_int,
                    );
                    self._callbacks = Some(callbacks);
                    if self.c.is_null() {
                        3
                    } else {
                        0
                    }
                }
                Op::SetupExperiment => {
                    (f.setup_experiment)(c, h.i[0] as c_int, h.f[0], h.f[1], h.i[1] as c_int, h.f[2])
                }
                Op::EnterInitializationMode => (f.enter_initialization_mode)(c),
                Op::ExitInitializationMode => (f.exit_initialization_mode)(c),
                Op::Terminate => (f.terminate)(c),
                Op::Reset => f.reset.map_or(missing, |g| g(c)),
                Op::GetReal => (f.get_real)(c, vrs, n, data.add(after_vrs) as *mut f64),
                Op::GetInteger => (f.get_integer)(c, vrs, n, data.add(after_vrs) as *mut c_int),
                Op::GetBoolean => (f.get_boolean)(c, vrs, n, data.add(after_vrs) as *mut c_int),
                Op::GetString => get_strings(region, n, |ptrs| (f.get_string)(c, vrs, n, ptrs)),
                Op::SetString => {
                    let ptrs = self.strings_of(region, n);
                    (f.set_string)(c, vrs, n, ptrs.as_ptr())
                }
                Op::DoStep => f.do_step.map_or(missing, |g| g(c, h.f[0], h.f[1], h.i[0] as c_int)),
                Op::GetFmuState => state_handle(&mut h.i[0], |s| f.get_fmu_state.map_or(missing, |g| g(c, s))),
                Op::SetFmuState => f.set_fmu_state.map_or(missing, |g| g(c, h.i[0] as usize as *mut c_void)),
                Op::FreeFmuState => state_handle(&mut h.i[0], |s| f.free_fmu_state.map_or(missing, |g| g(c, s))),
                Op::GetBooleanStatus => {
                    let mut v: c_int = 0;
                    let r = f.get_boolean_status.map_or(missing, |g| g(c, h.i[0] as c_int, &mut v));
                    h.i[1] = v as i64;
                    r
                }
                Op::GetRealStatus => {
                    let mut v = 0.0;
                    let r = f.get_real_status.map_or(missing, |g| g(c, h.i[0] as c_int, &mut v));
                    h.f[0] = v;
                    r
                }
                Op::EnterEventMode => f.enter_event_mode.map_or(missing, |g| g(c)),
                Op::NewDiscreteStates => f.new_discrete_states.map_or(missing, |g| g(c, data as *mut EventInfo)),
                Op::EnterContinuousTimeMode => f.enter_continuous_time_mode.map_or(missing, |g| g(c)),
                Op::CompletedIntegratorStep => {
                    let (mut a, mut b) = (0, 0);
                    let r = f.completed_integrator_step.map_or(missing, |g| g(c, h.i[0] as c_int, &mut a, &mut b));
                    h.i[1] = a as i64;
                    h.i[2] = b as i64;
                    r
                }
                Op::SetTime => f.set_time.map_or(missing, |g| g(c, h.f[0])),
                Op::SetContinuousStates => f.set_continuous_states.map_or(missing, |g| g(c, data as *const f64, n)),
                Op::GetDerivatives => f.get_derivatives.map_or(missing, |g| g(c, data as *mut f64, n)),
                Op::GetEventIndicators => f.get_event_indicators.map_or(missing, |g| g(c, data as *mut f64, n)),
                Op::GetContinuousStates => f.get_continuous_states.map_or(missing, |g| g(c, data as *mut f64, n)),
                Op::GetNominalsOfContinuousStates => {
                    f.get_nominals_of_continuous_states.map_or(missing, |g| g(c, data as *mut f64, n))
                }
                Op::Free | Op::Flush => 0,
                _ => missing,
            }
        }
    }

    /// The strings the master wrote after the references (n of them, each NUL-ended),
    /// kept for the call; their pointers.
    ///
    /// # Safety
    /// The data area holds n NUL-ended strings after the references (proxy.rs).
    unsafe fn strings_of(&mut self, region: &Region, n: usize) -> Vec<*const c_char> {
        let data: *mut u8 = region.at(region.layout.data);
        self.strings.clear();
        let mut p = (4 * n).div_ceil(8) * 8;
        for _ in 0..n {
            let s = CStr::from_ptr(data.add(p) as *const c_char);
            p += s.to_bytes().len() + 1;
            self.strings.push(s.to_owned());
        }
        self.strings.iter().map(|s| s.as_ptr()).collect()
    }

    /// One fmi3 call.
    fn call3(&mut self, f: &Fmi3Functions, op: Op, region: &Region) -> i32 {
        let (h, l) = (region.header(), region.layout);
        let (n, data, vrs, after_vrs) = region.call_arrays();
        let c = self.c;
        let missing = 3;
        // SAFETY: as in call2: every pointer inside the data area, laid out by the proxy
        // for this op (proxy3.rs); the component live.
        unsafe {
            match op {
                Op::Instantiate3 => {
                    let [name, token, resources] = region.three_strings();
                    let environment = &*self.log as *const LogSink as *mut c_void;
                    let Some(g) = f.instantiate_co_simulation else { return missing };
                    // visible false, logging off, eventModeUsed as asked, early return
                    // allowed, no intermediate update: as `Instance::new_fmi3`
                    self.c = g(
                        name.as_ptr(),
                        token.as_ptr(),
                        resources.as_ptr(),
                        0,
                        0,
                        h.i[0] as u8,
                        1,
                        std::ptr::null(),
                        0,
                        environment,
                        Some(crate::log::log_message::<crate::log::LogSink>),
                        None,
                    );
                    if self.c.is_null() {
                        3
                    } else {
                        0
                    }
                }
                Op::InstantiateModelExchange3 => {
                    let [name, token, resources] = region.three_strings();
                    let environment = &*self.log as *const LogSink as *mut c_void;
                    let Some(g) = f.instantiate_model_exchange else { return missing };
                    // visible false, logging off: as `Instance::new_fmi3`
                    let logger =
                        Some(crate::log::log_message::<crate::log::LogSink> as fmi_sys::fmi3::Fmi3LogMessageCallback);
                    self.c = g(name.as_ptr(), token.as_ptr(), resources.as_ptr(), 0, 0, environment, logger);
                    if self.c.is_null() {
                        3
                    } else {
                        0
                    }
                }
                Op::EnterContinuousTimeMode3 => f.enter_continuous_time_mode.map_or(missing, |g| g(c)),
                Op::CompletedIntegratorStep3 => {
                    let (mut event, mut terminate) = (0u8, 0u8);
                    let r =
                        f.completed_integrator_step.map_or(missing, |g| g(c, h.i[0] as u8, &mut event, &mut terminate));
                    h.i[1] = i64::from(event);
                    h.i[2] = i64::from(terminate);
                    r
                }
                Op::SetTime3 => f.set_time.map_or(missing, |g| g(c, h.f[0])),
                Op::SetContinuousStates3 => f.set_continuous_states.map_or(missing, |g| g(c, data as *const f64, n)),
                Op::GetContinuousStateDerivatives3 => {
                    f.get_continuous_state_derivatives.map_or(missing, |g| g(c, data as *mut f64, n))
                }
                Op::GetEventIndicators3 => f.get_event_indicators.map_or(missing, |g| g(c, data as *mut f64, n)),
                Op::GetContinuousStates3 => f.get_continuous_states.map_or(missing, |g| g(c, data as *mut f64, n)),
                Op::GetNominalsOfContinuousStates3 => {
                    f.get_nominals_of_continuous_states.map_or(missing, |g| g(c, data as *mut f64, n))
                }
                Op::EnterInitializationMode3 => {
                    (f.enter_initialization_mode)(c, h.i[0] as u8, h.f[0], h.f[1], h.i[1] as u8, h.f[2])
                }
                Op::ExitInitializationMode3 => (f.exit_initialization_mode)(c),
                Op::Terminate3 => (f.terminate)(c),
                Op::Reset3 => f.reset.map_or(missing, |g| g(c)),
                Op::Get3 | Op::Set3 => {
                    let Some(ty) = fmi3_type(h.i[0]) else { return missing };
                    typed(f, ty, op == Op::Set3, c, vrs, n, data.add(after_vrs), h.i[1] as usize)
                }
                Op::GetString3 => {
                    let Some(g) = f.get_string else { return missing };
                    get_strings(region, n, |ptrs| g(c, vrs, n, ptrs, n))
                }
                Op::GetBinary3 => {
                    let Some(g) = f.get_binary else { return missing };
                    let n_values = h.i[1] as usize;
                    let mut sizes = vec![0usize; n_values];
                    let mut values: Vec<*const u8> = vec![std::ptr::null(); n_values];
                    let s = g(c, vrs, n, sizes.as_mut_ptr(), values.as_mut_ptr(), n_values);
                    let mut p = after_vrs + 8 * n_values;
                    let needs = p + sizes.iter().sum::<usize>();
                    if needs > l.data_len {
                        h.answer_needs = needs as u64;
                        return 3;
                    }
                    for (k, (size, value)) in sizes.iter().zip(&values).enumerate() {
                        *(data.add(after_vrs + 8 * k) as *mut u64) = *size as u64;
                        if *size > 0 && !value.is_null() {
                            std::ptr::copy_nonoverlapping(*value, data.add(p), *size);
                        }
                        p += size;
                    }
                    s
                }
                Op::SetString3 => {
                    let Some(g) = f.set_string else { return missing };
                    let ptrs = self.strings_of(region, n);
                    g(c, vrs, n, ptrs.as_ptr(), n)
                }
                Op::DoStep3 => {
                    let (mut event, mut terminate, mut early, mut reached) = (0u8, 0u8, 0u8, h.f[0]);
                    let r = f.do_step.map_or(missing, |g| {
                        g(c, h.f[0], h.f[1], h.i[0] as u8, &mut event, &mut terminate, &mut early, &mut reached)
                    });
                    h.i[1] = i64::from(event);
                    h.i[2] = i64::from(terminate);
                    h.i[3] = i64::from(early);
                    h.f[2] = reached;
                    r
                }
                Op::EnterEventMode3 => f.enter_event_mode.map_or(missing, |g| g(c)),
                Op::EnterStepMode3 => f.enter_step_mode.map_or(missing, |g| g(c)),
                Op::UpdateDiscreteStates3 => {
                    // the five Booleans as bytes 0..5, nextEventTime at byte 8
                    let b = data;
                    f.update_discrete_states
                        .map_or(missing, |g| g(c, b, b.add(1), b.add(2), b.add(3), b.add(4), b.add(8) as *mut f64))
                }
                // the clock calls: their arrays after the references, as the proxy laid them out
                Op::SetClock3 => {
                    let ([a], _) = clock_arrays(n, [1]);
                    f.set_clock.map_or(missing, |g| g(c, vrs, n, data.add(a)))
                }
                Op::GetClock3 => {
                    let ([a], _) = clock_arrays(n, [1]);
                    f.get_clock.map_or(missing, |g| g(c, vrs, n, data.add(a)))
                }
                Op::GetIntervalDecimal3 => {
                    let ([v, q], _) = clock_arrays(n, [8, 4]);
                    f.get_interval_decimal
                        .map_or(missing, |g| g(c, vrs, n, data.add(v) as *mut f64, data.add(q) as *mut c_int))
                }
                Op::GetIntervalFraction3 => {
                    let ([k, r, q], _) = clock_arrays(n, [8, 8, 4]);
                    f.get_interval_fraction.map_or(missing, |g| {
                        g(c, vrs, n, data.add(k) as *mut u64, data.add(r) as *mut u64, data.add(q) as *mut c_int)
                    })
                }
                Op::GetShiftDecimal3 => {
                    let ([v], _) = clock_arrays(n, [8]);
                    f.get_shift_decimal.map_or(missing, |g| g(c, vrs, n, data.add(v) as *mut f64))
                }
                Op::GetShiftFraction3 => {
                    let ([k, r], _) = clock_arrays(n, [8, 8]);
                    f.get_shift_fraction
                        .map_or(missing, |g| g(c, vrs, n, data.add(k) as *mut u64, data.add(r) as *mut u64))
                }
                Op::SetIntervalDecimal3 => {
                    let ([v], _) = clock_arrays(n, [8]);
                    f.set_interval_decimal.map_or(missing, |g| g(c, vrs, n, data.add(v) as *const f64))
                }
                Op::GetFmuState3 => state_handle(&mut h.i[0], |s| f.get_fmu_state.map_or(missing, |g| g(c, s))),
                Op::SetFmuState3 => f.set_fmu_state.map_or(missing, |g| g(c, h.i[0] as usize as *mut c_void)),
                Op::FreeFmuState3 => state_handle(&mut h.i[0], |s| f.free_fmu_state.map_or(missing, |g| g(c, s))),
                Op::Free | Op::Flush => 0,
                _ => missing,
            }
        }
    }
}

/// A string getter's results (`call` fills the n pointers) copied after the references,
/// each NUL-ended; a status 3 if they do not fit.
///
/// # Safety
/// `call` writes n pointers, each null or to a NUL-ended string.
unsafe fn get_strings(region: &Region, n: usize, call: impl FnOnce(*mut *const c_char) -> c_int) -> c_int {
    let data: *mut u8 = region.at(region.layout.data);
    let mut ptrs: Vec<*const c_char> = vec![std::ptr::null(); n];
    let s = call(ptrs.as_mut_ptr());
    let mut p = (4 * n).div_ceil(8) * 8;
    let text = |q: *const c_char| if q.is_null() { &[][..] } else { CStr::from_ptr(q).to_bytes() };
    let needs = p + ptrs.iter().map(|q| text(*q).len() + 1).sum::<usize>();
    if needs > region.layout.data_len {
        region.header().answer_needs = needs as u64;
        return 3;
    }
    for q in ptrs {
        let bytes = text(q);
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), data.add(p), bytes.len());
        *data.add(p + bytes.len()) = 0;
        p += bytes.len() + 1;
    }
    s
}

/// The typed `fmi3Get*` / `fmi3Set*` of `ty` (absent from the library: 3).
///
/// # Safety
/// `vrs` holds n references and `values` room for `n_values` values of `ty`, 8-aligned.
#[allow(clippy::too_many_arguments)]
unsafe fn typed(
    f: &Fmi3Functions,
    ty: ValueType,
    set: bool,
    c: *mut c_void,
    vrs: *const u32,
    n: usize,
    values: *mut u8,
    n_values: usize,
) -> c_int {
    macro_rules! go {
        ($get:ident, $set:ident, $t:ty) => {
            if set {
                f.$set.map_or(3, |g| g(c, vrs, n, values as *const $t, n_values))
            } else {
                f.$get.map_or(3, |g| g(c, vrs, n, values as *mut $t, n_values))
            }
        };
    }
    match ty {
        ValueType::Float64 if set => (f.set_float64)(c, vrs, n, values as *const f64, n_values),
        ValueType::Float64 => (f.get_float64)(c, vrs, n, values as *mut f64, n_values),
        ValueType::Float32 => go!(get_float32, set_float32, f32),
        ValueType::Int8 => go!(get_int8, set_int8, i8),
        ValueType::UInt8 => go!(get_uint8, set_uint8, u8),
        ValueType::Int16 => go!(get_int16, set_int16, i16),
        ValueType::UInt16 => go!(get_uint16, set_uint16, u16),
        ValueType::Int32 => go!(get_int32, set_int32, i32),
        ValueType::UInt32 => go!(get_uint32, set_uint32, u32),
        ValueType::Int64 => go!(get_int64, set_int64, i64),
        ValueType::UInt64 => go!(get_uint64, set_uint64, u64),
        ValueType::Boolean => go!(get_boolean, set_boolean, u8),
        _ => 3,
    }
}
