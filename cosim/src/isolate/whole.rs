//! The whole run in one host process (`cosim run --isolate=run`): a crash boundary around
//! every FMU at in-process speed (the FMUs are called directly in the host; no round trip
//! per call as with a host per FMU).
//!
//! The parent creates a shared region (`memfd_create`) and starts its own program again
//! with `NIGEL_COSIM_WHOLE_RUN=FD,TEXT_FD` in the environment; the host ([`is_host`]) parses the
//! same command line, loads the FMUs in process and simulates ([`host_simulate`]),
//! writing into the region:
//! - before each fmi2 call, the instance, the function and the time, and after it that the
//!   call returned (`fmi_import::call_site`; with one thread: `--threads` 1);
//! - each recorded row as it comes (the region grows with `ftruncate` + `mremap`), and the
//!   text of its exact columns (64-bit integers, Strings, Binaries) as a line of the
//!   second file;
//! - the folders its FMUs are unpacked in (the parent removes them if the host is killed);
//! - at the end the outcome: the summary's JSON, or that the run failed (the host printed
//!   the error itself).
//!
//! The parent ([`simulate_in_host`]) waits for the host, kills it half a second after the
//! run's time limit (`--timeout`, checked every 10 ms; the host's own check between steps
//! comes first), and returns the rows written, with
//! [`Error::Host`] naming the instance, the call, the time and the signal or exit code
//! when the host ended without an outcome.

use std::os::fd::{AsRawFd, OwnedFd};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use crate::error::{Error, HostEnd, Result};
use crate::simulate::{default_record, simulate_with, Experiment, Results, Summary};
use crate::system::System;
use fmi_import::call_site::{self, CallSlots};

/// The environment variable that makes a `cosim` the host of a whole run.
pub const HOST_VARIABLE: &str = "NIGEL_COSIM_WHOLE_RUN";

const HEADER: usize = 64 << 10;
const MAGIC: u64 = 0x6e69_6765_6c57_484c;

/// The start of the region.
#[repr(C)]
struct Header {
    magic: u64,
    /// 0 running, 1 completed (the summary's JSON follows), 2 failed (reported by the host).
    state: AtomicU32,
    /// The call in progress (or the last one).
    call: CallSlots,
    /// Values per row (time first) and the rows written.
    width: AtomicU64,
    rows: AtomicU64,
    /// Bytes of the folder list and of the summary JSON, both in `text`.
    folders_len: AtomicU32,
    summary_len: AtomicU32,
    text: [u8; HEADER - 8 * 3 - 4 * 4 - std::mem::size_of::<CallSlots>()],
}

const _: () = assert!(std::mem::size_of::<Header>() <= HEADER);

/// Whether this process is the host of a whole run (its parent set [`HOST_VARIABLE`]).
pub fn is_host() -> bool {
    std::env::var_os(HOST_VARIABLE).is_some()
}

/// A region that only holds the call marker, for a process that runs many runs (a
/// campaign's worker): the parent creates it and hands its descriptor to the process, which
/// calls [`mark_calls`]; after the process ended, [`CallMarker::last_call`] says what it was
/// calling.
pub struct CallMarker {
    fd: OwnedFd,
}

impl CallMarker {
    /// A fresh region (`memfd_create`, close-on-exec: the parent lets one child inherit it).
    pub fn new() -> std::result::Result<CallMarker, String> {
        let fd = fmi_import::isolate::os::memfd_create(c"nigel-cosim-mark", libc::MFD_CLOEXEC)
            .map_err(|e| format!("memfd_create: {e}"))?;
        // SAFETY: plain syscalls on the fresh descriptor.
        unsafe {
            if libc::ftruncate(fd.as_raw_fd(), HEADER as libc::off_t) != 0 {
                return Err(format!("ftruncate: {}", std::io::Error::last_os_error()));
            }
            Ok(CallMarker { fd })
        }
    }

    /// The descriptor to hand to the marked process.
    pub fn fd(&self) -> i32 {
        self.fd.as_raw_fd()
    }

    /// The last fmi2 call the marked process started: the instance, the function, the
    /// simulation time, and whether it was still in it (`None`: it marked no call).
    pub fn last_call(&self) -> Option<(String, String, f64, bool)> {
        read_region(&self.fd, None).and_then(|r| r.4)
    }
}

