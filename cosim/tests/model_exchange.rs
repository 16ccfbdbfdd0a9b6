//! Model Exchange through the master: RK4 against the plant's own Co-Simulation RK4,
//! state events of a bouncing ball located against the closed-form crossing times,
//! time events exactly on time, dopri5 against RK4 and the exact solution, and a
//! mixed CS + ME system.

mod common;
use common::{build_ball, build_fmu, plant_fmu, work_dir, Model};
use nigel_cosim::{simulate, Algorithm, Experiment, Fmu, ImportOptions, Interface, Solver, SystemBuilder};

fn plant(interface: Interface) -> std::sync::Arc<Fmu> {
    Fmu::load_with(&plant_fmu(), &ImportOptions { interface: Some(interface), ..ImportOptions::default() }).unwrap()
}

fn plant_run(interface: Interface, solver: Solver) -> nigel_cosim::Results {
    let mut b = SystemBuilder::new();
    b.add_instance("p", plant(interface)).unwrap();
    for (k, v) in
        [("v_x_start", "0.35"), ("delta_fl", "0.2"), ("delta_fr", "0.2"), ("tau_rl", "0.02"), ("mu_rr", "0.3")]
    {
        b.set_text(&format!("p.{k}"), v).unwrap();
    }
    let mut e = Experiment::new(2.0, 1e-3);
    e.solver = solver;
    simulate(&b.build(), &e).unwrap().0
}

#[test]
fn me_rk4_equals_the_plants_own_co_simulation_rk4() {
    // the plant's CS takes RK4 sub-steps of at most 0.5 ms: 2 per 1 ms step
    let cs = plant_run(Interface::CoSimulation, Solver::default());
    let me = plant_run(Interface::ModelExchange, Solver::Rk4 { max_step: Some(0.5e-3) });
    assert_eq!(cs.names, me.names);
    let mut worst = 0.0f64;
    for (a, b) in cs.values.iter().zip(&me.values) {
        worst = worst.max((a - b).abs() / a.abs().max(1.0));
    }
    eprintln!("ME RK4 vs CS RK4: largest difference {worst:e}");
    assert!(worst < 1e-12, "largest difference {worst}");
    assert!(cs.column("psi").unwrap()[2000].abs() > 1e-2, "the car turned");
    // one RK4 step per 1 ms is a different (coarser) solution: the comparison can fail
    let coarse = plant_run(Interface::ModelExchange, Solver::Rk4 { max_step: None });
    let d = cs.values.iter().zip(&coarse.values).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(d > 1e-12, "{d}");
    // dopri5 at tight tolerance agrees with RK4 at 0.5 ms to its truncation error
    let dp = plant_run(Interface::ModelExchange, Solver::Dopri5 { rtol: 1e-10, atol: 1e-12 });
    let d = cs.values.iter().zip(&dp.values).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(d < 1e-8, "dopri5 vs RK4: {d}");
}

