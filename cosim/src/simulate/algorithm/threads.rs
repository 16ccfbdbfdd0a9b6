//! `jacobi` with the instances spread over threads.
//!
//! The first [`CALIBRATION_STEPS`] steps run in one thread and measure each instance's
//! time; the instances are then spread over the threads.
//!
//! A pool lives for one run (`std::thread::scope`): `threads - 1` workers plus the
//! calling thread, each owning a fixed group of instances ([`Lane`]s) chosen by their
//! measured cost (longest first, onto the least loaded thread). Per communication step
//! the calling thread publishes the step (an epoch counter), every thread steps its own
//! instances (inputs from the previous step's values, the step, outputs fetched into
//! each instance's buffers), the calling thread waits for all, then writes every
//! instance's outputs into the value slots and records the row. An instance is only ever
//! called by one thread at a time, always with the same sequence of calls as in one
//! thread, so the results are identical to the serial run.
//!
//! The pool runs only while it pays: after its first 1000 steps it is compared with the
//! wall time per step measured in one thread over the calibration steps, and stops if it
//! is slower (the summary's `parallel_steps` says how many steps it ran).
//!
//! Threads wait for the next step by spinning briefly (a step of a few microseconds is
//! shorter than putting a thread to sleep and waking it again), then park; the thread
//! that makes them ready unparks them, which costs one atomic operation when they are
//! not parked. On a machine with no free core the spinning only delays the others, so
//! it is short.

use super::{Communication, Core, Jacobi};
use crate::error::{Error, Result};
use crate::me::Solver;
use crate::simulate::clock::{Clock, Point};
use crate::simulate::lane::Lane;
use crate::simulate::observer::Observers;
use crate::simulate::profiler::Profiler;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, RwLock};

/// Busy-wait before parking (`pause` takes from 10 to 140 cycles depending on the
/// processor, so the bound is a time, checked every 32 spins).
const SPIN_TIME: std::time::Duration = std::time::Duration::from_micros(10);

struct Shared {
    groups: Vec<Mutex<Vec<Lane>>>,
    values: RwLock<Vec<f64>>,
    args: Mutex<Point>,
    epoch: AtomicU64,
    done: AtomicUsize,
    stop: AtomicBool,
    panicked: AtomicBool,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

fn wait_until(ready: impl Fn() -> bool) {
    if ready() {
        return;
    }
    let start = std::time::Instant::now();
    let mut spinning = true;
    let mut spins = 0u32;
    while !ready() {
        if spinning {
            std::hint::spin_loop();
            spins += 1;
            if spins.is_multiple_of(32) && start.elapsed() > SPIN_TIME {
                spinning = false;
            }
        } else {
            // unparked by the thread that makes us ready; the timeout only bounds a
            // wake-up lost to a race (park tokens make that rare)
            std::thread::park_timeout(std::time::Duration::from_millis(1));
        }
    }
}

/// Steps the instances of group `g` once; an error stays in its lane, a panic is flagged.
fn work(shared: &Shared, g: usize, solver: Solver, profile: bool) {
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let a = *lock(&shared.args);
        let values = shared.values.read().unwrap_or_else(|e| e.into_inner());
        let mut lanes = lock(&shared.groups[g]);
        for lane in lanes.iter_mut() {
            if let Err(e) = lane.jacobi_step(&values, a, profile, solver) {
                lane.error = Some(e);
                break;
            }
        }
    }));
    if outcome.is_err() {
        shared.panicked.store(true, Ordering::Release);
    }
}

/// Groups of lanes with about equal measured cost (`Lane::spent`), longest first onto
/// the least loaded group.
fn partition(mut lanes: Vec<Lane>, threads: usize) -> Vec<Vec<Lane>> {
    lanes.sort_by(|a, b| b.spent.cmp(&a.spent).then(a.index.cmp(&b.index)));
    let mut groups: Vec<Vec<Lane>> = (0..threads).map(|_| Vec::new()).collect();
    let mut load = vec![std::time::Duration::ZERO; threads];
    for lane in lanes {
        let g = (0..threads).min_by_key(|g| (load[*g], *g)).unwrap_or(0);
        load[g] += lane.spent;
        groups[g].push(lane);
    }
    for g in groups.iter_mut() {
        g.sort_by_key(|l| l.index);
    }
    groups
}

