//! The master's side of one host process: start, calls (one round trip each, sets queued),
//! liveness and time limits, and the end of the host.

use super::os::{HostProcess, SharedRegion};
use super::protocol::{publish, wait_for, Header, Layout, Op, Spin};
use crate::error::HostEnd;
use crate::log::{LogRecord, LogSink};
use crate::status::Status;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// How often a sleeping master checks the host and the time limits.
const CHECK_SLICE: Duration = Duration::from_millis(10);
/// fmi2Fatal: what the proxy returns for a call the host did not answer.
pub(crate) const FATAL: i32 = 4;

/// The host binary: `explicit`, else `NIGEL_COSIM_HOST`, else `cosim-host` next to the
/// running executable or one folder up (test binaries live in `target/*/deps`).
pub(crate) fn find_host(explicit: Option<&Path>) -> Result<PathBuf, String> {
    if let Some(p) = explicit {
        return Ok(p.to_path_buf());
    }
    if let Some(p) = std::env::var_os("NIGEL_COSIM_HOST") {
        return Ok(PathBuf::from(p));
    }
    let exe = std::env::current_exe().map_err(|e| format!("cannot find the running executable: {e}"))?;
    let mut dir = exe.parent();
    for _ in 0..2 {
        let Some(d) = dir else { break };
        let candidate = d.join("cosim-host");
        if candidate.is_file() {
            return Ok(candidate);
        }
        dir = d.parent();
    }
    Err(format!(
        "no cosim-host next to {} (build it with `cargo build --release -p nigel-cosim`, or set NIGEL_COSIM_HOST)",
        exe.display()
    ))
}

/// One host process and the region shared with it.
pub(crate) struct Channel {
    base: *mut u8,
    layout: Layout,
    /// The region (unmapped when the channel ends, after the host).
    _region: SharedRegion,
    process: HostProcess,
    /// The host's end, once known (it is then reaped).
    pub(crate) failure: Option<HostEnd>,
    /// A call refused before it was made because its data (bytes) exceed what the region
    /// holds (bytes): taken by the status of that call.
    pub(crate) over_limit: Option<(usize, usize)>,
    reaped: bool,
    seq: u32,
    call_timeout: Option<Duration>,
    run_deadline: Option<(Instant, Duration)>,
    /// The log the messages of the host's FMU go to (the instance's).
    pub(crate) log: *const LogSink,
    /// The simulation time of the last timed call, s.
    pub(crate) last_time: f64,
    /// Sets queued for the next call.
    queued: u32,
    queued_bytes: usize,
    /// Where the queued sets came from, for the message of a failure.
    queued_functions: Vec<&'static str>,
    /// The batches of Reals the host reads after each step (the references of each, and
    /// where its record starts in the prefetch area), and whether the values in the
    /// region are those of the last step.
    prefetch_batches: Vec<(Vec<u32>, usize)>,
    prefetch_valid: bool,
    /// The `fmi2GetReal` calls since the last step with nothing else between them (`None`:
    /// another call came between).
    gets_since_step: Option<usize>,
    /// Strings returned by `fmi2GetString`, valid until the next call.
    pub(crate) strings: Vec<std::ffi::CString>,
    /// The values of the last `fmi3GetBinary`, which its pointers point into.
    pub(crate) binaries: Vec<Vec<u8>>,
    /// The messages of the last call (also in the instance's log once it has one).
    last_records: Vec<LogRecord>,
    /// The posted call waiting for its answer, and when it was posted.
    pending: Option<(Op, Instant)>,
    /// Whether the master's spins for this host have paid lately.
    gauge: super::protocol::SpinGauge,
    /// The arguments (time, step) of the posted `fmi2DoStep`.
    pub(crate) posted_step: Option<(f64, f64)>,
    spin: Spin,
}

// SAFETY: the region and the host are used only through `&mut self` (one caller at a
// time), as the instance that owns the channel is.
unsafe impl Send for Channel {}

