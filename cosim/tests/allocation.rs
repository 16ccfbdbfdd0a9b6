//! The master's per-step path does not allocate: a run of 20 times more steps makes
//! exactly as many heap allocations (counted by a global allocator in this test binary;
//! the C test FMUs allocate only when instantiated, with calloc, outside this count).

mod common;
use common::{build_ball, build_fmu, build_latch, work_dir, Model};
use nigel_cosim::{simulate, Algorithm, Experiment, Fmu, SystemBuilder};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

struct Counting;
static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The count is process-wide: the tests of this file run one at a time, or one would
/// count the other's allocations (the harness runs tests on parallel threads).
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// (algorithm, threads, recorded variables, output interval)
type Case = (Algorithm, usize, Option<Vec<String>>, Option<f64>);

#[test]
fn the_step_loop_allocates_nothing() {
    let _alone = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = work_dir("allocation");
    let mut b = SystemBuilder::new();
    b.add_instance("src", Fmu::load(&build_fmu(Model::Source, &dir, &[])).unwrap()).unwrap();
    b.add_instance("amp", Fmu::load(&build_fmu(Model::Gain, &dir, &[])).unwrap()).unwrap();
    b.add_instance("int", Fmu::load(&build_fmu(Model::Integrator, &dir, &[])).unwrap()).unwrap();
    b.add_instance("src2", Fmu::load(&build_fmu(Model::Source, &dir, &[])).unwrap()).unwrap();
    b.connect("src.y", "amp.u").unwrap();
    b.connect("amp.y", "int.u").unwrap();
    let system = b.build();
    let cases: [Case; 6] = [
        (Algorithm::Ordered, 1, None, None),
        (Algorithm::Ordered, 1, Some(vec![]), None),
        (Algorithm::Ordered, 1, None, Some(0.01)),
        (Algorithm::Jacobi, 1, None, None),
        (Algorithm::Jacobi, 1, Some(vec!["int.x".into(), "amp.u".into()]), Some(0.003)),
        (Algorithm::Jacobi, 2, None, None),
    ];
    for (algorithm, threads, record, interval) in cases {
        let count = |steps: u32, profile: bool| {
            let mut e = Experiment::new(f64::from(steps) * 1e-3, 1e-3);
            e.algorithm = algorithm;
            e.threads = threads;
            e.record = record.clone();
            e.profile = profile;
            e.output_interval = interval;
            let before = ALLOCATIONS.load(Ordering::Relaxed);
            let (results, _) = simulate(&system, &e).unwrap();
            let after = ALLOCATIONS.load(Ordering::Relaxed);
            assert!(results.rows() > 1);
            after - before
        };
        for profile in [false, true] {
            let short = count(300, profile);
            let long = count(6000, profile);
            assert_eq!(
                short, long,
                "{algorithm:?}, {threads} threads, record {record:?}, interval {interval:?}, profile {profile}: \
                 {short} allocations for 300 steps, {long} for 6000"
            );
        }
    }
}

#[test]
fn coupled_model_exchange_steps_allocate_nothing_between_events() {
    let _alone = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    // the ball and the counter fed by its velocity, integrated together: runs of 300 and
    // 6000 steps of 10 us end before the first bounce (0.45 s), so no event happens
    let dir = work_dir("allocation-me");
    let mut b = SystemBuilder::new();
    b.add_instance("ball", Fmu::load(&build_ball(&dir)).unwrap()).unwrap();
    b.add_instance("counter", Fmu::load(&build_latch(&dir)).unwrap()).unwrap();
    b.connect("ball.v", "counter.u").unwrap();
    let system = b.build();
    for algorithm in [Algorithm::Ordered, Algorithm::Jacobi] {
        for solver in
            [nigel_cosim::Solver::Rk4 { max_step: None }, nigel_cosim::Solver::Dopri5 { rtol: 1e-8, atol: 1e-10 }]
        {
            let count = |steps: u32| {
                let mut e = Experiment::new(f64::from(steps) * 1e-5, 1e-5);
                e.algorithm = algorithm;
                e.solver = solver;
                let before = ALLOCATIONS.load(Ordering::Relaxed);
                let (results, summary) = simulate(&system, &e).unwrap();
                let after = ALLOCATIONS.load(Ordering::Relaxed);
                assert!(summary.events.is_empty() && results.rows() == steps as usize + 1);
                after - before
            };
            let (short, long) = (count(300), count(6000));
            assert_eq!(short, long, "{algorithm:?} {solver:?}: {short} allocations for 300 steps, {long} for 6000");
        }
    }
}
