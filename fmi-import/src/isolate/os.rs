//! What isolation needs of the operating system: a memory region shared with the host
//! process (`memfd_create` + `mmap`), the host process itself (dying with the master through
//! `PR_SET_PDEATHSIG`, polled with `waitpid`, killed with SIGKILL) and sleeping on a word of
//! the region (`futex`). All of it is Linux's; on other systems (Windows, macOS) a region
//! cannot be made, so no host starts and the master says so ([`unsupported`]) before it
//! loads anything: the types below are then uninhabited and their methods unreachable.

use crate::error::HostEnd;
use std::sync::atomic::AtomicU32;
use std::time::Duration;

/// The operating system this build runs on, as users name it.
pub fn os_name() -> &'static str {
    match std::env::consts::OS {
        "windows" => "Windows",
        "macos" => "macOS",
        "linux" => "Linux",
        other => other,
    }
}

/// Why isolation is not available in this build, `None` on Linux, where it is.
pub fn unsupported() -> Option<String> {
    (!cfg!(target_os = "linux")).then(|| {
        format!(
            "isolation (--isolate: FMUs or the run in host processes over shared memory and futexes) is \
             available on Linux only, not on {}: run without --isolate",
            os_name()
        )
    })
}

#[cfg(target_os = "linux")]
mod imp {
    use super::*;
    use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};

    /// `memfd_create(2)` by its system call: glibc wraps it from 2.27 on, and the release
    /// builds link against glibc 2.17 (Linux has the call since 3.17).
    pub fn memfd_create(name: &std::ffi::CStr, flags: libc::c_uint) -> std::io::Result<OwnedFd> {
        // SAFETY: the name is NUL-terminated; the call returns a fresh descriptor or -1.
        let raw = unsafe { libc::syscall(libc::SYS_memfd_create, name.as_ptr(), flags) };
        if raw < 0 {
            return Err(std::io::Error::last_os_error());
        }
        // SAFETY: `raw` is a fresh descriptor we own.
        Ok(unsafe { OwnedFd::from_raw_fd(raw as i32) })
    }

    /// A region of `len` bytes shared with a child process, zeroed when made.
    pub(crate) struct SharedRegion {
        base: *mut u8,
        len: usize,
        fd: OwnedFd,
    }

    impl SharedRegion {
        /// A fresh region of `len` bytes (`name` shows in /proc/PID/fd).
        pub(crate) fn create(name: &std::ffi::CStr, len: usize) -> Result<SharedRegion, String> {
            let fd = memfd_create(name, 0).map_err(|e| format!("memfd_create: {e}"))?;
            // SAFETY: a descriptor we own, a size in range.
            if unsafe { libc::ftruncate(fd.as_raw_fd(), len as libc::off_t) } != 0 {
                return Err(format!("ftruncate: {}", std::io::Error::last_os_error()));
            }
            let base = map(fd.as_raw_fd(), len)?;
            Ok(SharedRegion { base, len, fd })
        }

        /// The start of the mapping.
        pub(crate) fn base(&self) -> *mut u8 {
            self.base
        }

        /// What the child is given to map the region ([`map_inherited`]): the descriptor's number.
        pub(crate) fn handle_argument(&self) -> String {
            self.fd.as_raw_fd().to_string()
        }
    }

    impl Drop for SharedRegion {
        fn drop(&mut self) {
            // SAFETY: the mapping made in `create`, unmapped once.
            unsafe {
                libc::munmap(self.base as *mut libc::c_void, self.len);
            }
        }
    }

    fn map(fd: i32, len: usize) -> Result<*mut u8, String> {
        // SAFETY: maps `len` bytes of the descriptor shared, read-write.
        let base = unsafe {
            libc::mmap(std::ptr::null_mut(), len, libc::PROT_READ | libc::PROT_WRITE, libc::MAP_SHARED, fd, 0)
        };
        if base == libc::MAP_FAILED {
            return Err(format!("mmap: {}", std::io::Error::last_os_error()));
        }
        Ok(base as *mut u8)
    }

    /// In the host: maps the region the master passed as `handle` ([`SharedRegion::handle_argument`]),
    /// of `len` bytes, for the rest of the process's life.
    pub(crate) fn map_inherited(handle: &str, len: usize) -> Result<*mut u8, String> {
        let fd = handle.parse::<i32>().map_err(|_| format!("bad descriptor {handle:?}"))?;
        map(fd, len)
    }

    /// A host process, a child of the master that dies with it.
    pub(crate) struct HostProcess {
        pid: libc::pid_t,
    }

    impl HostProcess {
        /// Starts `command` so that the child gets SIGKILL when the master ends.
        pub(crate) fn spawn(mut command: std::process::Command) -> std::io::Result<HostProcess> {
            // SAFETY: runs in the child between fork and exec: only async-signal-safe calls
            // (prctl). The host dies with the master.
            unsafe {
                use std::os::unix::process::CommandExt;
                command.pre_exec(|| {
                    libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
                    Ok(())
                });
            }
            let child = command.spawn()?;
            let pid = child.id() as libc::pid_t;
            std::mem::forget(child); // reaped by waitpid in `try_wait` or `kill`
            Ok(HostProcess { pid })
        }

        /// The host's end if it has ended (then reaped); `None` while it runs.
        pub(crate) fn try_wait(&self) -> Option<HostEnd> {
            let mut status: libc::c_int = 0;
            // SAFETY: our own child; WNOHANG does not block.
            let r = unsafe { libc::waitpid(self.pid, &mut status, libc::WNOHANG) };
            if r != self.pid {
                return None;
            }
            if libc::WIFSIGNALED(status) {
                return Some(HostEnd::Signal(libc::WTERMSIG(status)));
            }
            Some(HostEnd::Exit(libc::WEXITSTATUS(status)))
        }

        /// Kills the host and reaps it (call once, on a host not yet reaped).
        pub(crate) fn kill(&self) {
            // SAFETY: our own child, not yet reaped (its pid is still ours).
            unsafe {
                libc::kill(self.pid, libc::SIGKILL);
                libc::waitpid(self.pid, std::ptr::null_mut(), 0);
            }
        }
    }

    /// Sleeps until `word` (in shared memory) is woken or no longer `old`, at most `slice`.
    pub(crate) fn sleep_on(word: &AtomicU32, old: u32, slice: Duration) {
        let ts =
            libc::timespec { tv_sec: slice.as_secs() as libc::time_t, tv_nsec: slice.subsec_nanos() as libc::c_long };
        // SAFETY: `word` is a live u32 in shared memory; FUTEX_WAIT (not private: the
        // region is shared between processes) returns when woken, on timeout or at once
        // if the word is no longer `old`.
        unsafe {
            libc::syscall(libc::SYS_futex, word.as_ptr(), libc::FUTEX_WAIT, old, &ts as *const libc::timespec);
        }
    }

    /// Wakes every sleeper on `word`.
    pub(crate) fn wake(word: &AtomicU32) {
        // SAFETY: `word` is a live u32 in shared memory; wakes every waiter on it.
        unsafe {
            libc::syscall(libc::SYS_futex, word.as_ptr(), libc::FUTEX_WAKE, i32::MAX);
        }
    }
}