impl Channel {
    /// Starts `host` for the library `library` (an FMI 3.0 one if `fmi3`) with the region
    /// laid out as `layout` ([`Layout::for_fmu`]).
    pub(crate) fn start(
        host: &Path,
        library: &Path,
        fmi3: bool,
        layout: Layout,
        call_timeout: Option<Duration>,
        run_deadline: Option<(Instant, Duration)>,
        spin: Spin,
    ) -> Result<Channel, HostEnd> {
        let region = SharedRegion::create(c"nigel-cosim-host", layout.total).map_err(HostEnd::Failed)?;
        let base = region.base();
        // SAFETY: the fresh mapping starts with a zeroed Header; the host is not started yet.
        unsafe {
            let h = &mut *(base as *mut Header);
            h.host_spin_ns = spin.host.as_nanos().min(u128::from(u32::MAX)) as u32;
            h.host_yield_every = spin.yield_every;
            h.host_adaptive = u32::from(spin.adaptive);
            h.fmi3 = u32::from(fmi3);
            h.arrays = layout.data_len as u64;
        }
        let mut command = std::process::Command::new(host);
        command
            .arg(region.handle_argument())
            .arg(layout.total.to_string())
            .arg(library)
            .stdin(std::process::Stdio::null());
        let process = HostProcess::spawn(command)
            .map_err(|e| HostEnd::Failed(format!("cannot start {}: {e}", host.display())))?;
        let mut channel = Channel {
            base,
            layout,
            _region: region,
            process,
            failure: None,
            over_limit: None,
            reaped: false,
            seq: 0,
            call_timeout,
            run_deadline,
            log: std::ptr::null(),
            last_time: 0.0,
            queued: 0,
            queued_bytes: 0,
            queued_functions: Vec::new(),
            prefetch_batches: Vec::new(),
            prefetch_valid: false,
            gets_since_step: None,
            strings: Vec::new(),
            binaries: Vec::new(),
            last_records: Vec::new(),
            pending: None,
            posted_step: None,
            gauge: super::protocol::SpinGauge::new(),
            spin,
        };
        super::protocol::LIVE_HOSTS.fetch_add(1, Ordering::Relaxed);
        // the host answers a first empty call once it has loaded the library (its
        // load-time initializers ran there: a crash in them is the host's end)
        let status = channel.call(Op::Flush);
        if status != 0 {
            return Err(match &channel.failure {
                Some(f) => f.clone(),
                None => HostEnd::Failed(format!(
                    "could not load {}: {}",
                    library.display(),
                    channel.last_records.iter().map(|r| r.message.as_str()).collect::<Vec<_>>().join("; ")
                )),
            });
        }
        Ok(channel)
    }

    #[allow(clippy::mut_from_ref)] // the region is memory the host shares, not a Rust object
    pub(crate) fn header(&self) -> &mut Header {
        // SAFETY: the region starts with a Header, is page-aligned and lives as long as
        // self; the host writes it only while the master waits (the protocol's turns).
        unsafe { &mut *(self.base as *mut Header) }
    }

    /// The call's array area.
    pub(crate) fn data(&mut self) -> &mut [u8] {
        // SAFETY: within the mapping (see Layout), exclusive while it is the master's turn.
        unsafe { std::slice::from_raw_parts_mut(self.base.add(self.layout.data), self.layout.data_len) }
    }

    fn area(&mut self, offset: usize, len: usize) -> &mut [u8] {
        // SAFETY: within the mapping (see Layout), exclusive while it is the master's turn.
        unsafe { std::slice::from_raw_parts_mut(self.base.add(offset), len) }
    }

    /// Queues an `fmi2SetReal/Integer/Boolean` (kind 0/1/2) of `vrs` with the values'
    /// bytes `bytes`; false if it does not fit (the caller then flushes and retries).
    pub(crate) fn queue_set(&mut self, kind: u32, function: &'static str, vrs: &[u32], bytes: &[u8]) -> bool {
        let need = 8 + 4 * vrs.len() + bytes.len();
        let need = need.div_ceil(8) * 8;
        if self.queued_bytes + need > self.layout.sets_len {
            return false;
        }
        let at = self.queued_bytes;
        let (sets, len) = (self.layout.sets, self.layout.sets_len);
        let area = self.area(sets, len);
        area[at..at + 4].copy_from_slice(&kind.to_ne_bytes());
        area[at + 4..at + 8].copy_from_slice(&(vrs.len() as u32).to_ne_bytes());
        let mut p = at + 8;
        for vr in vrs {
            area[p..p + 4].copy_from_slice(&vr.to_ne_bytes());
            p += 4;
        }
        area[p..p + bytes.len()].copy_from_slice(bytes);
        self.queued_bytes += need;
        self.queued += 1;
        self.queued_functions.push(function);
        self.prefetch_valid = false;
        self.gets_since_step = None;
        true
    }