/// Steps in the pool before it is compared with one thread.
const PROBE_STEPS: u64 = 1000;

/// A pool for one run.
struct Pool<'a> {
    /// Threads, the calling one included (at least 2, at most the number of lanes).
    threads: usize,
    solver: Solver,
    /// Lanes measure the time of their calls.
    profile: bool,
    /// Wall time of one step in one thread (measured): after [`PROBE_STEPS`] steps
    /// slower than this, the pool stops and the caller goes on in one thread.
    serial_step: std::time::Duration,
    /// Some instance has FMI 3.0 clocks ([`Core::clocked`]), and the clock connections.
    clocked: bool,
    clock_links: &'a [crate::system::ClockConnection],
}

impl Pool<'_> {
    /// Runs the `jacobi` steps `steps` of `clock`; the observers are told after each step
    /// with all outputs in their slots. Returns the lanes in their original order and the
    /// first step not run (the end of `steps` unless the pool was slower than one thread),
    /// or the first error (lowest instance index) of a step, which ends the run.
    fn run(
        &self,
        lanes: Vec<Lane>,
        values: &mut Vec<f64>,
        clock: &Clock,
        steps: Range<u64>,
        observers: &mut Observers,
    ) -> (Vec<Lane>, Result<u64>) {
        let solver = self.solver;
        let profile = self.profile;
        let threads = self.threads.clamp(1, lanes.len().max(1));
        let shared = Shared {
            groups: partition(lanes, threads).into_iter().map(Mutex::new).collect(),
            values: RwLock::new(std::mem::take(values)),
            args: Mutex::new(Point::default()),
            epoch: AtomicU64::new(0),
            done: AtomicUsize::new(0),
            stop: AtomicBool::new(false),
            panicked: AtomicBool::new(false),
        };
        let main = std::thread::current();
        let run = crate::exit_guard::current_run();
        let result = std::thread::scope(|scope| {
            let mut workers = Vec::with_capacity(threads - 1);
            for g in 1..threads {
                let shared = &shared;
                let main = main.clone();
                let handle = scope.spawn(move || {
                    run.enter();
                    let mut seen = 0;
                    loop {
                        wait_until(|| shared.epoch.load(Ordering::Acquire) != seen);
                        seen = shared.epoch.load(Ordering::Acquire);
                        if shared.stop.load(Ordering::Acquire) {
                            return;
                        }
                        work(shared, g, solver, profile);
                        shared.done.fetch_add(1, Ordering::AcqRel);
                        main.unpark();
                    }
                });
                workers.push(handle.thread().clone());
            }
            // one step of every lane in the pool, from `a.t` to `a.t_next`: the errors
            // taken (the lowest instance's first), the outputs scattered into their slots
            let step_all = |a: Point| -> Result<()> {
                *lock(&shared.args) = a;
                shared.done.store(0, Ordering::Release);
                shared.epoch.fetch_add(1, Ordering::AcqRel);
                for w in &workers {
                    w.unpark();
                }
                work(&shared, 0, solver, profile);
                wait_until(|| shared.done.load(Ordering::Acquire) == threads - 1);
                if shared.panicked.load(Ordering::Acquire) {
                    return Err(Error::Experiment("a thread stepping the instances panicked".into()));
                }
                let mut values = shared.values.write().unwrap_or_else(|e| e.into_inner());
                let mut first: Option<(usize, Error)> = None;
                for g in &shared.groups {
                    for lane in lock(g).iter_mut() {
                        if let Some(e) = lane.error.take() {
                            if first.as_ref().is_none_or(|(i, _)| lane.index < *i) {
                                first = Some((lane.index, e));
                            }
                        }
                    }
                }
                if let Some((_, e)) = first {
                    return Err(e);
                }
                for g in &shared.groups {
                    for lane in lock(g).iter() {
                        lane.scatter(&mut values, a.output_point);
                    }
                }
                Ok(())
            };
            // FMI 3.0 clocks, as `Communication::run` in one thread: the step split at
            // every tick inside it (a row there), the output clocks' ticks carried
            let next_tick = |from: f64, until: f64| -> Option<f64> {
                let guards: Vec<_> = shared.groups.iter().map(lock).collect();
                super::next_tick_inside(guards.iter().flat_map(|g| g.iter()), from, until)
            };
            let carry = |t_next: f64| {
                if !self.clock_links.is_empty() {
                    let mut guards: Vec<_> = shared.groups.iter().map(lock).collect();
                    super::carry_clock_ticks(guards.iter_mut().flat_map(|g| g.iter_mut()), self.clock_links, t_next);
                }
            };
            let mut drive = || -> Result<u64> {
                let start = std::time::Instant::now();
                let first = steps.start;
                for n in steps.clone() {
                    if n == first + PROBE_STEPS && start.elapsed() > self.serial_step * PROBE_STEPS as u32 {
                        return Ok(n); // slower than one thread: the caller goes on alone
                    }
                    let mut a = clock.point(n);
                    while let Some(tick) = self.clocked.then(|| next_tick(a.t, a.t_next)).flatten() {
                        step_all(Point { t_next: tick, output_point: true, ..a })?;
                        carry(tick);
                        observers.recorder.push_row(tick, &shared.values.read().unwrap_or_else(|e| e.into_inner()));
                        a.t = tick;
                    }
                    step_all(a)?;
                    carry(a.t_next);
                    observers.step_complete(&a, &shared.values.read().unwrap_or_else(|e| e.into_inner()))?;
                }
                Ok(steps.end)
            };
            let result = drive();
            shared.stop.store(true, Ordering::Release);
            shared.epoch.fetch_add(1, Ordering::AcqRel);
            for w in &workers {
                w.unpark();
            }
            result
        });
        *values = shared.values.into_inner().unwrap_or_else(|e| e.into_inner());
        let mut lanes: Vec<Lane> =
            shared.groups.into_iter().flat_map(|g| g.into_inner().unwrap_or_else(|e| e.into_inner())).collect();
        lanes.sort_by_key(|l| l.index);
        (lanes, result)
    }
}

