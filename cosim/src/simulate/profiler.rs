//! The time spent in each instance's calls, one clock read per call boundary; the
//! algorithms tell the [`Profiler`] after each call (it is attached only when asked for, so
//! an unprofiled run reads no clock).

use std::time::{Duration, Instant};

/// Time spent in each instance's calls, one clock read per call boundary: the time from
/// the previous mark to the end of a call is charged to that call's instance (the
/// master's marshalling of the call's arguments included). Lanes stepped in threads
/// measure their own time ([`crate::simulate::lane::Lane::spent`]), added at the end.
pub(crate) struct Profiler {
    last: Instant,
    pub(crate) spent: Vec<Duration>,
}

impl Profiler {
    pub(crate) fn new(n: usize) -> Profiler {
        Profiler { last: Instant::now(), spent: vec![Duration::ZERO; n] }
    }

    /// Starts a stretch of calls.
    #[inline]
    pub(crate) fn restart(&mut self) {
        self.last = Instant::now();
    }

    /// Charges the time since the last mark evenly to `instances` (a coupled group).
    pub(crate) fn charge_shared(&mut self, instances: &[usize]) {
        let now = Instant::now();
        let share = (now - self.last) / instances.len().max(1) as u32;
        for &i in instances {
            self.spent[i] += share;
        }
        self.last = now;
    }

    /// Charges the time since the last mark to `instance`.
    #[inline]
    pub(crate) fn charge(&mut self, instance: usize) {
        let now = Instant::now();
        self.spent[instance] += now - self.last;
        self.last = now;
    }
}