    /// `fmi2GetReal` of `vrs` answered from the values the host read after the last step:
    /// true if this is the k-th `fmi2GetReal` since the step, with nothing else between,
    /// and the host's k-th batch is these references. Otherwise the batch is learned for
    /// the next steps (the host then reads it after each step) and false is returned.
    pub(crate) fn prefetched_reals(&mut self, vrs: &[u32], out: &mut [f64]) -> bool {
        let Some(k) = self.gets_since_step else { return false };
        self.gets_since_step = Some(k + 1);
        if let Some((batch, at)) = self.prefetch_batches.get(k) {
            if batch == vrs {
                if !self.prefetch_valid {
                    return false;
                }
                let off = self.layout.prefetch + at + 8 + (4 * vrs.len()).div_ceil(8) * 8;
                // SAFETY: the host wrote vrs.len() f64 there, 8-aligned, before its answer.
                let values = unsafe { std::slice::from_raw_parts(self.base.add(off) as *const f64, vrs.len()) };
                out.copy_from_slice(values);
                return true;
            }
        }
        self.learn_prefetch(k, vrs);
        self.prefetch_valid = false;
        false
    }

    /// The k-th `fmi2GetReal` after a step, `vrs`, becomes the host's k-th batch (those
    /// after it are dropped), if the prefetch area holds it.
    fn learn_prefetch(&mut self, k: usize, vrs: &[u32]) {
        if k > self.prefetch_batches.len() {
            return;
        }
        self.prefetch_batches.truncate(k);
        let at = self.prefetch_batches.last().map_or(0, |(b, at)| at + record_len(b.len()));
        if at + record_len(vrs.len()) > self.layout.prefetch_len {
            return;
        }
        let (off, len) = (self.layout.prefetch, self.layout.prefetch_len);
        let area = self.area(off, len);
        area[at..at + 4].copy_from_slice(&(vrs.len() as u32).to_ne_bytes());
        for (j, vr) in vrs.iter().enumerate() {
            area[at + 8 + 4 * j..at + 12 + 4 * j].copy_from_slice(&vr.to_ne_bytes());
        }
        self.prefetch_batches.push((vrs.to_vec(), at));
        self.header().prefetch = self.prefetch_batches.len() as u32;
    }

    /// One round trip: call `op` (its arguments already in the header and data area),
    /// with the queued sets first. Returns the fmi2 status, or [`FATAL`] with
    /// `self.failure` set if the host ended or a time limit passed.
    pub(crate) fn call(&mut self, op: Op) -> i32 {
        self.post(op);
        self.collect()
    }

    /// The first half of [`Channel::call`]: the request of `op` (and the queued sets)
    /// handed to the host, which starts on it at once; [`Channel::collect`] waits for the
    /// answer. Between the two the master may post to other hosts, so that they run at
    /// the same time. A call still pending when another is made is collected first.
    pub(crate) fn post(&mut self, op: Op) {
        self.settle();
        if self.failure.is_some() {
            return;
        }
        let queued = self.queued;
        let queued_bytes = self.queued_bytes as u32;
        {
            let h = self.header();
            h.op = op as u32;
            h.log_count = 0;
            h.log_bytes = 0;
            h.answer_needs = 0;
            h.prefetched = 0;
            h.queued = queued;
            h.queued_bytes = queued_bytes;
            h.queued_failed = u32::MAX;
        }
        self.seq = self.seq.wrapping_add(1);
        self.pending = Some((op, Instant::now()));
        let host_spin = if self.spin.cores_to_spare() { self.spin.host } else { Duration::ZERO };
        self.header().host_spin_ns = host_spin.as_nanos().min(u128::from(u32::MAX)) as u32;
        let hdr = self.header();
        publish(&hdr.request, self.seq, &hdr.host_sleeping);
    }

