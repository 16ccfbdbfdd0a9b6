//! The random call sequences of `random_calls.rs`, one loop for both generations: the seeded
//! generator, the hostile numbers, the importer's shadow of the instance's state and how a
//! call's status moves it, the state-table check after every call, the check that no
//! non-finite number is handed out with OK, and the loop over every built FMU and interface.
//! Each generation ([`Generation`], `fmi2.rs` and `fmi3.rs`) brings only its own calls.

use std::ffi::c_void;

use fmi_export::states::{Function, Generation as Abi, Machine, Scope};
use nigel_integration_tests::{built_fmu, Fmu, DISCARD, ERROR, OK};

pub mod fmi2;
pub mod fmi3;

/// xorshift64*: the same sequences on every platform.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    pub fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.below(items.len())]
    }
    /// A time argument: mostly `now`, else one of the times a call must refuse or survive.
    pub fn time(&mut self, now: f64) -> f64 {
        if self.chance(70) {
            now
        } else {
            self.pick(&[0.0, -1.0, 1.0, f64::NAN, f64::INFINITY, now + 1e-3])
        }
    }
}

/// The arguments of fmi2SetupExperiment / fmi3EnterInitializationMode, drawn in this
/// order: start, stop, toleranceDefined, tolerance, stopTimeDefined.
pub struct Experiment {
    pub start: f64,
    pub stop: f64,
    pub tolerance_defined: bool,
    pub tolerance: f64,
    pub stop_defined: bool,
}

impl Experiment {
    pub fn draw(rng: &mut Rng) -> Experiment {
        let start = rng.pick(&[0.0, 0.0, 1.0, f64::NAN, -5.0]);
        let stop = rng.pick(&[10.0, 0.5, f64::NAN, f64::INFINITY, -1.0]);
        let tolerance_defined = rng.below(2) == 1;
        let tolerance = rng.pick(&HOSTILE);
        let stop_defined = rng.below(2) == 1;
        Experiment { start, stop, tolerance_defined, tolerance, stop_defined }
    }
}

/// The numbers the sequences pass where a number is asked for.
pub const HOSTILE: [f64; 12] =
    [0.0, 1.0, -1.0, 0.3, 1e-3, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e308, -1e308, 5e-324, 2.5];

/// The importer side of one instance: what it believes the state is.
pub struct Shadow {
    pub machine: Option<Machine>,
    pub time: f64,
    /// live FMU states and the machine they were saved in (None: unknown, deserialized)
    pub states: Vec<(*mut c_void, Option<Machine>)>,
    pub freed: Vec<*mut c_void>,
    pub bytes: Vec<u8>,
}

impl Shadow {
    /// A freshly instantiated instance.
    pub fn instantiated() -> Shadow {
        Shadow {
            machine: Some(Machine::Instantiated),
            time: 0.0,
            states: Vec::new(),
            freed: Vec::new(),
            bytes: Vec::new(),
        }
    }

    /// An FMU state argument: a live one, a freed one, a made-up pointer or NULL.
    pub fn state_arg(&self, rng: &mut Rng) -> *mut c_void {
        match rng.below(4) {
            0 | 1 if !self.states.is_empty() => self.states[rng.below(self.states.len())].0,
            2 if !self.freed.is_empty() => self.freed[rng.below(self.freed.len())],
            3 => 0x40usize as *mut c_void,
            _ => std::ptr::null_mut(),
        }
    }

    /// fmiXGetFMUstate through `get`: now and then into a live state (overwriting it),
    /// else into a new one; a new state is remembered with the machine it was saved in.
    pub fn get_state(&mut self, rng: &mut Rng, get: impl FnOnce(&mut *mut c_void) -> i32) -> i32 {
        let mut s = if rng.chance(20) && !self.states.is_empty() { self.states[0].0 } else { std::ptr::null_mut() };
        let before = s;
        let status = get(&mut s);
        if status == OK {
            if before.is_null() {
                self.states.push((s, self.machine));
            } else if let Some(e) = self.states.iter_mut().find(|e| e.0 == s) {
                e.1 = self.machine;
            }
        }
        status
    }

    /// fmiXSetFMUstate through `set` with a state argument; with OK, `restored` is the
    /// machine the state was saved in (None: unknown).
    pub fn set_state(
        &mut self,
        rng: &mut Rng,
        restored: &mut Option<Option<Machine>>,
        set: impl FnOnce(*mut c_void) -> i32,
    ) -> i32 {
        let s = self.state_arg(rng);
        let status = set(s);
        if status == OK {
            *restored = Some(self.states.iter().find(|e| e.0 == s).map(|e| e.1).unwrap_or(None));
        }
        status
    }