/// Steps run in one thread before the instances are spread over threads by their
/// measured cost (and the time of one step in one thread taken as the mark the pool must
/// beat).
const CALIBRATION_STEPS: u64 = 200;

/// `jacobi` with the instances in `threads` threads (the calling one included); a system
/// with a coupled Model Exchange group runs in one thread.
pub(crate) struct ThreadedJacobi {
    pub(crate) threads: usize,
}

impl Communication for ThreadedJacobi {
    fn propagate(&mut self, core: &mut Core) -> Result<()> {
        Jacobi.propagate(core)
    }

    fn step(&mut self, core: &mut Core, p: Point, calls: Option<&mut Profiler>) -> Result<()> {
        Jacobi.step(core, p, calls)
    }

    fn finish(&mut self, core: &mut Core) -> Result<()> {
        Jacobi.finish(core)
    }

    fn run(&mut self, core: &mut Core, observers: &mut Observers, range: Range<u64>) -> Result<()> {
        let threads = if core.group.is_some() { 1 } else { self.threads.min(core.lanes.len()) };
        let steps = range.end;
        let mut first = range.start;
        if threads > 1 {
            // a few steps in one thread to measure each instance's cost, then the
            // instances spread over the threads by that cost
            let calibration = steps.min(first + CALIBRATION_STEPS);
            let calibration_start = std::time::Instant::now();
            // in one thread as `Jacobi` runs (the steps split at clock ticks), each lane
            // measuring the time of its calls
            let profile = std::mem::replace(&mut core.profile, true);
            let calibrated = Jacobi.run(core, observers, first..calibration);
            core.profile = profile;
            calibrated?;
            let serial_step = calibration_start.elapsed() / (calibration - first).max(1) as u32;
            first = calibration;
            if first < steps {
                let lanes = std::mem::take(&mut core.lanes);
                let clock = core.clock;
                let clock_links = std::mem::take(&mut core.clock_links);
                let pool = Pool {
                    threads,
                    solver: core.solver,
                    profile: core.profile,
                    serial_step,
                    clocked: core.clocked,
                    clock_links: &clock_links,
                };
                let (back, next) = pool.run(lanes, &mut core.values, &clock, first..steps, observers);
                core.lanes = back;
                core.clock_links = clock_links;
                let next = next?;
                core.parallel_steps += next - first;
                first = next;
            }
        }
        Jacobi.run(core, observers, first..steps)
    }
}
