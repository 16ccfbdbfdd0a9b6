//! The importer's memory callbacks (`allocateMemory`, `freeMemory`): calloc and free with
//! a red zone of [`RED_ZONE`] bytes of a known pattern after every block, so that an FMU
//! that writes a little past a block it allocated writes into the red zone, not into the
//! heap's own bookkeeping (which glibc finds later and aborts on, far from the write).
//!
//! The blocks alive are kept in one table (address, size): [`overruns`] tells how many
//! blocks have had their red zone written, alive or freed, and the first such write it
//! saw. An importer compares it before and after a call to know whether the call wrote
//! past a block (MapleSim 2023's ControlledTemperature writes 16 bytes past a 48-byte
//! block of its own in `fmi2GetDirectionalDerivative`). The pointer the FMU receives is
//! calloc's own, so an FMU that frees it with `free` instead of `freeMemory` still works;
//! its table entry then stays, and the red zone is read through a system call that fails
//! instead of faulting ([`read_own_memory`]), so reading it never crashes. Memory an FMU
//! gets from `malloc` itself, and FMI 3.0 (no memory callbacks), are not guarded.
//!
//! ```
//! use fmi_sys::fmi2::guard::{allocate, overruns, release};
//! let before = overruns().count;
//! unsafe {
//!     let p = allocate(6, 8) as *mut f64;
//!     *p.add(6) = 1.0; // one past the six doubles: into the red zone
//!     assert_eq!(overruns().count, before + 1);
//!     release(p.cast());
//! }
//! assert_eq!(overruns().count, before + 1);
//! ```

use std::collections::BTreeMap;
use std::ffi::{c_char, c_void};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// The bytes after every block that an overrun writes into harmlessly (and is seen in).
pub const RED_ZONE: usize = 64;
const PATTERN: u8 = 0xA5;

/// The blocks alive: address -> the size the FMU asked for.
static LIVE: Mutex<BTreeMap<usize, usize>> = Mutex::new(BTreeMap::new());
/// Blocks freed with their red zone written.
static FREED_OVERRUN: AtomicU64 = AtomicU64::new(0);
/// The first overrun seen (block size, bytes written past it), 0 when none.
static FIRST: Mutex<(usize, usize)> = Mutex::new((0, 0));

extern "C" {
    fn calloc(n: usize, size: usize) -> *mut c_void;
    fn free(p: *mut c_void);
    fn fmi2_sys_read_own_memory(at: usize, out: *mut c_char, n: usize) -> std::ffi::c_long;
}

/// What [`overruns`] found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Overruns {
    /// Blocks whose red zone was written (alive now or freed before), since the process began.
    pub count: u64,
    /// The first overrun seen: the block's size and how many bytes past it were written.
    pub first: Option<(usize, usize)>,
}

fn live() -> std::sync::MutexGuard<'static, BTreeMap<usize, usize>> {
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// How many bytes past the block of `size` bytes at `at` were written (the last red-zone
/// byte that lost its pattern, counted from the block's end), 0 when none; a red zone that
/// cannot be read (an entry of a block freed with `free` and unmapped) counts as none.
fn written_past(at: usize, size: usize) -> usize {
    let mut zone = [PATTERN; RED_ZONE];
    // SAFETY: the system call reads this process's memory into `zone` or fails.
    let got = unsafe { fmi2_sys_read_own_memory(at + size, zone.as_mut_ptr().cast(), RED_ZONE) };
    if got != RED_ZONE as std::ffi::c_long {
        return 0;
    }
    zone.iter().rposition(|b| *b != PATTERN).map_or(0, |k| k + 1)
}

fn note_first(size: usize, past: usize) {
    let mut first = FIRST.lock().unwrap_or_else(|e| e.into_inner());
    if first.1 == 0 {
        *first = (size, past);
    }
}

/// The overruns so far: the blocks alive are read now.
pub fn overruns() -> Overruns {
    let mut count = FREED_OVERRUN.load(Ordering::Relaxed);
    for (&at, &size) in live().iter() {
        let past = written_past(at, size);
        if past > 0 {
            count += 1;
            note_first(size, past);
        }
    }
    let first = *FIRST.lock().unwrap_or_else(|e| e.into_inner());
    Overruns { count, first: (first.1 > 0).then_some(first) }
}

/// `allocateMemory`: calloc's contract (zeroed, null when `n * size` overflows or memory
/// is out), the block followed by its red zone.
///
/// # Safety
/// Any arguments; the block is freed with [`release`] (or `free`).
pub unsafe extern "C" fn allocate(n: usize, size: usize) -> *mut c_void {
    let Some(bytes) = n.checked_mul(size) else { return std::ptr::null_mut() };
    let Some(total) = bytes.checked_add(RED_ZONE) else { return std::ptr::null_mut() };
    let p = calloc(total, 1);
    if p.is_null() {
        return p;
    }
    std::ptr::write_bytes(p.cast::<u8>().add(bytes), PATTERN, RED_ZONE);
    live().insert(p as usize, bytes);
    p
}

/// `freeMemory`: the red zone checked, then free.
///
/// # Safety
/// `p` is null or a block of [`allocate`] not freed yet.
pub unsafe extern "C" fn release(p: *mut c_void) {
    if p.is_null() {
        return;
    }
    if let Some(size) = live().remove(&(p as usize)) {
        let past = written_past(p as usize, size);
        if past > 0 {
            FREED_OVERRUN.fetch_add(1, Ordering::Relaxed);
            note_first(size, past);
        }
    }
    free(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A write into a block is none; one byte past it and 16 bytes past it (MapleSim's two
    /// doubles) are seen with their distance; calloc's zeroes.
    #[test]
    fn writes_past_a_block_are_seen_and_counted_once() {
        unsafe {
            let p = allocate(3, 16) as *mut u8;
            assert!((0..48).all(|k| *p.add(k) == 0));
            *p.add(47) = 1;
            assert_eq!(written_past(p as usize, 48), 0);
            *p.add(48) = 1;
            assert_eq!(written_past(p as usize, 48), 1);
            *p.add(48 + 15) = 1;
            assert_eq!(written_past(p as usize, 48), 16);
            let before = overruns().count;
            release(p.cast());
            assert_eq!(overruns().count, before, "counted once, alive or freed");
            assert!(allocate(usize::MAX, 2).is_null());
            assert!(allocate(1, usize::MAX - 8).is_null());
        }
    }

    /// The size docs/third-party-fmus.md prints is this one.
    #[test]
    fn the_doc_prints_the_red_zone() {
        let doc = include_str!("../../../docs/third-party-fmus.md").split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(doc.contains(&format!("keep a red zone of {RED_ZONE} bytes after every block")));
    }
}