    /// fmiXFreeFMUstate through `free` with a state argument: a freed live state must come
    /// back as NULL and is remembered as freed.
    pub fn free_state(&mut self, rng: &mut Rng, free: impl FnOnce(&mut *mut c_void) -> i32) -> i32 {
        let mut s = self.state_arg(rng);
        let before = s;
        let status = free(&mut s);
        if status == OK && !before.is_null() {
            assert!(s.is_null());
            self.states.retain(|e| e.0 != before);
            self.freed.push(before);
        }
        status
    }

    /// fmiXSerializeFMUstate of a state argument into a buffer of the size `size` tells
    /// (now and then half of it); with OK the bytes are kept for deserialization.
    pub fn serialize_state(
        &mut self,
        rng: &mut Rng,
        size: impl FnOnce(*mut c_void, &mut usize) -> i32,
        serialize: impl FnOnce(*mut c_void, &mut [u8]) -> i32,
    ) -> i32 {
        let s = self.state_arg(rng);
        let mut n = 0usize;
        let _ = size(s, &mut n);
        let n = if rng.chance(10) { n / 2 } else { n };
        let mut buf = vec![0u8; n.min(1 << 20)];
        let status = serialize(s, &mut buf);
        if status == OK {
            self.bytes = buf;
        }
        status
    }

    /// fmiXDeSerializeFMUstate through `deserialize` of the kept bytes, now and then with a
    /// flipped bit, cut short (where `truncate`) or replaced by random bytes; a state made
    /// is remembered with an unknown machine.
    pub fn deserialize_state(
        &mut self,
        rng: &mut Rng,
        truncate: bool,
        deserialize: impl FnOnce(&[u8], &mut *mut c_void) -> i32,
    ) -> i32 {
        let mut bytes = self.bytes.clone();
        if !bytes.is_empty() && rng.chance(50) {
            let k = rng.below(bytes.len());
            bytes[k] ^= 1 << rng.below(8);
        }
        if truncate && !bytes.is_empty() && rng.chance(20) {
            bytes.truncate(rng.below(bytes.len()));
        }
        if rng.chance(10) {
            bytes = (0..rng.below(200)).map(|_| rng.next() as u8).collect();
        }
        let mut s = std::ptr::null_mut();
        let status = deserialize(&bytes, &mut s);
        if status == OK {
            self.states.push((s, None));
        }
        status
    }

    /// After `function` made `call`: no non-finite number in `call.reals_out[..k]` with OK
    /// (where `call.check_reals` is `Some(k)`), and the importer's view of the new state.
    pub fn after(&mut self, function: Function, call: Call, co_simulation: bool) {
        let fmi2 = function.generation() == Abi::Fmi2;
        if call.status == OK {
            if let Some(k) = call.check_reals {
                if let Some(bad) = call.reals_out[..k].iter().find(|x| !x.is_finite()) {
                    panic!("{function:?} handed out {bad} with {}", if fmi2 { "fmi2OK" } else { "fmi3OK" });
                }
            }
        }
        // an FMI 3.0 function moves the state as its FMI 2.0 counterpart does
        let as_fmi2 = function.counterpart().unwrap_or(function);
        if call.status == ERROR {
            self.machine = Some(Machine::Error);
        } else if call.status == DISCARD && as_fmi2 == Function::DoStep {
            // a Discard of the step leaves an FMI 2.0 instance in Step Failed; FMI 3.0 has
            // no such state: the instance stays in Step Mode at the time the step reached
            if fmi2 {
                self.machine = Some(Machine::StepFailed);
            } else {
                // at the time the step reached (a guess below: a wrong one just gives an error)
                self.time = f64::NAN;
            }
        } else if call.status == OK || call.status == 1 {
            if let Some(t) = call.new_time {
                self.time = t;
            }
            let after = match as_fmi2 {
                Function::EnterInitializationMode => Some(Some(Machine::InitializationMode)),
                Function::ExitInitializationMode => {
                    Some(Some(if co_simulation { Machine::StepComplete } else { Machine::EventMode }))
                }
                Function::Terminate => Some(Some(Machine::Terminated)),
                Function::Reset => {
                    self.time = 0.0;
                    Some(Some(Machine::Instantiated))
                }
                Function::EnterEventMode => Some(Some(Machine::EventMode)),
                Function::EnterContinuousTimeMode => Some(Some(Machine::ContinuousTimeMode)),
                Function::SetFMUstate => {
                    self.time = f64::NAN; // unknown until the next reset
                    call.restored
                }
                _ => None,
            };
            if let Some(m) = after {
                self.machine = m;
            }
        }
        if self.time.is_nan() {
            // the restored time is unknown here: a guess (a wrong one just gives an error)
            self.time = 0.0;
        }
    }
}

