//! Worker processes where the master has no isolation (Windows, macOS:
//! [`nigel_cosim::isolate::os::unsupported`]): `campaign run` runs its workers as threads
//! there (as `--in-process`, and says so); these are the same functions as on Linux, refusing.

use std::path::Path;

use crate::collector::Collector;
use crate::spec::Spec;
use crate::Error;

/// Why worker processes are not available in this build.
pub fn unsupported() -> String {
    format!(
        "worker processes (a crash boundary per worker, a timeout inside a call) are available on Linux only, not on {}: \
         the runs go in threads of this process (--in-process)",
        nigel_cosim::isolate::os::os_name()
    )
}

/// As on Linux, the temporary folders of this process removed on a stop signal.
pub fn remove_tmpdir_on_signals() {
    nigel_cosim::unpack::remove_on_signals();
}

/// A worker process: refused (exit code 1, the reason on standard error).
pub fn serve(_spec_path: &Path, _hash: &str) -> i32 {
    eprintln!("campaign worker: {}", unsupported());
    1
}

/// Refused: worker processes are Linux-only.
pub(crate) fn run_processes(
    _spec: &Spec,
    _program: &Path,
    _todo: &[u64],
    _workers: usize,
    _out: &mut Collector,
    _refused: &dyn Fn(String) -> Result<Option<String>, Error>,
) -> Result<(), Error> {
    Err(Error::Usage(unsupported()))
}