/// In a process handed a [`CallMarker`]'s descriptor: marks each fmi2 call of this process
/// from now on (call it from the one thread that simulates).
pub fn mark_calls(fd: i32) -> std::result::Result<(), String> {
    let mut region = Region { fd, base: std::ptr::null_mut(), len: 0 };
    region.grow(HEADER)?;
    region.header().magic = MAGIC;
    region.mark_calls();
    Ok(())
}

/// The host's side: maps the region of [`HOST_VARIABLE`], simulates with every row
/// written into it, and writes the outcome. Returns the process's exit code (the caller
/// prints an error itself and exits with it).
pub fn host_simulate(system: &System, experiment: &Experiment) -> Result<()> {
    // "FD,TEXT_FD": the region, and the file of the exact columns' text
    let fds: Vec<i32> = std::env::var(HOST_VARIABLE)
        .ok()
        .map(|v| v.split(',').filter_map(|f| f.parse().ok()).collect())
        .unwrap_or_default();
    let [fd, text_fd] = fds[..] else {
        return Err(Error::Experiment(format!("{HOST_VARIABLE}: not two descriptors")));
    };
    let width = experiment.record.as_ref().map_or_else(|| default_record(system).len(), |r| r.len()) + 1;
    let mut region = Region { fd, base: std::ptr::null_mut(), len: 0 };
    region.grow(HEADER + width * 8 * 1024).map_err(Error::Experiment)?;
    let h = region.header();
    h.width.store(width as u64, Ordering::Relaxed);
    let folders: Vec<String> =
        system.instances.iter().map(|i| i.fmu.unpacked_dir().display().to_string()).filter(|d| !d.is_empty()).collect();
    let list = folders.join("\n");
    let n = list.len().min(h.text.len() / 2);
    h.text[..n].copy_from_slice(&list.as_bytes()[..n]);
    h.folders_len.store(n as u32, Ordering::Release);
    h.magic = MAGIC;
    if experiment.threads <= 1 {
        region.mark_calls();
    }
    let mut rows = 0usize;
    let mut failed = None;
    let mut line = String::new();
    let mut sink = |t: f64, values: &[f64], exact: &[(usize, String)]| {
        if failed.is_some() {
            return;
        }
        if !exact.is_empty() {
            // the row's text first: the parent takes as many text lines as rows
            line.clear();
            line.push_str(&serde_json::to_string(exact).unwrap_or_default());
            line.push('\n');
            // SAFETY: a write of our own buffer to the inherited descriptor.
            let written = unsafe { libc::write(text_fd, line.as_ptr() as *const libc::c_void, line.len()) };
            if written != line.len() as isize {
                failed = Some(format!("writing the text of a row: {}", std::io::Error::last_os_error()));
                return;
            }
        }
        let need = HEADER + (rows + 1) * width * 8;
        if need > region.len {
            if let Err(e) = region.grow((need * 2).max(region.len * 2)) {
                failed = Some(e);
                return;
            }
            if experiment.threads <= 1 {
                region.mark_calls();
            }
        }
        // SAFETY: within the mapping just grown; the parent reads only `rows` rows.
        unsafe {
            let row = (region.base.add(HEADER) as *mut f64).add(rows * width);
            *row = t;
            std::ptr::copy_nonoverlapping(values.as_ptr(), row.add(1), values.len().min(width - 1));
        }
        rows += 1;
        region.header().rows.store(rows as u64, Ordering::Release);
    };
    let outcome = simulate_with(system, experiment, None, Some(&mut sink));
    // SAFETY: stops the marking.
    unsafe { call_site::mark_calls_in(std::ptr::null_mut()) };
    let h = region.header();
    match outcome {
        Ok((_, summary)) => {
            let json = summary_json(&summary);
            let off = h.folders_len.load(Ordering::Relaxed) as usize;
            let n = json.len().min(h.text.len() - off);
            h.text[off..off + n].copy_from_slice(&json.as_bytes()[..n]);
            h.summary_len.store(n as u32, Ordering::Relaxed);
            h.state.store(1, Ordering::Release);
            Ok(())
        }
        Err(e) => {
            h.state.store(2, Ordering::Release);
            Err(e)
        }
    }
}

