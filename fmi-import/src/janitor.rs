//! The temporary folders of a process that ends without cleaning up (a crash of an FMU in
//! process: SIGSEGV, SIGABRT; a SIGKILL): a small process of its own removes them.
//!
//! A signal handler of the crashing process cannot do it safely (a crash inside `malloc`,
//! as a double free is, leaves the allocator's lock held, and removing a folder
//! allocates). So at the first temporary folder the process starts a janitor (`/bin/sh`,
//! nothing of ours) that reads the folders' paths from a pipe, one a line, until the pipe
//! closes, then removes them. The pipe closes when this process ends, however it ends (the
//! kernel closes its descriptors); after a normal end the folders are gone already and the
//! janitor finds nothing. The janitor inherits the signal mask (SIGINT, SIGTERM and SIGHUP
//! blocked in programs that wait for them, `unpack::remove_on_signals`), so a Ctrl-C to the
//! terminal's process group does not end it before its work.

use std::io::Write;
use std::path::Path;
use std::process::{ChildStdin, Command, Stdio};
use std::sync::Mutex;

/// The janitor's pipe (`None`: not started yet, or it could not be started).
static PIPE: Mutex<Option<ChildStdin>> = Mutex::new(None);

/// The janitor: collects the lines, then removes them all (`rm -rf`: the folders and what
/// the FMUs wrote in them).
const SCRIPT: &str = r#"set -f; while IFS= read -r d; do set -- "$@" "$d"; done; [ "$#" -gt 0 ] && rm -rf -- "$@""#;

/// Has the janitor remove `dir` when this process ends (a path with a line break, which
/// one line cannot carry, is left to the process's own removal).
pub(crate) fn watch(dir: &Path) {
    let Some(text) = dir.to_str().filter(|t| !t.contains('\n')) else { return };
    let mut pipe = PIPE.lock().unwrap_or_else(|e| e.into_inner());
    if pipe.is_none() {
        *pipe = Command::new("/bin/sh")
            .args(["-c", SCRIPT, "nigel-cosim-janitor"])
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .ok()
            .and_then(|mut child| child.stdin.take());
        // the child is not waited for: it outlives this process by design
    }
    if let Some(p) = pipe.as_mut() {
        if writeln!(p, "{text}").and_then(|_| p.flush()).is_err() {
            *pipe = None;
        }
    }
}