fn ball_run(
    solver: Solver,
    stop: f64,
    h: f64,
    kick: Option<(f64, f64)>,
) -> (nigel_cosim::Results, nigel_cosim::Summary) {
    // one folder per call: tests run in parallel threads
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = work_dir(&format!("ball-{}", CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
    let mut b = SystemBuilder::new();
    b.add_instance("ball", Fmu::load(&build_ball(&dir)).unwrap()).unwrap();
    if let Some((t, k)) = kick {
        b.set_text("ball.t_kick", &t.to_string()).unwrap();
        b.set_text("ball.kick", &k.to_string()).unwrap();
    }
    let mut e = Experiment::new(stop, h);
    e.solver = solver;
    simulate(&b.build(), &e).unwrap()
}

#[test]
fn bouncing_ball_state_events_are_located_to_1e_10_s() {
    let g: f64 = 9.81;
    let t1 = (2.0 / g).sqrt(); // h = 1 - g t^2 / 2 = 0
    let t2 = t1 + 2.0 * 0.7 * g * t1 / g; // flight after the bounce: 2 v / g
    for solver in [Solver::Rk4 { max_step: None }, Solver::Dopri5 { rtol: 1e-10, atol: 1e-12 }] {
        let (r, s) = ball_run(solver, 1.5, 0.01, None);
        let state: Vec<f64> = s.events.iter().filter(|e| e.kind == "state").map(|e| e.time).collect();
        assert!(state.len() >= 2, "{solver:?}: {state:?}");
        eprintln!("{solver:?}: first bounce {:e} s from exact, second {:e} s", state[0] - t1, state[1] - t2);
        assert!((state[0] - t1).abs() < 1e-10, "{solver:?}: {} vs {t1}", state[0]);
        assert!((state[1] - t2).abs() < 1e-10, "{solver:?}: {} vs {t2}", state[1]);
        // between bounces the states are the exact parabola (both methods are exact for it)
        let (t, h) = (r.column("time").unwrap(), r.column("h").unwrap());
        let k = 90; // t = 0.9 s, after the first bounce, before the second
        let v1 = 0.7 * g * t1;
        let exact = v1 * (t[k] - state[0]) - 0.5 * g * (t[k] - state[0]).powi(2);
        assert!((h[k] - exact).abs() < 1e-9, "{solver:?}: h(0.9) = {} vs {exact}", h[k]);
    }
}

#[test]
fn time_events_fall_exactly_on_their_time() {
    // a kick at t = 0.123 (not a communication point of the 0.01 s grid)
    let (r, s) = ball_run(Solver::Rk4 { max_step: None }, 0.3, 0.01, Some((0.123, 2.0)));
    let time: Vec<&nigel_cosim::Event> = s.events.iter().filter(|e| e.kind == "time").collect();
    assert_eq!(time.len(), 1, "{:?}", s.events);
    assert_eq!(time[0].time, 0.123);
    // v(0.3) = -g 0.3 + 2 exactly, h(0.3) = 1 - g 0.3^2/2 + 2 (0.3 - 0.123)
    let v = r.column("v").unwrap();
    let h = r.column("h").unwrap();
    assert!((v[30] - (-9.81 * 0.3 + 2.0)).abs() < 1e-12, "{}", v[30]);
    assert!((h[30] - (1.0 - 9.81 * 0.09 / 2.0 + 2.0 * (0.3 - 0.123))).abs() < 1e-12, "{}", h[30]);
}

#[test]
fn mixed_co_simulation_and_model_exchange_system() {
    // a CS source drives an ME plant input: ordered, so the plant sees the source at t_k
    let dir = work_dir("mixed");
    let mut b = SystemBuilder::new();
    b.add_instance("src", Fmu::load(&build_fmu(Model::Source, &dir, &[])).unwrap()).unwrap();
    b.add_instance("p", plant(Interface::ModelExchange)).unwrap();
    b.add_instance("q", plant(Interface::CoSimulation)).unwrap();
    b.connect("src.y", "p.mu_fl").unwrap();
    b.connect("src.y", "q.mu_fl").unwrap();
    for p in ["p", "q"] {
        b.set_text(&format!("{p}.v_x_start"), "0.3").unwrap();
        b.set_text(&format!("{p}.delta_fl"), "0.1").unwrap();
    }
    let mut e = Experiment::new(0.5, 1e-3);
    e.algorithm = Algorithm::Ordered;
    e.solver = Solver::Rk4 { max_step: Some(0.5e-3) };
    e.record = Some(vec!["p.mu_fl".into(), "p.psi".into(), "q.psi".into(), "p.v_y".into(), "q.v_y".into()]);
    let (r, _) = simulate(&b.build(), &e).unwrap();
    let t = r.column("time").unwrap();
    assert_eq!(r.column("p.mu_fl").unwrap(), t); // mu = 1 * t, no delay
    for (a, b) in [("p.psi", "q.psi"), ("p.v_y", "q.v_y")] {
        let (x, y) = (r.column(a).unwrap(), r.column(b).unwrap());
        let d = x.iter().zip(&y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(d < 1e-12, "{a} vs {b}: {d}");
        assert!(x[500].abs() > 1e-4);
    }
}

#[test]
fn an_fmu_with_no_states_runs_without_the_state_functions() {
    // ramp.c refuses fmi2Get/SetContinuousStates, fmi2GetDerivatives and
    // fmi2GetEventIndicators (it has nx = nz = 0): a call of any of them fails the run
    let dir = work_dir("ramp");
    let fmu = Fmu::load(&common::build_ramp(&dir, &common::ramp_xml("local"))).unwrap();
    for solver in [
        Solver::Rk4 { max_step: None },
        Solver::Dopri5 { rtol: 1e-6, atol: 1e-8 },
        Solver::Bdf { rtol: 1e-6, atol: 1e-8 },
    ] {
        let mut b = SystemBuilder::new();
        b.add_instance("ramp", fmu.clone()).unwrap();
        let mut e = Experiment::new(1.0, 0.1);
        e.solver = solver;
        let (r, s) = simulate(&b.build(), &e).unwrap();
        assert_eq!(r.rows(), 11, "{solver:?}");
        // y = 2 t, and 2 t + 1 from the time event at 0.55 s on (the FMU's definition)
        for (t, y) in r.column("time").unwrap().iter().zip(r.column("y").unwrap()) {
            let exact = 2.0 * t + if *t >= 0.55 { 1.0 } else { 0.0 };
            assert!((y - exact).abs() < 1e-14, "{solver:?}: y({t}) = {y} vs {exact}");
        }
        let times: Vec<(f64, &str)> = s.events.iter().map(|e| (e.time, e.kind)).collect();
        assert_eq!(times, [(0.55, "time")], "{solver:?}");
    }
}