/// The summary's JSON, with what the parent needs back beside `to_json`'s fields.
fn summary_json(s: &Summary) -> String {
    let mut v = s.to_json();
    v["steps"] = s.steps.into();
    serde_json::to_string(&v).unwrap_or_default()
}

/// The host's mapping of the region.
struct Region {
    fd: i32,
    base: *mut u8,
    len: usize,
}

// SAFETY: the mapping belongs to the process, valid in any of its threads; a Region is
// owned by one thread at a time (moved, never shared), as a row sink is.
unsafe impl Send for Region {}

impl Region {
    /// Copies each marked call of this process into the region's call slots, from now on.
    fn mark_calls(&self) {
        // SAFETY: the mapping lives as long as the process (it is never unmapped, only
        // moved by `grow`, which is followed by another `mark_calls`).
        unsafe { call_site::mark_calls_in(&mut self.header().call) };
    }

    fn header(&self) -> &'static mut Header {
        // SAFETY: the mapping starts with a Header and lives as long as the process.
        unsafe { &mut *(self.base as *mut Header) }
    }

    /// Grows the region to `len` bytes (its rows stay where they are in the file).
    fn grow(&mut self, len: usize) -> std::result::Result<(), String> {
        // SAFETY: plain syscalls on the inherited memfd and our own mapping.
        unsafe {
            if libc::ftruncate(self.fd, len as libc::off_t) != 0 {
                return Err(format!("ftruncate: {}", std::io::Error::last_os_error()));
            }
            let p = if self.base.is_null() {
                libc::mmap(std::ptr::null_mut(), len, libc::PROT_READ | libc::PROT_WRITE, libc::MAP_SHARED, self.fd, 0)
            } else {
                libc::mremap(self.base as *mut libc::c_void, self.len, len, libc::MREMAP_MAYMOVE)
            };
            if p == libc::MAP_FAILED {
                return Err(format!("mmap: {}", std::io::Error::last_os_error()));
            }
            self.base = p as *mut u8;
        }
        self.len = len;
        Ok(())
    }
}

/// What the parent learns from a finished host.
pub struct HostRun {
    /// The rows the host wrote, named as the run records them.
    pub results: Results,
    /// `Ok(summary, its JSON)`; `Err(None)`: the run failed and the host printed why;
    /// `Err(Some(e))`: the host ended without an outcome (crash, exit, killed).
    pub outcome: std::result::Result<(Summary, serde_json::Value), Option<Error>>,
}

