//! The protocol between the master and a host process: the calls ([`Op`]), the shared
//! region's header and layout, and how each side waits for the other (spinning, then the
//! futex) and wakes it.

use model_description::fmi3::ValueType;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};
use std::sync::OnceLock;
use std::time::Duration;

/// Declares the calls of the protocol once: each variant with the function it stands for.
/// The numbers on the wire are the variants' positions from 1 (0 is never a request).
macro_rules! protocol_ops {
    ($first:ident => $first_function:literal, $($(#[$doc:meta])* $op:ident => $function:literal,)*) => {
        /// The calls of the protocol.
        #[repr(u32)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub(crate) enum Op {
            $first = 1,
            $($(#[$doc])* $op,)*
        }

        impl Op {
            const ALL: &'static [Op] = &[Op::$first, $(Op::$op),*];

            pub(crate) fn from_u32(v: u32) -> Option<Op> {
                Op::ALL.get((v as usize).checked_sub(1)?).copied()
            }

            /// The function it is.
            pub(crate) fn function(self) -> &'static str {
                match self {
                    Op::$first => $first_function,
                    $(Op::$op => $function,)*
                }
            }
        }
    };
}

protocol_ops! {
    Instantiate => "fmi2Instantiate",
    Free => "fmi2FreeInstance",
    SetupExperiment => "fmi2SetupExperiment",
    EnterInitializationMode => "fmi2EnterInitializationMode",
    ExitInitializationMode => "fmi2ExitInitializationMode",
    Terminate => "fmi2Terminate",
    Reset => "fmi2Reset",
    GetReal => "fmi2GetReal",
    GetInteger => "fmi2GetInteger",
    GetBoolean => "fmi2GetBoolean",
    GetString => "fmi2GetString",
    SetString => "fmi2SetString",
    DoStep => "fmi2DoStep",
    GetFmuState => "fmi2GetFMUstate",
    SetFmuState => "fmi2SetFMUstate",
    FreeFmuState => "fmi2FreeFMUstate",
    GetBooleanStatus => "fmi2GetBooleanStatus",
    GetRealStatus => "fmi2GetRealStatus",
    EnterEventMode => "fmi2EnterEventMode",
    NewDiscreteStates => "fmi2NewDiscreteStates",
    EnterContinuousTimeMode => "fmi2EnterContinuousTimeMode",
    CompletedIntegratorStep => "fmi2CompletedIntegratorStep",
    SetTime => "fmi2SetTime",
    SetContinuousStates => "fmi2SetContinuousStates",
    GetDerivatives => "fmi2GetDerivatives",
    GetEventIndicators => "fmi2GetEventIndicators",
    GetContinuousStates => "fmi2GetContinuousStates",
    GetNominalsOfContinuousStates => "fmi2GetNominalsOfContinuousStates",
    /// Only the queued sets.
    Flush => "fmi2Set*",
    // FMI 3.0 (a host of an FMI 3.0 library answers only these, Flush and Free)
    Instantiate3 => "fmi3InstantiateCoSimulation",
    EnterInitializationMode3 => "fmi3EnterInitializationMode",
    ExitInitializationMode3 => "fmi3ExitInitializationMode",
    Terminate3 => "fmi3Terminate",
    Reset3 => "fmi3Reset",
    /// A typed `fmi3Get*`: the type's code in `i[0]` ([`fmi3_type_code`]), `nValues` in `i[1]`.
    Get3 => "fmi3Get*",
    /// A typed `fmi3Set*`, arguments as for `Get3`.
    Set3 => "fmi3Set*",
    GetString3 => "fmi3GetString",
    /// `nValues` in `i[1]`; the answer: the sizes (u64) after the references, then the bytes.
    GetBinary3 => "fmi3GetBinary",
    SetString3 => "fmi3SetString",
    DoStep3 => "fmi3DoStep",
    EnterEventMode3 => "fmi3EnterEventMode",
    UpdateDiscreteStates3 => "fmi3UpdateDiscreteStates",
    EnterStepMode3 => "fmi3EnterStepMode",
    GetFmuState3 => "fmi3GetFMUState",
    SetFmuState3 => "fmi3SetFMUState",
    FreeFmuState3 => "fmi3FreeFMUState",
    InstantiateModelExchange3 => "fmi3InstantiateModelExchange",
    EnterContinuousTimeMode3 => "fmi3EnterContinuousTimeMode",
    CompletedIntegratorStep3 => "fmi3CompletedIntegratorStep",
    SetTime3 => "fmi3SetTime",
    SetContinuousStates3 => "fmi3SetContinuousStates",
    GetContinuousStateDerivatives3 => "fmi3GetContinuousStateDerivatives",
    GetEventIndicators3 => "fmi3GetEventIndicators",
    GetContinuousStates3 => "fmi3GetContinuousStates",
    GetNominalsOfContinuousStates3 => "fmi3GetNominalsOfContinuousStates",
    // FMI 3.0 clocks: the references, then each array of the call ([`clock_arrays`])
    SetClock3 => "fmi3SetClock",
    GetClock3 => "fmi3GetClock",
    GetIntervalDecimal3 => "fmi3GetIntervalDecimal",
    GetIntervalFraction3 => "fmi3GetIntervalFraction",
    GetShiftDecimal3 => "fmi3GetShiftDecimal",
    GetShiftFraction3 => "fmi3GetShiftFraction",
    SetIntervalDecimal3 => "fmi3SetIntervalDecimal",
}

/// Where the arrays of a clock call lie in the data area, after its `n` references: one
/// array of `n` values per width in `widths` (bytes per value), each 8-aligned; the
/// offsets, and the bytes the call takes. The master (`proxy3.rs`) and the host lay them
/// out by this one function.
pub(crate) fn clock_arrays<const K: usize>(n: usize, widths: [usize; K]) -> ([usize; K], usize) {
    let mut at = (4 * n).div_ceil(8) * 8;
    let mut offsets = [0; K];
    for (o, w) in offsets.iter_mut().zip(widths) {
        *o = at;
        at += (w * n).div_ceil(8) * 8;
    }
    (offsets, at)
}

/// The code on the wire of the value type `ty` of `Op::Get3` / `Op::Set3`: its position in
/// `ValueType::ALL`.
pub(crate) fn fmi3_type_code(ty: ValueType) -> i64 {
    ValueType::ALL.iter().position(|t| *t == ty).map_or(-1, |k| k as i64)
}

/// The value type of wire code `code`.
pub(crate) fn fmi3_type(code: i64) -> Option<ValueType> {
    ValueType::ALL.get(usize::try_from(code).ok()?).copied()
}

/// Bytes per value of `ty` (`fmi3Boolean`, a C `bool`: one byte); 0 for a type the
/// protocol does not carry as values.
pub(crate) fn fmi3_width(ty: ValueType) -> usize {
    match ty {
        ValueType::Float64 | ValueType::Int64 | ValueType::UInt64 => 8,
        ValueType::Float32 | ValueType::Int32 | ValueType::UInt32 => 4,
        ValueType::Int16 | ValueType::UInt16 => 2,
        ValueType::Int8 | ValueType::UInt8 | ValueType::Boolean => 1,
        _ => 0,
    }
}

/// The header at the start of the shared region.
#[repr(C)]
pub(crate) struct Header {
    /// Bumped by the master when a request is ready (a futex word).
    pub(crate) request: AtomicU32,
    /// Set to the request number by the host when it is answered (a futex word).
    pub(crate) response: AtomicU32,
    /// 1 while the host sleeps on `request`.
    pub(crate) host_sleeping: AtomicU32,
    /// 1 while the master sleeps on `response`.
    pub(crate) master_sleeping: AtomicU32,
    /// How long the host spins for the next request before sleeping, ns, and every how
    /// many spin rounds it yields the core (0: never); set by the master before the
    /// first call.
    pub(crate) host_spin_ns: u32,
    pub(crate) host_yield_every: u32,
    /// 1: the host spins only while spinning pays ([`SpinGauge`]).
    pub(crate) host_adaptive: u32,
    pub(crate) op: u32,
    /// The fmi2 status of the call.
    pub(crate) status: i32,
    /// Queued sets in the set area (count, bytes used).
    pub(crate) queued: u32,
    pub(crate) queued_bytes: u32,
    /// Index of the queued set that failed (u32::MAX: none), and its status.
    pub(crate) queued_failed: u32,
    pub(crate) queued_status: i32,
    /// Batches of Reals to read after a successful `fmi2DoStep` (the prefetch), their
    /// number; each batch's count, references and values are in the prefetch area.
    pub(crate) prefetch: u32,
    /// The prefetch was read (1) after the last step.
    pub(crate) prefetched: u32,
    /// 1: the library is an FMI 3.0 one (set by the master before the host starts).
    pub(crate) fmi3: u32,
    /// The bytes of each array area ([`Layout::with_area`]; set by the master before the
    /// host starts, which lays the region out from it).
    pub(crate) arrays: u64,
    /// Array lengths and scalar arguments of the call.
    pub(crate) n: u64,
    pub(crate) f: [f64; 4],
    pub(crate) i: [i64; 4],
    /// Set by the host when the FMU's answer (strings, binaries) did not fit the data
    /// area: the bytes it takes (0: it fit).
    pub(crate) answer_needs: u64,
    /// Messages logged during the call, and the bytes they take in the log area.
    pub(crate) log_count: u32,
    pub(crate) log_bytes: u32,
}

const PAGE: usize = 4096;

/// Layout of the region: the header, the call's arrays, the queued sets, the prefetch,
/// the log. Sized from the FMU's numbers of variables and states.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout {
    pub(crate) data: usize,
    pub(crate) data_len: usize,
    pub(crate) sets: usize,
    pub(crate) sets_len: usize,
    pub(crate) prefetch: usize,
    pub(crate) prefetch_len: usize,
    pub(crate) log: usize,
    pub(crate) log_len: usize,
    pub(crate) total: usize,
}

impl Layout {
    /// For calls whose arrays (references and values, or an instantiation's strings) take
    /// at most `arrays` bytes: each array area that plus 64 KiB (strings, alignment), in
    /// whole pages; the log area what the host's log keeps.
    pub(crate) fn for_bytes(arrays: usize) -> Layout {
        Layout::with_area(arrays.saturating_add(64 << 10).div_ceil(PAGE) * PAGE)
    }

    /// With each array area `arrays` bytes (a whole number of pages, as the header's
    /// [`Header::arrays`] gives it to the host).
    pub(crate) fn with_area(arrays: usize) -> Layout {
        let page = PAGE;
        let data = page;
        let sets = data + arrays;
        let prefetch = sets + arrays;
        let log = prefetch + arrays;
        // the host's log keeps at most CAPACITY messages, each bounded: all fit
        let record = 12 + crate::log::MAX_CATEGORY_BYTES + crate::log::MAX_MESSAGE_BYTES + 64;
        let log_len = (crate::log::LogSink::CAPACITY * record).div_ceil(page) * page;
        Layout {
            data,
            data_len: arrays,
            sets,
            sets_len: arrays,
            prefetch,
            prefetch_len: arrays,
            log,
            log_len,
            total: log + log_len,
        }
    }

    /// For an FMU of `values` scalar values (array elements counted one by one) and
    /// `indicators` event indicators, and an instantiation whose strings take `strings`
    /// bytes: 16 bytes per value or indicator (8 for the value, 4 for its reference, and
    /// room for a call that gives both), and the strings.
    pub(crate) fn for_fmu(values: usize, indicators: usize, strings: usize) -> Layout {
        Layout::for_bytes((16 * values.max(indicators).max(16)).max(strings))
    }
}

/// How each side waits for the other: spin at most this long (checking the word every 64
/// pause instructions, yielding the core every `yield_every` rounds, 0: never), then
/// sleep on the futex.
///
/// Spinning pays only when the side waited for has a core of its own: then an answer
/// takes about a microsecond, where a sleep and a futex wake-up take tens (a wake-up in a
/// VM is an inter-processor interrupt through the hypervisor). With fewer cores than the
/// master and its hosts, a spinning side holds the core the other side needs, and one
/// round trip can wait for a scheduler time slice (milliseconds); and a machine busy with
/// other work preempts the side waited for, so that spinning only burns the core. So with
/// `adaptive` (the default) both sides spin only while the cores (`available_parallelism`:
/// the affinity mask and the cgroup's CPU quota) are more than the live hosts, and each
/// only while its spins have paid lately ([`SpinGauge`]); otherwise it sleeps at once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Spin {
    pub(crate) master: Duration,
    pub(crate) host: Duration,
    pub(crate) yield_every: u32,
    pub(crate) adaptive: bool,
}

