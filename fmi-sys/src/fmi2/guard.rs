//! The importer's memory callbacks (`allocateMemory`, `freeMemory`): calloc and free with
//! a red zone of [`RED_ZONE`] bytes of a known pattern after every block, so that an FMU
//! that writes a little past a block it allocated writes into the red zone, not into the
//! heap's own bookkeeping (which glibc finds later and aborts on, far from the write).
//!
//! The blocks alive are kept by owner, the instance whose call allocated them: the
//! allocator has no `componentEnvironment` argument, so the importer marks each call it makes
//! with the calling instance's `componentEnvironment` (in the mark of the call in progress it
//! keeps anyway, one thread-local) and tells this module how to read it ([`owners_from`]);
//! a block allocated during the call belongs to that instance (an FMU's calls run on the
//! thread that called it; a block allocated on a thread of the FMU's own, or with no
//! importer's function told, has owner 0).
//! [`overruns_of`] tells how many blocks of one owner have had their red zone written,
//! alive or freed, and the first such write it saw, reading that owner's blocks only; an
//! importer compares it before and after a call to know whether the call wrote past a block
//! of its instance (MapleSim 2023's ControlledTemperature writes 16 bytes past a 48-byte
//! block of its own in `fmi2GetDirectionalDerivative`), and with several instances in
//! threads one instance's write is never blamed on another's call. [`overruns`] is the
//! process's count. The pointer the FMU receives is
//! calloc's own, so an FMU that frees it with `free` instead of `freeMemory` still works;
//! its table entry then stays, and the red zone is read through a system call that fails
//! instead of faulting ([`read_own_memory`]), so reading it never crashes. Memory an FMU
//! gets from `malloc` itself, and FMI 3.0 (no memory callbacks), are not guarded.
//!
//! ```
//! use fmi_sys::fmi2::guard::{allocate, overruns_of, owners_from, release};
//! let owner = 0x5eed; // an instance's componentEnvironment
//! // the importer's mark of the call in progress on this thread (here: always that instance)
//! owners_from(|| 0x5eed);
//! let p = unsafe { allocate(6, 8) as *mut f64 };
//! unsafe {
//!     *p.add(6) = 1.0; // one past the six doubles: into the red zone
//!     assert_eq!(overruns_of(owner).count, 1);
//!     assert_eq!(overruns_of(owner + 1).count, 0, "another instance's count");
//!     release(p.cast());
//! }
//! assert_eq!(overruns_of(owner).count, 1);
//! ```

use std::collections::BTreeMap;
use std::ffi::{c_char, c_void};
use std::sync::{Mutex, OnceLock};

/// The bytes after every block that an overrun writes into harmlessly (and is seen in).
pub const RED_ZONE: usize = 64;
const PATTERN: u8 = 0xA5;

/// The blocks alive: (owner, address) -> the size the FMU asked for.
static LIVE: Mutex<BTreeMap<(usize, usize), usize>> = Mutex::new(BTreeMap::new());
/// The owner of each block alive: address -> owner.
static OWNER_OF: Mutex<BTreeMap<usize, usize>> = Mutex::new(BTreeMap::new());
/// By owner: blocks freed with their red zone written, and the first overrun seen (block
/// size, bytes written past it).
static SEEN: Mutex<BTreeMap<usize, Seen>> = Mutex::new(BTreeMap::new());

#[derive(Clone, Copy, Debug, Default)]
struct Seen {
    freed_overrun: u64,
    first: Option<(usize, usize)>,
}

/// The importer's function that tells the owner of the call in progress on the calling
/// thread (0: none), told once ([`owners_from`]).
static OWNER_OF_CALL: OnceLock<fn() -> usize> = OnceLock::new();

/// Tells the function that gives the owner of the call in progress on the calling thread
/// (the calling instance's `componentEnvironment`, 0 outside any call): the blocks
/// [`allocate`] gives during a call are that instance's. The first function told stays
/// (one importer per process marks the calls).
pub fn owners_from(owner_of_call: fn() -> usize) {
    let _ = OWNER_OF_CALL.set(owner_of_call);
}

/// The owner of the blocks allocated on this thread now (0: none marked).
fn owner_now() -> usize {
    OWNER_OF_CALL.get().map_or(0, |owner_of_call| owner_of_call())
}

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

fn lock<T>(m: &'static Mutex<T>) -> std::sync::MutexGuard<'static, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
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

fn note_overrun(owner: usize, size: usize, past: usize, freed: bool) {
    let mut seen = lock(&SEEN);
    let s = seen.entry(owner).or_default();
    s.freed_overrun += u64::from(freed);
    s.first.get_or_insert((size, past));
}

/// The overruns of the blocks of `owner` so far: its blocks alive are read now (one
/// `process_vm_readv` each), no other's.
pub fn overruns_of(owner: usize) -> Overruns {
    let blocks: Vec<(usize, usize)> =
        lock(&LIVE).range((owner, 0)..=(owner, usize::MAX)).map(|(&(_, at), &size)| (at, size)).collect();
    let mut count = 0;
    for (at, size) in blocks {
        let past = written_past(at, size);
        if past > 0 {
            count += 1;
            note_overrun(owner, size, past, false);
        }
    }
    let seen = lock(&SEEN).get(&owner).copied().unwrap_or_default();
    Overruns { count: count + seen.freed_overrun, first: seen.first }
}

/// The overruns of every owner's blocks so far (the process's).
pub fn overruns() -> Overruns {
    let owners: Vec<usize> = {
        let mut o: Vec<usize> = lock(&LIVE).keys().map(|(owner, _)| *owner).collect();
        o.extend(lock(&SEEN).keys());
        o.sort_unstable();
        o.dedup();
        o
    };
    let mut all = Overruns::default();
    for owner in owners {
        let o = overruns_of(owner);
        all.count += o.count;
        all.first = all.first.or(o.first);
    }
    all
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
    let owner = owner_now();
    lock(&LIVE).insert((owner, p as usize), bytes);
    lock(&OWNER_OF).insert(p as usize, owner);
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
    let owner = lock(&OWNER_OF).remove(&(p as usize));
    if let Some(size) = owner.and_then(|owner| lock(&LIVE).remove(&(owner, p as usize))) {
        let past = written_past(p as usize, size);
        if past > 0 {
            note_overrun(owner.unwrap_or(0), size, past, true);
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
