//! The marker of the FMU call in progress: which instance, which function, at what time,
//! and which instance owns the memory the FMU allocates in it (fmi-sys's `fmi2::guard`
//! reads that through [`owner_of_call`]: one thread-local for both).
//!
//! Every call into an FMU is marked (two stores per call, a thread-local): the master's
//! `atexit` handler reads the mark when an FMU ends the process with `exit()` inside a call
//! ([`current_call`]), and a process that is the host of a whole run or a campaign's worker
//! also copies it into a region shared with its parent ([`mark_calls_in`]), which reads it
//! after a crash. The marker holds pointers to the instance's name and its FMU's path, both
//! alive for the whole call it marks; they are read only in the calling thread. Only
//! thread-local `Cell`s of `Copy` values are read: they have no destructor, so glibc's run
//! of thread-local destructors before the `atexit` handlers leaves them intact.

use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicPtr, AtomicU32, AtomicU64, AtomicUsize, Ordering};

/// The call an FMU was in when it called `exit()`.
#[derive(Clone, Debug)]
pub struct ExitInsideCall {
    /// The instance.
    pub instance: String,
    /// The FMU's archive ([`Fmu::source`](crate::Fmu::source)).
    pub fmu: PathBuf,
    /// The FMI function.
    pub function: &'static str,
    /// The time the instance was at (the step's start for `fmi2DoStep`), s.
    pub time: f64,
}

impl std::fmt::Display for ExitInsideCall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let file = self.fmu.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        write!(
            f,
            "{} ({file}) called exit() inside {} at t = {} s, ending the process in the middle of the run",
            self.instance, self.function, self.time
        )
    }
}

#[derive(Clone, Copy)]
struct Site {
    instance: *const str,
    fmu: *const Path,
    function: &'static str,
    time: f64,
    /// The instance's `componentEnvironment`, which owns the blocks the FMU allocates in
    /// the call (fmi-sys's `fmi2::guard` reads it through [`owner_of_call`]): one
    /// thread-local per call for both.
    owner: usize,
}

thread_local! {
    static CALL: Cell<Option<Site>> = const { Cell::new(None) };
}

/// Bytes kept of an instance's or a function's name in [`CallSlots`].
pub const NAME: usize = 128;

/// The call marker as a region shared with another process lays it out.
#[repr(C)]
pub struct CallSlots {
    /// 1 while a call is in progress.
    pub in_call: AtomicU32,
    /// The call's time, as `f64` bits.
    pub time: AtomicU64,
    /// Bytes of `instance` in use.
    pub instance_len: AtomicU32,
    /// Bytes of `function` in use.
    pub function_len: AtomicU32,
    /// The instance's name (cut to [`NAME`] bytes).
    pub instance: [u8; NAME],
    /// The function's name.
    pub function: [u8; NAME],
}

impl CallSlots {
    /// The last call marked: instance, function, time, and whether it was still in it.
    pub fn last_call(&self) -> (String, String, f64, bool) {
        let il = (self.instance_len.load(Ordering::Acquire) as usize).min(NAME);
        let fl = (self.function_len.load(Ordering::Acquire) as usize).min(NAME);
        (
            String::from_utf8_lossy(&self.instance[..il]).into_owned(),
            String::from_utf8_lossy(&self.function[..fl]).into_owned(),
            f64::from_bits(self.time.load(Ordering::Acquire)),
            self.in_call.load(Ordering::Acquire) == 1,
        )
    }
}

/// The shared slots calls are copied into (null: none).
static SHARED: AtomicPtr<CallSlots> = AtomicPtr::new(std::ptr::null_mut());
/// The function last written into the shared slots (its address).
static LAST_FUNCTION: AtomicUsize = AtomicUsize::new(0);

/// From now on, copies each marked call into `slots` too (null: stops). Only for a
/// process that simulates in one thread: one marker holds one call.
///
/// # Safety
/// `slots` must stay valid (mapped) until this is called again with another pointer.
pub unsafe fn mark_calls_in(slots: *mut CallSlots) {
    LAST_FUNCTION.store(0, Ordering::Relaxed);
    SHARED.store(slots, Ordering::Release);
}

#[inline]
fn copy_name(dst: &mut [u8; NAME], len: &AtomicU32, s: &str) {
    let b = s.as_bytes();
    let n = b.len().min(NAME);
    if n <= 16 {
        // a short name byte by byte: cheaper than a call of memcpy
        for (d, c) in dst.iter_mut().zip(&b[..n]) {
            *d = *c;
        }
    } else {
        dst[..n].copy_from_slice(&b[..n]);
    }
    len.store(n as u32, Ordering::Relaxed);
}

/// The mark of a call in progress; the previous mark comes back when it is dropped.
pub(crate) struct InCall(Option<Site>, bool);

/// Marks the call `function` of `instance` (of the FMU archive `fmu`) at `time` as in progress in this
/// thread, the blocks the FMU allocates in it owned by `owner` (the instance's
/// `componentEnvironment`; [`owner_of_call`] for the owner of the call this one is in).
#[inline]
pub(crate) fn enter(instance: &str, fmu: &Path, function: &'static str, time: f64, owner: usize) -> InCall {
    let site = Site { instance, fmu, function, time, owner };
    let p = SHARED.load(Ordering::Relaxed);
    let shared = !p.is_null();
    if shared {
        // SAFETY: the slots stay mapped while they are registered (`mark_calls_in`); only
        // the simulating thread writes them.
        let h = unsafe { &mut *p };
        // the instance's name every time (a freed name's address may come back with another);
        // the function's only when it changes (a static string)
        copy_name(&mut h.instance, &h.instance_len, instance);
        // plain loads and stores, no locked instruction: one thread writes the marker
        if LAST_FUNCTION.load(Ordering::Relaxed) != function.as_ptr() as usize {
            LAST_FUNCTION.store(function.as_ptr() as usize, Ordering::Relaxed);
            copy_name(&mut h.function, &h.function_len, function);
        }
        h.time.store(time.to_bits(), Ordering::Relaxed);
        h.in_call.store(1, Ordering::Release);
    }
    InCall(CALL.with(|c| c.replace(Some(site))), shared)
}

impl Drop for InCall {
    #[inline]
    fn drop(&mut self) {
        CALL.with(|c| c.set(self.0));
        if self.1 {
            let p = SHARED.load(Ordering::Relaxed);
            if !p.is_null() {
                // SAFETY: as in `enter`.
                unsafe { (*p).in_call.store(0, Ordering::Release) };
            }
        }
    }
}

/// The owner of the call this thread is in (0: none, or the thread-local is gone): the
/// function fmi-sys's `fmi2::guard` reads the owner of a block through
/// (`fmi_sys::fmi2::guard::owners_from`).
pub(crate) fn owner_of_call() -> usize {
    CALL.try_with(|c| c.get().map_or(0, |site| site.owner)).unwrap_or(0)
}

/// The call this thread is in (`None`: none, or the thread-local is gone). For the
/// master's `atexit` handler, which runs in the thread that called `exit()`.
pub fn current_call() -> Option<ExitInsideCall> {
    let site = CALL.try_with(|c| c.get()).ok().flatten()?;
    // SAFETY: the pointers of a mark are alive for the call it marks, and that call is in
    // progress in this very thread.
    Some(unsafe {
        ExitInsideCall {
            instance: (*site.instance).to_string(),
            fmu: (*site.fmu).to_path_buf(),
            function: site.function,
            time: site.time,
        }
    })
}
