//! Worker processes: each loads the system once and runs many runs; the parent hands out
//! run numbers and writes the rows as they come back.
//!
//! A worker is this program started as `PROGRAM worker SPEC HASH` ([`serve`]). It talks
//! over its standard input and output, one line each way:
//!
//! | parent -> worker | worker -> parent |
//! |---|---|
//! | (start) | `ready`, or `error MESSAGE` |
//! | `check` | `check ok`, or `check refused MESSAGE` ([`Worker::check_stop_time`]) |
//! | `run I` | `row INSIDE_NS TOTAL_NS` tab the row's CSV line tab its message |
//!
//! The worker's own standard output (fd 1) is pointed at its standard error before the
//! system is loaded, so that an FMU that prints cannot break the protocol.
//!
//! The parent ([`run_processes`]) keeps each run's wall clock: past the description's
//! `timeout` (plus [`GRACE`], so that a run the master stops between two steps reports its
//! own simulation time) it kills the worker (SIGKILL); a worker that ends during a run
//! (a signal: an FMU's segfault, abort, stack overflow; an exit code: an FMU called `exit`)
//! or is killed makes that run's row ([`STATUS_CRASHED`], [`STATUS_TIMEOUT`]) with the
//! reason and a new worker starts. Each worker has a TMPDIR of its own (a fresh folder in
//! the parent's), removed by the parent when the worker ends however it ends (what a killed
//! worker unpacked goes with it). Workers die with the parent (`PR_SET_PDEATHSIG`: SIGTERM,
//! on which a worker removes its TMPDIR itself, [`remove_tmpdir_on_signals`]).

use std::io::{BufRead, Write};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use nigel_cosim::isolate::whole::CallMarker;
use nigel_cosim::HostEnd;

use crate::collector::Collector;
use crate::results::{parse_line, Row, STATUS_CRASHED, STATUS_TIMEOUT};
use crate::runner::Worker;
use crate::spec::Spec;
use crate::Error;

/// The environment variable with the descriptor of a worker's call marker
/// ([`nigel_cosim::isolate::whole::CallMarker`]).
pub const MARK_FD: &str = "NIGEL_CAMPAIGN_MARK_FD";

/// The environment variable naming a worker's own TMPDIR (set by the parent).
pub const WORKER_TMPDIR: &str = "NIGEL_CAMPAIGN_WORKER_TMPDIR";

/// In a worker process (call it first in `main`, before any thread starts, instead of
/// `nigel_cosim::unpack::remove_on_signals`): on SIGINT, SIGTERM or SIGHUP (the parent's end
/// arrives as SIGTERM) removes the worker's whole TMPDIR, the folder the parent made for it,
/// and exits with 128 + the signal.
pub fn remove_tmpdir_on_signals() {
    let Some(dir) = std::env::var_os(WORKER_TMPDIR).map(PathBuf::from) else {
        nigel_cosim::unpack::remove_on_signals();
        return;
    };
    nigel_cosim::unpack::on_signals(move |_| {
        let _ = std::fs::remove_dir_all(&dir);
    });
}

/// Past the description's `timeout`, how long the parent waits before it kills a worker:
/// the master's own check between steps comes first and names the simulation time.
pub const GRACE: Duration = Duration::from_millis(500);

/// Text on one protocol line: tabs and line breaks as spaces.
fn field(s: &str) -> String {
    s.replace(['\t', '\n', '\r'], " ")
}