/// The host processes alive in this process (the master's), for [`Spin`].
pub(crate) static LIVE_HOSTS: AtomicUsize = AtomicUsize::new(0);

/// The cores this process may run on.
pub(crate) fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

impl Spin {
    /// The policy of a run: adaptive, or fixed by `NIGEL_COSIM_SPIN`
    /// (`MASTER_US,HOST_US,YIELD_EVERY`, for measuring the ways of waiting side by side).
    pub(crate) fn of_run() -> Spin {
        let default =
            Spin { master: Duration::from_micros(50), host: Duration::from_micros(30), yield_every: 8, adaptive: true };
        let Some(v) = std::env::var_os("NIGEL_COSIM_SPIN") else { return default };
        let parts: Vec<u64> = v.to_string_lossy().split(',').filter_map(|x| x.trim().parse().ok()).collect();
        match parts[..] {
            [m, h, y] => Spin {
                master: Duration::from_micros(m),
                host: Duration::from_micros(h),
                yield_every: y as u32,
                adaptive: false,
            },
            _ => default,
        }
    }

    /// Whether the master and every live host can each have a core of their own.
    pub(crate) fn cores_to_spare(&self) -> bool {
        !self.adaptive || cores() > LIVE_HOSTS.load(Ordering::Relaxed)
    }
}