    /// Answers a posted call that nobody collected (before any other use of the region);
    /// a failure of it goes to the instance's log.
    pub(crate) fn settle(&mut self) {
        let Some((op, _)) = self.pending else { return };
        self.posted_step = None;
        let status = self.collect();
        if status > 1 && self.failure.is_none() {
            self.push_log(
                Status::from_raw(status),
                format!("{} returned {}", op.function(), Status::from_raw(status).spelled_for(op.function())),
            );
        }
    }

    /// Whether a posted call of `op` waits for its answer.
    pub(crate) fn is_pending(&self, op: Op) -> bool {
        self.pending.is_some_and(|(p, _)| p == op)
    }

    /// The answer to the posted call: its fmi2 status, or [`FATAL`] with `self.failure`
    /// set if the host ended or a time limit passed.
    pub(crate) fn collect(&mut self) -> i32 {
        let Some((op, start)) = self.pending.take() else {
            return if self.failure.is_some() { FATAL } else { 0 };
        };
        if self.failure.is_some() {
            return FATAL;
        }
        let seq = self.seq;
        let spin = if self.spin.cores_to_spare() { self.spin.master } else { Duration::ZERO };
        let yield_every = self.spin.yield_every;
        let adaptive = self.spin.adaptive;
        let h = self.header() as *mut Header;
        // SAFETY: the header lives as long as self (see `header`).
        let hdr = unsafe { &*h };
        let mut gauge = self.gauge;
        let outcome = wait_for(
            &hdr.response,
            seq.wrapping_sub(1),
            &hdr.master_sleeping,
            spin,
            yield_every,
            adaptive.then_some(&mut gauge),
            CHECK_SLICE,
            || self.check(start),
        );
        self.gauge = gauge;
        // the response may be stale only if it was never written (the host died)
        if let Err(end) = outcome {
            self.failure = Some(end);
            return FATAL;
        }
        if hdr.response.load(Ordering::Acquire) != seq {
            self.failure =
                Some(HostEnd::Failed(format!("answer {} to call {seq}", hdr.response.load(Ordering::Acquire))));
            return FATAL;
        }
        self.read_log();
        if hdr.answer_needs != 0 {
            self.over_limit = Some((hdr.answer_needs as usize, self.layout.data_len));
        }
        let mut status = hdr.status;
        if hdr.queued_failed != u32::MAX {
            let function = self.queued_functions.get(hdr.queued_failed as usize).copied().unwrap_or("fmi2Set*");
            status = hdr.queued_status;
            self.push_log(
                Status::from_raw(status),
                format!(
                    "{function} (sent with {}) returned {}",
                    op.function(),
                    Status::from_raw(status).spelled_for(function)
                ),
            );
        }
        self.queued = 0;
        self.queued_bytes = 0;
        self.queued_functions.clear();
        self.prefetch_valid = match op {
            Op::DoStep => hdr.prefetched == 1,
            Op::GetReal => self.prefetch_valid,
            _ => false,
        };
        self.gets_since_step = match op {
            Op::DoStep => (status <= 1).then_some(0),
            // a read changes nothing: the count since the step goes on
            Op::GetReal if status <= 1 => self.gets_since_step,
            _ => None,
        };
        status
    }

    /// While waiting: the host alive, and the time limits.
    fn check(&mut self, start: Instant) -> Result<(), HostEnd> {
        if let Some(end) = self.poll_exit() {
            return Err(end);
        }
        if let Some(limit) = self.call_timeout {
            if start.elapsed() > limit {
                self.kill();
                return Err(HostEnd::CallTimeout(limit));
            }
        }
        if let Some((deadline, limit)) = self.run_deadline {
            if Instant::now() > deadline {
                self.kill();
                return Err(HostEnd::RunTimeout(limit));
            }
        }
        Ok(())
    }

    /// The host's end if it has ended (reaps it).
    fn poll_exit(&mut self) -> Option<HostEnd> {
        if self.reaped {
            return Some(HostEnd::Failed("the host is gone".into()));
        }
        let end = self.process.try_wait();
        self.reaped |= end.is_some();
        end
    }