/// The worker's side: loads `spec_path` (whose hash must be `hash`), answers `ready`, then
/// each request until its input ends. Returns the process's exit code.
pub fn serve(spec_path: &Path, hash: &str) -> i32 {
    // the protocol gets a descriptor of its own; fd 1 (where an FMU's printf goes) becomes
    // standard error
    // SAFETY: plain descriptor calls on the process's own standard streams.
    let proto = unsafe {
        let fd = libc::dup(1);
        if fd < 0 || libc::dup2(2, 1) < 0 {
            eprintln!("campaign worker: cannot set up its output: {}", std::io::Error::last_os_error());
            return 1;
        }
        fd
    };
    use std::os::fd::FromRawFd;
    // SAFETY: `proto` is a fresh descriptor owned from here on.
    let mut out = std::io::BufWriter::new(unsafe { std::fs::File::from_raw_fd(proto) });
    let loaded =
        Spec::parse(spec_path, &std::fs::read_to_string(spec_path).unwrap_or_default()).and_then(|(spec, system)| {
            if spec.hash != hash {
                return Err(Error::Spec(format!(
                    "{} changed since the campaign started (hash {} instead of {})",
                    spec_path.display(),
                    crate::results::short(&spec.hash),
                    crate::results::short(hash)
                )));
            }
            Ok((spec, system))
        });
    let failed = |out: &mut std::io::BufWriter<std::fs::File>, e: Error| {
        let _ = writeln!(out, "error {}", field(&e.to_string()));
        let _ = out.flush();
        1
    };
    let spec = match loaded {
        Ok((spec, _)) => spec,
        Err(e) => return failed(&mut out, e),
    };
    let mut worker = match Worker::new(&spec) {
        Ok(w) => w,
        Err(e) => return failed(&mut out, e),
    };
    // each fmi2 call marked where the parent reads it after a crash (this thread runs them)
    if let Some(fd) = std::env::var(MARK_FD).ok().and_then(|v| v.parse().ok()) {
        if let Err(e) = nigel_cosim::isolate::whole::mark_calls(fd) {
            eprintln!("campaign worker: its calls are not marked: {e}");
        }
    }
    if writeln!(out, "ready").and_then(|_| out.flush()).is_err() {
        return 1;
    }
    let stdin = std::io::stdin();
    for line in stdin.lock().lines() {
        let Ok(line) = line else { break };
        let reply = if line == "check" {
            match worker.check_stop_time() {
                Ok(()) => "check ok".to_string(),
                Err(m) => format!("check refused {}", field(&m)),
            }
        } else if let Some(i) = line.strip_prefix("run ").and_then(|i| i.trim().parse::<u64>().ok()) {
            let before = worker.timing;
            let row = worker.run(i);
            let (inside, total) = (worker.timing.0 - before.0, worker.timing.1 - before.1);
            format!(
                "row {} {}\t{}\t{}",
                inside.as_nanos(),
                total.as_nanos(),
                row.line().trim_end(),
                field(&row.message)
            )
        } else {
            format!("error unknown request {}", field(&line))
        };
        if writeln!(out, "{reply}").and_then(|_| out.flush()).is_err() {
            break;
        }
    }
    // its input ended: the parent is done with it, or gone (then this may come before the
    // SIGTERM of PR_SET_PDEATHSIG): the worker removes its TMPDIR itself either way
    drop(worker);
    if let Some(dir) = std::env::var_os(WORKER_TMPDIR) {
        let _ = std::fs::remove_dir_all(dir);
    }
    0
}

/// A line from a worker, or the end of its output.
enum Said {
    Line(String),
    End,
}

/// One worker process and what it is doing.
struct Slot {
    child: Child,
    stdin: Option<ChildStdin>,
    /// Counts the processes of this slot: messages of an earlier one are ignored.
    generation: u64,
    ready: bool,
    /// The run it is on and when it was handed out.
    busy: Option<(u64, Instant)>,
    /// Its TMPDIR (where it unpacks the system), removed when it has ended.
    tmp: Option<tempfile::TempDir>,
    /// Where it marks each fmi2 call (instance, function, time).
    marker: Option<CallMarker>,
}

/// Where a worker was when it ended: ` during fmi2DoStep of model at t = 0.5 s`.
fn where_it_was(slot: &Slot) -> String {
    match slot.marker.as_ref().and_then(|m| m.last_call()) {
        Some((instance, function, t, true)) => format!(" during {function} of {instance} at t = {t} s"),
        Some((instance, function, t, false)) => {
            format!(" outside the FMUs, after {function} of {instance} returned at t = {t} s")
        }
        None => String::new(),
    }
}

fn start(
    program: &Path,
    spec: &Spec,
    index: usize,
    generation: u64,
    tx: &mpsc::Sender<(usize, u64, Said)>,
) -> Result<Slot, Error> {
    let tmp = tempfile::Builder::new()
        .prefix("nigel-campaign-worker-")
        .tempdir()
        .map_err(|e| Error::Io(format!("{}: {e}", std::env::temp_dir().display())))?;
    // a marker is a nicety: without one a crash still names its signal
    let marker = CallMarker::new().ok();
    let mark_fd = marker.as_ref().map(|m| m.fd());
    let mut command = Command::new(program);
    if let Some(fd) = mark_fd {
        command.env(MARK_FD, fd.to_string());
    }
    command
        .env("TMPDIR", tmp.path())
        .env(WORKER_TMPDIR, tmp.path())
        .arg("worker")
        .arg(std::path::absolute(&spec.path).unwrap_or_else(|_| spec.path.clone()))
        .arg(&spec.hash)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    // SAFETY: runs in the child between fork and exec: only prctl (async-signal-safe). The
    // worker gets SIGTERM when the parent ends, and removes its unpacked FMUs.
    unsafe {
        command.pre_exec(move || {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
            // this child alone inherits its marker (fcntl is async-signal-safe)
            if let Some(fd) = mark_fd {
                libc::fcntl(fd, libc::F_SETFD, 0);
            }
            Ok(())
        });
    }
    let mut child = command
        .spawn()
        .map_err(|e| Error::Io(format!("cannot start the worker process {}: {e}", program.display())))?;
    let stdin = child.stdin.take().expect("piped");
    let stdout = child.stdout.take().expect("piped");
    let tx = tx.clone();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if tx.send((index, generation, Said::Line(line))).is_err() {
                return;
            }
        }
        let _ = tx.send((index, generation, Said::End));
    });
    Ok(Slot { child, stdin: Some(stdin), generation, ready: false, busy: None, tmp: Some(tmp), marker })
}