/// Runs `system` with `experiment` in a host process: this program again, with `args`
/// (its command line without the program) and [`HOST_VARIABLE`].
pub fn simulate_in_host(system: &System, experiment: &Experiment, args: &[std::ffi::OsString]) -> Result<HostRun> {
    let failed = |m: String| {
        Error::Import(crate::ImportError::Host {
            instance: "(the run)".into(),
            function: "starting",
            time: 0.0,
            cause: HostEnd::Failed(m),
        })
    };
    // no CLOEXEC: the host inherits the descriptor
    let fd = fmi_import::isolate::os::memfd_create(c"nigel-cosim-run", 0)
        .map_err(|e| failed(format!("memfd_create: {e}")))?;
    // the text of the exact columns, one line per row (the host appends)
    let text_fd = fmi_import::isolate::os::memfd_create(c"nigel-cosim-run-text", 0)
        .map_err(|e| failed(format!("memfd_create: {e}")))?;
    let program = std::env::current_exe().map_err(|e| failed(format!("the running program: {e}")))?;
    let mut command = std::process::Command::new(&program);
    command
        .args(args)
        .env(HOST_VARIABLE, format!("{},{}", fd.as_raw_fd(), text_fd.as_raw_fd()))
        .stdin(std::process::Stdio::null());
    // SAFETY: only prctl between fork and exec; the host dies with the parent.
    unsafe {
        use std::os::unix::process::CommandExt;
        command.pre_exec(|| {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
            Ok(())
        });
    }
    let mut child = command.spawn().map_err(|e| failed(format!("cannot start {}: {e}", program.display())))?;
    // the host's own check between steps comes first and names the simulation time; past
    // it by half a second (a call that does not return) the host is killed
    let deadline = experiment.timeout.map(|t| (Instant::now() + t + Duration::from_millis(500), t));
    let mut killed = None;
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break s,
            Ok(None) => {}
            Err(e) => return Err(failed(format!("waiting for the host: {e}"))),
        }
        if let Some((at, limit)) = deadline {
            if Instant::now() >= at && killed.is_none() {
                let _ = child.kill();
                killed = Some(limit);
            }
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let names = record_names(system, experiment)?;
    let read = read_region(&fd, Some(names));
    let simulating = read.is_some();
    let (mut results, state, folders, summary, mark) = match read {
        Some(r) => r,
        None => (
            Results { names: record_names(system, experiment)?, values: Vec::new(), exact: Vec::new() },
            0,
            Vec::new(),
            None,
            None,
        ),
    };
    let mut text = String::new();
    {
        use std::io::{Read, Seek};
        let mut file = std::fs::File::from(text_fd);
        if file.rewind().is_ok() {
            let _ = file.read_to_string(&mut text);
        }
    }
    results.exact = exact_columns(&text, results.rows());
    use std::os::unix::process::ExitStatusExt;
    let outcome = match (state, summary) {
        (1, Some(json)) if killed.is_none() => Ok((summary_of(&json), json)),
        (2, _) if killed.is_none() => Err(None),
        _ => {
            for d in folders {
                let _ = std::fs::remove_dir_all(d);
            }
            let cause = match (killed, status.signal(), status.code()) {
                (Some(limit), _, _) => HostEnd::RunTimeout(limit),
                (None, Some(s), _) => HostEnd::Signal(s),
                (None, None, Some(c)) => HostEnd::Exit(c),
                _ => HostEnd::Failed("ended without a status".into()),
            };
            let (instance, function, time) = match mark {
                Some((i, f, t, true)) => (i, f, t),
                Some((i, f, t, false)) => (format!("(the master, after {f} of {i} returned)"), f, t),
                // the calls are marked with one thread only
                None if simulating => (
                    "(an instance)".to_string(),
                    "an fmi2 call (named with --threads 1 only)".to_string(),
                    results.rows().checked_sub(1).map_or(0.0, |k| results.row(k)[0]),
                ),
                None => ("(the run)".to_string(), "loading the FMUs".to_string(), 0.0),
            };
            let function: &'static str = Box::leak(function.into_boxed_str());
            Err(Some(Error::Import(crate::ImportError::Host { instance, function, time, cause })))
        }
    };
    Ok(HostRun { results, outcome })
}

fn record_names(system: &System, experiment: &Experiment) -> Result<Vec<String>> {
    let single = system.instances.len() == 1;
    let refs = match &experiment.record {
        None => default_record(system),
        Some(names) => names.iter().map(|n| system.resolve(n)).collect::<Result<_>>()?,
    };
    Ok(refs.iter().map(|r| if single { system.variable(r).name.clone() } else { system.name_of(r) }).collect())
}

type Read = (Results, u32, Vec<PathBuf>, Option<serde_json::Value>, Option<(String, String, f64, bool)>);

/// The rows, state, folders, summary and marker the host left in the region (`names`:
/// those of the rows; `None`: a region with the marker only).
fn read_region(fd: &OwnedFd, names: Option<Vec<String>>) -> Option<Read> {
    // SAFETY: fstat and a read-only mapping of the whole memfd, unmapped below.
    unsafe {
        let mut st: libc::stat = std::mem::zeroed();
        if libc::fstat(fd.as_raw_fd(), &mut st) != 0 || (st.st_size as usize) < HEADER {
            return None;
        }
        let len = st.st_size as usize;
        let p = libc::mmap(std::ptr::null_mut(), len, libc::PROT_READ, libc::MAP_SHARED, fd.as_raw_fd(), 0);
        if p == libc::MAP_FAILED {
            return None;
        }
        let h = &*(p as *const Header);
        let out = (|| {
            if h.magic != MAGIC {
                return None;
            }
            let width = h.width.load(Ordering::Acquire) as usize;
            let rows = (h.rows.load(Ordering::Acquire) as usize).min((len - HEADER) / (8 * width.max(1)));
            let names = match names {
                Some(n) if width == n.len() + 1 => n,
                Some(_) => return None,
                None => Vec::new(),
            };
            let values = std::slice::from_raw_parts((p as *const u8).add(HEADER) as *const f64, rows * width).to_vec();
            let folders_len = (h.folders_len.load(Ordering::Acquire) as usize).min(h.text.len());
            let folders = String::from_utf8_lossy(&h.text[..folders_len])
                .lines()
                .filter(|l| !l.is_empty())
                .map(PathBuf::from)
                .collect();
            let state = h.state.load(Ordering::Acquire);
            let summary_len = (h.summary_len.load(Ordering::Acquire) as usize).min(h.text.len() - folders_len);
            let summary = (state == 1)
                .then(|| serde_json::from_slice(&h.text[folders_len..folders_len + summary_len]).ok())
                .flatten();
            let mark = (h.call.function_len.load(Ordering::Acquire) > 0).then(|| h.call.last_call());
            Some((Results { names, values, exact: Vec::new() }, state, folders, summary, mark))
        })();
        libc::munmap(p, len);
        out
    }
}