    fn kill(&mut self) {
        if !self.reaped {
            self.process.kill();
            self.reaped = true;
        }
    }

    /// Keeps `message` in the instance's log (category "host").
    pub(crate) fn push_log(&self, status: Status, message: String) {
        if self.log.is_null() {
            return;
        }
        // SAFETY: the instance's LogSink outlives its channel (see proxy.rs).
        let sink = unsafe { &*self.log };
        sink.push(LogRecord { status, category: "host".into(), message });
    }

    /// The messages of the call into the instance's log.
    fn read_log(&mut self) {
        let (count, bytes) = (self.header().log_count, self.header().log_bytes as usize);
        self.last_records.clear();
        if count == 0 {
            return;
        }
        let (off, len) = (self.layout.log, self.layout.log_len);
        let area = self.area(off, len)[..bytes.min(len)].to_vec();
        let mut p = 0;
        for _ in 0..count {
            if p + 12 > area.len() {
                break;
            }
            let status = i32::from_ne_bytes(area[p..p + 4].try_into().unwrap_or([0; 4]));
            let cl = u32::from_ne_bytes(area[p + 4..p + 8].try_into().unwrap_or([0; 4])) as usize;
            let ml = u32::from_ne_bytes(area[p + 8..p + 12].try_into().unwrap_or([0; 4])) as usize;
            p += 12;
            if p + cl + ml > area.len() {
                break;
            }
            let category = String::from_utf8_lossy(&area[p..p + cl]).into_owned();
            let message = String::from_utf8_lossy(&area[p + cl..p + cl + ml]).into_owned();
            p += cl + ml;
            let record = LogRecord { status: Status::from_raw(status), category, message };
            if !self.log.is_null() {
                // SAFETY: as in push_log.
                unsafe { &*self.log }.push(record.clone());
            }
            self.last_records.push(record);
        }
    }
}

/// The bytes of one batch in the prefetch area: its count (and 4 bytes of padding), its
/// references (padded to 8 bytes), its values.
pub(crate) fn record_len(n: usize) -> usize {
    8 + (4 * n).div_ceil(8) * 8 + 8 * n
}

impl Drop for Channel {
    fn drop(&mut self) {
        super::protocol::LIVE_HOSTS.fetch_sub(1, Ordering::Relaxed);
        // a host that is still there after fmi2FreeInstance (or never got it) is killed
        if !self.reaped {
            let deadline = Instant::now() + Duration::from_millis(200);
            while Instant::now() < deadline {
                if self.poll_exit().is_some() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(1));
            }
            self.kill();
        }
        // the region is unmapped when `_region` drops, after this
    }
}

/// `n` null round trips (a call the host answers at once) to each of `hosts` host
/// processes of the FMU library `library`, in turn (`overlapped`: the request posted to
/// every host, then the answers collected); the time of all. For the isolation bench:
/// the floor under the cost of an isolated step.
#[doc(hidden)]
pub fn null_round_trips(
    host: &Path,
    library: &Path,
    hosts: usize,
    n: u32,
    overlapped: bool,
) -> Result<Duration, String> {
    let spin = Spin::of_run();
    let mut channels = Vec::new();
    for _ in 0..hosts {
        channels.push(
            Channel::start(host, library, false, Layout::for_fmu(16, 0, 0), None, None, spin)
                .map_err(|e| e.to_string())?,
        );
    }
    let start = Instant::now();
    for _ in 0..n {
        if overlapped {
            for c in channels.iter_mut() {
                c.post(Op::Flush);
            }
            for c in channels.iter_mut() {
                if c.collect() != 0 {
                    return Err(format!("null call failed: {:?}", c.failure));
                }
            }
        } else {
            for c in channels.iter_mut() {
                if c.call(Op::Flush) != 0 {
                    return Err(format!("null call failed: {:?}", c.failure));
                }
            }
        }
    }
    let elapsed = start.elapsed();
    for c in channels.iter_mut() {
        c.call(Op::Free);
    }
    Ok(elapsed)
}