/// Sends one request; a worker that died is seen by its reader's end.
fn send(slot: &mut Slot, request: &str) {
    if let Some(s) = slot.stdin.as_mut() {
        let _ = writeln!(s, "{request}").and_then(|_| s.flush());
    }
}

/// Starts workers 1 .. `workers` (worker 0 checked the stop time first).
fn start_others(
    program: &Path,
    spec: &Spec,
    workers: usize,
    generations: &mut u64,
    tx: &mpsc::Sender<(usize, u64, Said)>,
    slots: &mut Vec<Slot>,
) -> Result<(), Error> {
    for j in slots.len()..workers {
        *generations += 1;
        slots.push(start(program, spec, j, *generations, tx)?);
    }
    Ok(())
}

/// Starts a new worker in slot `k` in place of the one that ended or was killed, and counts
/// the restart.
fn restart(
    program: &Path,
    spec: &Spec,
    k: usize,
    generations: &mut u64,
    restarts: &mut u64,
    tx: &mpsc::Sender<(usize, u64, Said)>,
    slots: &mut [Slot],
) -> Result<(), Error> {
    *restarts += 1;
    *generations += 1;
    slots[k] = start(program, spec, k, *generations, tx)?;
    Ok(())
}

/// How a worker process ended, in the words of the master's host processes.
fn end_of(status: std::process::ExitStatus) -> HostEnd {
    match (status.signal(), status.code()) {
        (Some(s), _) => HostEnd::Signal(s),
        (None, Some(c)) => HostEnd::Exit(c),
        _ => HostEnd::Failed("ended without a status".into()),
    }
}

/// Ends a slot's process (killed if still running) and removes its unpacked folders.
fn finish(slot: &mut Slot, kill: bool) -> HostEnd {
    if kill {
        let _ = slot.child.kill();
    }
    let end = slot.child.wait().map(end_of).unwrap_or_else(|e| HostEnd::Failed(e.to_string()));
    drop(slot.tmp.take());
    end
}

/// The row of run `i` that did not finish: its values, NaN metrics, the status and reason.
fn failed_row(spec: &Spec, i: u64, status: u8, message: String) -> Row {
    let mut values = spec.values(i).numbers;
    values.extend(std::iter::repeat(f64::NAN).take(spec.metrics.len()));
    Row { run: i, status, message, values }
}

/// Parses a `row` reply.
fn parse_row(spec: &Spec, text: &str) -> Option<(Row, (Duration, Duration))> {
    let mut parts = text.splitn(3, '\t');
    let mut times = parts.next()?.split(' ');
    let inside = Duration::from_nanos(times.next()?.parse().ok()?);
    let total = Duration::from_nanos(times.next()?.parse().ok()?);
    let (run, status, _, values) = parse_line(parts.next()?, spec.header().len())?;
    let message = parts.next().unwrap_or("").to_string();
    Some((Row { run, status, message, values }, (inside, total)))
}