/// Whether spinning has paid lately for one waiting side: the share of its recent spins
/// that saw the answer before they ran out (an average over about 16), and a count that
/// lets every 64th wait spin anyway, so that a side that stopped spinning notices when
/// it would pay again.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpinGauge {
    paid: f32,
    waits: u32,
}

impl SpinGauge {
    pub(crate) const fn new() -> SpinGauge {
        SpinGauge { paid: 1.0, waits: 0 }
    }

    /// How long to spin this time, at most `max`.
    fn budget(&mut self, max: Duration) -> Duration {
        self.waits = self.waits.wrapping_add(1);
        if self.paid >= 0.5 || self.waits.is_multiple_of(64) {
            max
        } else {
            Duration::ZERO
        }
    }

    fn record(&mut self, paid: bool) {
        self.paid += (f32::from(u8::from(paid)) - self.paid) / 16.0;
    }
}

/// Waits until `word` differs from `old`: spins for `spin` (yielding every `yield_every`
/// rounds; with a `gauge`, only while spinning pays), then sleeps on the futex with
/// `sleeping` set (the waker wakes only sleepers), at most `slice` at a time; `check` is
/// called after each slice and may end the wait with its error.
#[allow(clippy::too_many_arguments)]
pub(crate) fn wait_for<E>(
    word: &AtomicU32,
    old: u32,
    sleeping: &AtomicU32,
    spin: Duration,
    yield_every: u32,
    gauge: Option<&mut SpinGauge>,
    slice: Duration,
    mut check: impl FnMut() -> Result<(), E>,
) -> Result<(), E> {
    if word.load(Ordering::Acquire) != old {
        return Ok(());
    }
    let mut gauge = gauge;
    let spin = match gauge.as_deref_mut() {
        Some(g) => g.budget(spin),
        None => spin,
    };
    if !spin.is_zero() {
        let start = std::time::Instant::now();
        let mut spins = 0u32;
        let mut paid = false;
        while start.elapsed() < spin {
            for _ in 0..64 {
                std::hint::spin_loop();
            }
            if word.load(Ordering::Acquire) != old {
                paid = true;
                break;
            }
            spins += 1;
            if yield_every > 0 && spins.is_multiple_of(yield_every) {
                std::thread::yield_now();
            }
        }
        if let Some(g) = gauge {
            g.record(paid);
        }
        if paid {
            return Ok(());
        }
    }
    loop {
        sleeping.store(1, Ordering::SeqCst);
        if word.load(Ordering::SeqCst) != old {
            sleeping.store(0, Ordering::SeqCst);
            return Ok(());
        }
        super::os::sleep_on(word, old, slice);
        sleeping.store(0, Ordering::SeqCst);
        if word.load(Ordering::Acquire) != old {
            return Ok(());
        }
        check()?;
    }
}

/// Publishes `value` in `word` and wakes the other side if it sleeps on it.
pub(crate) fn publish(word: &AtomicU32, value: u32, sleeping: &AtomicU32) {
    word.store(value, Ordering::SeqCst);
    if sleeping.load(Ordering::SeqCst) != 0 {
        super::os::wake(word);
    }
}

#[cfg(test)]
mod protocol_tests {
    use super::Op;

    #[test]
    fn wire_numbers_map_back_to_their_calls() {
        for &op in Op::ALL {
            assert_eq!(Op::from_u32(op as u32), Some(op));
        }
        assert_eq!(Op::from_u32(0), None);
        assert_eq!(Op::from_u32(Op::ALL.len() as u32 + 1), None);
        assert_eq!(Op::DoStep.function(), "fmi2DoStep");
        assert_eq!(Op::Instantiate as u32, 1);
    }
}