/// The exact columns of the first `rows` rows from the host's text file: one JSON line
/// per row, `[[column, text], ...]`.
fn exact_columns(text: &str, rows: usize) -> Vec<crate::simulate::ExactColumn> {
    let mut columns: Vec<crate::simulate::ExactColumn> = Vec::new();
    for line in text.lines().take(rows) {
        let Ok(serde_json::Value::Array(cells)) = serde_json::from_str::<serde_json::Value>(line) else { break };
        for (k, cell) in cells.iter().enumerate() {
            let (Some(column), Some(t)) = (cell[0].as_u64(), cell[1].as_str()) else { continue };
            if columns.len() <= k {
                columns.push(crate::simulate::ExactColumn { column: column as usize, rows: Vec::new() });
            }
            columns[k].rows.push(t.to_string());
        }
    }
    columns
}

/// The summary from the host's JSON: every field `Summary::to_json` writes, so that
/// `--summary` prints the same under isolation as in one process.
fn summary_of(v: &serde_json::Value) -> Summary {
    let count = |x: &serde_json::Value| x.as_u64().unwrap_or(0);
    let bdf = &v["bdf"];
    let mut s = Summary {
        steps: count(&v["steps"]),
        wall_time: Duration::from_secs_f64(v["wall_time_s"].as_f64().unwrap_or(0.0).max(0.0)),
        discard_retries: count(&v["discard_retries"]),
        parallel_steps: count(&v["parallel_steps"]),
        integrator_steps: (count(&v["integrator_steps"]["accepted"]), count(&v["integrator_steps"]["rejected"])),
        stiff: crate::bdf::Work {
            rhs: count(&bdf["rhs"]),
            jacobian_rhs: count(&bdf["jacobian_rhs"]),
            jacobians: count(&bdf["jacobians"]),
            factorizations: count(&bdf["factorizations"]),
            ..crate::bdf::Work::default()
        },
        ..Summary::default()
    };
    if let Some(c) = v["clock_ticks"].as_array() {
        s.clock_ticks = c.iter().map(|x| (x["clock"].as_str().unwrap_or("").to_string(), count(&x["ticks"]))).collect();
    }
    if let Some(e) = v["event_times"].as_array() {
        s.events = e
            .iter()
            .map(|x| crate::me::Event {
                instance: x["instance"].as_str().unwrap_or("").to_string(),
                time: x["time"].as_f64().unwrap_or(f64::NAN),
                kind: match x["kind"].as_str() {
                    Some("time") => "time",
                    Some("state") => "state",
                    Some("step") => "step",
                    _ => "unknown",
                },
            })
            .collect();
    }
    if let Some(i) = v["instances"].as_array() {
        s.instance_time = i
            .iter()
            .map(|x| {
                let d = Duration::from_secs_f64(x["time_s"].as_f64().unwrap_or(0.0).max(0.0));
                (x["name"].as_str().unwrap_or("").to_string(), d)
            })
            .collect();
    }
    if let Some(w) = v["warnings"].as_array() {
        s.warnings = w
            .iter()
            .map(|x| {
                (x["instance"].as_str().unwrap_or("").to_string(), x["message"].as_str().unwrap_or("").to_string())
            })
            .collect();
    }
    if let Some(e) = v["ended_by"].as_object() {
        let reason: &'static str = Box::leak(e["reason"].as_str().unwrap_or("").to_string().into_boxed_str());
        s.ended_by =
            Some((e["instance"].as_str().unwrap_or("").to_string(), e["time"].as_f64().unwrap_or(0.0), reason));
    }
    s
}