/// Runs `run(fmu, co_simulation, seed)` on every FMU of `build-fmu`'s list and each
/// interface it offers, prints the counts (OK, Warning, Discard, Error) with `what`, and
/// checks that enough calls succeeded to mean anything; returns the counts of `plant`
/// (CS, then ME).
pub fn every_fmu_and_interface(
    what: &str,
    sequences: usize,
    seed: u64,
    plant: &str,
    mut run: impl FnMut(&Fmu, bool, u64) -> [usize; 4],
) -> Vec<[usize; 4]> {
    let mut plant_counts = Vec::new();
    for (k, target) in build_fmu::targets().iter().enumerate() {
        let fmu = Fmu::load(&built_fmu(&target.model_identifier).unwrap()).unwrap();
        for co_simulation in [true, false] {
            let offered = if co_simulation {
                fmu.description.co_simulation.is_some()
            } else {
                fmu.description.model_exchange.is_some()
            };
            if !offered {
                continue;
            }
            let counts = run(&fmu, co_simulation, seed ^ (k as u64 * 2 + co_simulation as u64));
            let total: usize = counts.iter().sum();
            println!(
                "{} {}{what}: {sequences} sequences, {total} calls: {} OK, {} Warning, {} Discard, {} Error",
                target.model_identifier,
                if co_simulation { "CS" } else { "ME" },
                counts[0],
                counts[1],
                counts[2],
                counts[3]
            );
            assert!(counts[0] > total / 20, "too few successful calls to mean anything: {counts:?}");
            if target.model_identifier == plant {
                plant_counts.push(counts);
            }
        }
    }
    plant_counts
}

/// What one call did: its status and what the shadow learns from it.
pub struct Call {
    pub status: i32,
    /// with OK, the first this many of `reals_out` must be finite
    pub check_reals: Option<usize>,
    pub reals_out: Vec<f64>,
    /// the time the call set (with OK or Warning)
    pub new_time: Option<f64>,
    /// with OK of the set-state call: the machine the state was saved in (None: unknown)
    pub restored: Option<Option<Machine>>,
}

/// One FMI generation's side of the random sequences on one FMU and interface.
pub trait Generation {
    /// A live instance with its log, freed on drop.
    type Live;
    /// Every function of the generation, which the sequences draw from.
    const FUNCTIONS: &'static [Function];
    /// A new instance (the sequence's first call).
    fn instantiate(&self) -> Self::Live;
    /// The calls that make progress from `machine` (so that sequences reach the deeper
    /// states).
    fn progress(machine: Option<Machine>) -> &'static [Function];
    /// The functions the sequences leave out (instantiation and freeing).
    fn left_out(function: Function) -> bool;
    /// Draws the arguments of `function` and calls it; `None` for a call without status
    /// (the version and platform strings, checked there).
    ///
    /// # Safety
    /// `live` is a live instance of this generation.
    unsafe fn call(&self, live: &Self::Live, function: Function, rng: &mut Rng, sh: &mut Shadow) -> Option<Call>;
    /// A rule of the generation beyond the state table by which `function` must be refused.
    fn refuses(&self, _function: Function) -> bool {
        false
    }
    /// What the generation checks or does after the shadow has moved.
    fn after_call(&self, _live: &Self::Live, _function: Function, _status: i32, _rng: &mut Rng, _sh: &mut Shadow) {}
}

/// `sequences` seeded sequences of 1 to 16 calls of `generation` on fresh instances, each call
/// checked: a defined status, a call the state table (or the generation's own rule) forbids
/// refused with Error, no non-finite number with OK. Returns the counts of OK, Warning,
/// Discard, Error.
pub fn run<G: Generation>(generation: &G, co_simulation: bool, sequences: usize, seed: u64) -> [usize; 4] {
    let mut rng = Rng(seed);
    let mut counts = [0usize; 4];
    let interface_scope = if co_simulation { Scope::CoSimulation } else { Scope::ModelExchange };
    for _ in 0..sequences {
        let live = generation.instantiate();
        let mut sh = Shadow::instantiated();
        for _ in 0..1 + rng.below(16) {
            // 40 %: a call that makes progress from the current state, else any function
            let function = if rng.chance(40) { rng.pick(G::progress(sh.machine)) } else { rng.pick(G::FUNCTIONS) };
            if G::left_out(function) {
                continue;
            }
            let Some(call) = (unsafe { generation.call(&live, function, &mut rng, &mut sh) }) else { continue };
            let status = call.status;
            assert!((0..=3).contains(&status), "{function:?} returned {status}");
            counts[status as usize] += 1;
            // the state table: a call it forbids is an error
            if let Some(m) = sh.machine {
                let wrong_interface = function.scope() != Scope::Common && function.scope() != interface_scope;
                if wrong_interface || generation.refuses(function) || !function.allowed_in(m) {
                    assert_eq!(status, ERROR, "{function:?} in {m:?} ({})", if co_simulation { "CS" } else { "ME" });
                }
            }
            sh.after(function, call, co_simulation);
            generation.after_call(&live, function, status, &mut rng, &mut sh);
        }
        // the instance is freed with its live FMU states (the allocator would report a double free)
    }
    counts
}