/// The runs `todo` on `workers` worker processes of `program`. Before the first run the
/// first worker checks the stop time; a refusal goes to `refused`, which returns it to
/// keep in [`crate::run::Done::stop_time_refused`] (going on) or the error that ends the
/// campaign.
pub(crate) fn run_processes(
    spec: &Spec,
    program: &Path,
    todo: &[u64],
    workers: usize,
    out: &mut Collector,
    refused: &dyn Fn(String) -> Result<Option<String>, Error>,
) -> Result<(), Error> {
    let (tx, rx) = mpsc::channel::<(usize, u64, Said)>();
    let mut generations = 0u64;
    let mut slots: Vec<Slot> = Vec::with_capacity(workers);
    // the stop time is checked by the first worker before the others start
    slots.push(start(program, spec, 0, generations, &tx)?);
    let limit = spec.timeout.map(|t| t + GRACE);
    let mut next = 0usize;
    let mut checked = false;
    let mut check_since: Option<Instant> = None;
    // the events until the last run is done or an error ends the campaign
    let mut serve = || -> Result<(), Error> {
        loop {
            // hand out runs to the ready idle workers
            if checked {
                for slot in slots.iter_mut().filter(|s| s.ready && s.busy.is_none()) {
                    let Some(&i) = todo.get(next) else { break };
                    next += 1;
                    slot.busy = Some((i, Instant::now()));
                    send(slot, &format!("run {i}"));
                }
                if next >= todo.len() && slots.iter().all(|s| s.busy.is_none()) {
                    break;
                }
            }
            let now = Instant::now();
            let checking = if checked { None } else { check_since };
            let wait = slots
                .iter()
                .filter_map(|s| Some(s.busy?.1 + limit?))
                .chain(checking.and_then(|since| Some(since + limit?)))
                .map(|at| at.saturating_duration_since(now))
                .min()
                .unwrap_or(Duration::from_secs(1));
            match rx.recv_timeout(wait) {
                Ok((k, generation, said)) => {
                    if !slots.get(k).is_some_and(|s| s.generation == generation) {
                        continue; // a worker already ended and replaced
                    }
                    match said {
                        Said::Line(line) => {
                            let slot = &mut slots[k];
                            if line == "ready" {
                                slot.ready = true;
                                if !checked {
                                    send(slot, "check");
                                    check_since = Some(Instant::now());
                                }
                            } else if let Some(answer) = line.strip_prefix("check ") {
                                if let Some(m) = answer.strip_prefix("refused ") {
                                    out.done.stop_time_refused = refused(m.to_string())?;
                                }
                                checked = true;
                                start_others(program, spec, workers, &mut generations, &tx, &mut slots)?;
                            } else if let Some(rest) = line.strip_prefix("row ") {
                                let Some((row, timing)) = parse_row(spec, rest) else {
                                    return Err(Error::Io(format!("a worker process sent a malformed row: {line}")));
                                };
                                slot.busy = None;
                                out.push(row, timing)?;
                            } else {
                                let m = line.strip_prefix("error ").unwrap_or(&line);
                                return Err(Error::Spec(format!("worker process: {m}")));
                            }
                        }
                        Said::End => {
                            let end = finish(&mut slots[k], false);
                            if !slots[k].ready {
                                // it could not load the system: no run would do better
                                return Err(Error::Spec(format!(
                                    "a worker process {end} while loading {} (before any run)",
                                    spec.system.display()
                                )));
                            }
                            if let Some((i, _)) = slots[k].busy.take() {
                                let why = match end {
                                    HostEnd::Exit(_) => " (an FMU called exit?)",
                                    _ => "",
                                };
                                let at = where_it_was(&slots[k]);
                                let message = format!(
                                    "crashed: the run's worker process {end}{at}{why}; the worker was restarted"
                                );
                                out.push(failed_row(spec, i, STATUS_CRASHED, message), Default::default())?;
                            } else if !checked {
                                // it crashed checking the stop time: the runs will say how they end
                                checked = true;
                                start_others(program, spec, workers, &mut generations, &tx, &mut slots)?;
                            }
                            restart(program, spec, k, &mut generations, &mut out.done.restarts, &tx, &mut slots)?;
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    let (Some(limit), Some(timeout)) = (limit, spec.timeout) else { continue };
                    if let (false, Some(since)) = (checked, check_since) {
                        if since.elapsed() >= limit {
                            // the check hangs as a run would: the runs will say how they end
                            finish(&mut slots[0], true);
                            checked = true;
                            restart(program, spec, 0, &mut generations, &mut out.done.restarts, &tx, &mut slots)
                                .and_then(|_| {
                                    start_others(program, spec, workers, &mut generations, &tx, &mut slots)
                                })?;
                        }
                    }
                    // by index: a slot is replaced in place by the worker started for it
                    #[allow(clippy::needless_range_loop)]
                    for k in 0..slots.len() {
                        let Some((i, since)) = slots[k].busy else { continue };
                        if since.elapsed() < limit {
                            continue;
                        }
                        slots[k].busy = None;
                        finish(&mut slots[k], true);
                        let at = match slots[k].marker.as_ref().and_then(|m| m.last_call()) {
                            Some((instance, function, t, true)) => {
                                format!("{function} of {instance} at t = {t} s did not return")
                            }
                            Some((instance, function, t, false)) => {
                                format!("the last call, {function} of {instance} at t = {t} s, had returned")
                            }
                            None => "a call did not return".into(),
                        };
                        let message = format!(
                        "timeout: the run took longer than the description's timeout of {} s ({at}); its worker process was killed and restarted",
                        timeout.as_secs_f64()
                    );
                        out.push(failed_row(spec, i, STATUS_TIMEOUT, message), Default::default())?;
                        restart(program, spec, k, &mut generations, &mut out.done.restarts, &tx, &mut slots)?;
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
        }
        Ok(())
    };
    let result = serve();
    // the workers end when their input does; a worker still busy (after an error) is killed
    for mut slot in slots {
        slot.stdin = None;
        let busy = slot.busy.is_some();
        finish(&mut slot, busy);
    }
    result
}