#[cfg(not(target_os = "linux"))]
mod imp {
    use super::*;

    /// No region can be made here ([`unsupported`]): uninhabited.
    pub(crate) enum SharedRegion {}

    impl SharedRegion {
        pub(crate) fn create(_name: &std::ffi::CStr, _len: usize) -> Result<SharedRegion, String> {
            Err(unsupported().unwrap_or_default())
        }

        pub(crate) fn base(&self) -> *mut u8 {
            match *self {}
        }

        pub(crate) fn handle_argument(&self) -> String {
            match *self {}
        }
    }

    pub(crate) fn map_inherited(_handle: &str, _len: usize) -> Result<*mut u8, String> {
        Err(unsupported().unwrap_or_default())
    }

    /// No host starts here: uninhabited.
    pub(crate) enum HostProcess {}

    impl HostProcess {
        pub(crate) fn spawn(_command: std::process::Command) -> std::io::Result<HostProcess> {
            Err(std::io::Error::new(std::io::ErrorKind::Unsupported, unsupported().unwrap_or_default()))
        }

        pub(crate) fn try_wait(&self) -> Option<HostEnd> {
            match *self {}
        }

        pub(crate) fn kill(&self) {
            match *self {}
        }
    }

    /// Without a region nobody waits on one; a plain sleep keeps the waiting loop correct.
    pub(crate) fn sleep_on(_word: &AtomicU32, _old: u32, slice: Duration) {
        std::thread::sleep(slice);
    }

    pub(crate) fn wake(_word: &AtomicU32) {}
}

#[cfg(target_os = "linux")]
pub use imp::memfd_create;
pub(crate) use imp::{map_inherited, sleep_on, wake, HostProcess, SharedRegion};
