//! Isolation: an instance whose FMU runs in its own host process (`cosim-host`), so that
//! a crash, an `exit`, or a call that never returns ends only the host. The master sees a
//! typed [`Error::Host`](crate::Error::Host) naming the FMU, the function, the simulation
//! time and the signal or exit code, and keeps the rows recorded so far.
//!
//! The master and the host share one memory region (`memfd_create` + `mmap`): a header
//! with two sequence numbers (futex words) and the arguments of one call, then the
//! arrays of the call (value references, values, states), then the messages the FMU
//! logged during it. A call is one round trip: the master writes the request and bumps
//! the request number; the host runs the FMU's function (FMI 2.0 or FMI 3.0, the
//! library's generation given in the header), writes the
//! results, the status and the log, and sets the response number. Each side spins while
//! that pays (see [`Spin`]), then sleeps on the futex (woken only if it sleeps). While it waits
//! the master checks every 10 ms that the host is alive (`waitpid`) and the call's and
//! the run's time limits; an expired limit kills the host (SIGKILL).
//!
//! Setting inputs does not wait: `fmi2Set*` calls are queued in the region and sent with
//! the next call that needs an answer (as a `jacobi` step's inputs go with its
//! `fmi2DoStep`); after a step the host also reads the batches of Reals the master read
//! after the previous step (before any other call), so that the master's next reads of
//! them need no round trip. The algorithms post the steps of all isolated instances
//! first and then collect the answers, so that the hosts step at the same time. A step
//! of an isolated instance is thus one round trip, overlapped with the others' (in
//! `ordered`, an instance whose outputs depend on inputs set after the step pays one
//! more); an error of a queued set is reported by the call it went with, its function
//! named in the log.
//!
//! The master's side is an [`Instance`](crate::Instance) whose function table is the
//! proxy of this module (`proxy.rs` for FMI 2.0, `proxy3.rs` for FMI 3.0): its state
//! machine, status handling and log are the in-process ones. FMI 3.0's sets of scalars
//! are queued as FMI 2.0's are (a set of array values is a call); its Reals are read with a
//! call (no prefetch); its clock calls (`fmi3SetClock`, `fmi3GetClock`, the intervals and
//! shifts) are calls, their arrays after the references as `protocol::clock_arrays` lays
//! them out. Scheduled Execution is not carried: its FMU calls the importer back from inside
//! `fmi3ActivateModelPartition`, and a host answers one call at a time. The host's side is
//! [`host::run`], the whole of `cosim-host`.
//!
//! The whole run in one host process (`--isolate=run`, the FMUs called in it directly) is
//! the master's (`nigel_cosim::isolate::whole`): it runs the simulation.
//!
//! Files: `os` (the region, the host process and the futex: Linux only; elsewhere isolation
//! is refused with [`os::unsupported`]'s message), `protocol` (the shared region's layout, the calls, waiting and waking), `channel`
//! (the master's end: starting a host, a call's round trip, the time limits), `proxy` and
//! `proxy3` (the function tables that carry each FMI 2.0 / 3.0 call over a channel),
//! `host` (the host's end). Each depends only on those before it.

pub(crate) mod channel;
pub mod host;
pub mod os;
pub(crate) mod protocol;
pub(crate) mod proxy;
pub(crate) mod proxy3;

use std::time::Duration;

#[doc(hidden)]
pub use channel::null_round_trips;

/// Which instances run in their own host process, and the time limit per call.
#[derive(Clone, Debug, Default)]
pub struct Isolation {
    /// The instances to isolate (`None`: every instance).
    pub instances: Option<Vec<String>>,
    /// The wall-clock limit of one FMU call; the host is killed when it passes.
    pub call_timeout: Option<Duration>,
    /// The host binary (`None`: `cosim-host` next to the running executable, or the
    /// `NIGEL_COSIM_HOST` environment variable).
    pub host: Option<std::path::PathBuf>,
}

impl Isolation {
    /// Whether instance `name` is isolated.
    pub fn covers(&self, name: &str) -> bool {
        self.instances.as_ref().is_none_or(|v| v.iter().any(|n| n == name))
    }
}
