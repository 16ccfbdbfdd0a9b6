//! The bdf solver (`--solver bdf`) on C test FMUs of known solution and against dopri5:
//! a stiff linear system against its closed form (with bdf, and with the default solver,
//! which finds it stiff and switches to bdf), van der Pol at mu = 1e3 with the FMU's
//! directional derivatives (one call per column group) against dopri5 at a tight
//! tolerance, the plant against dopri5, and the bouncing ball's events against dopri5 and
//! the exact bounce times.

mod common;
use common::{assert_counted_at_bounces, build_ball, build_linear, build_vdp, plant_fmu, plant_fmu3, work_dir};
use nigel_cosim::{simulate, Experiment, Fmu, ImportOptions, Interface, Results, Solver, Summary, SystemBuilder};
use std::path::Path;

fn run(fmu: &Path, name: &str, set: &[(&str, &str)], stop: f64, step: f64, solver: Solver) -> (Results, Summary) {
    try_run(fmu, name, set, stop, step, solver).unwrap()
}

fn try_run(
    fmu: &Path,
    name: &str,
    set: &[(&str, &str)],
    stop: f64,
    step: f64,
    solver: Solver,
) -> nigel_cosim::Result<(Results, Summary)> {
    let options = ImportOptions { interface: Some(Interface::ModelExchange), ..ImportOptions::default() };
    let mut b = SystemBuilder::new();
    b.add_instance(name, Fmu::load_with(fmu, &options).unwrap()).unwrap();
    for (k, v) in set {
        b.set_text(&format!("{name}.{k}"), v).unwrap();
    }
    let mut e = Experiment::new(stop, step);
    e.solver = solver;
    simulate(&b.build(), &e)
}

#[test]
fn bdf_on_a_stiff_linear_system_matches_the_closed_form() {
    let dir = work_dir("stiff-linear");
    let fmu = build_linear(&dir);
    let lambda = 1e4;
    for rtol in [1e-5, 1e-7, 1e-9] {
        let (r, s) = run(&fmu, "lin", &[], 2.0, 0.01, Solver::Bdf { rtol, atol: rtol / 100.0 });
        let (t, x1, x2) = (r.column("time").unwrap(), r.column("x1").unwrap(), r.column("x2").unwrap());
        let mut worst = 0.0f64;
        for k in 0..t.len() {
            let e2 = (-t[k]).exp();
            let e1 = (1.0 - 1.0 / (lambda - 1.0)) * (-lambda * t[k]).exp() + e2 / (lambda - 1.0);
            worst = worst.max((x1[k] - e1).abs()).max((x2[k] - e2).abs());
        }
        eprintln!("rtol {rtol:e}: largest error {worst:e}, {:?}, steps {:?}", s.stiff, s.integrator_steps);
        // the local error of each step is below rtol |x| + atol (|x| <= 1); over the run the
        // errors of the decaying solution add to a few rtol: 10 rtol bounds it
        assert!(worst < 10.0 * rtol, "rtol {rtol}: {worst}");
        // stiff: an explicit method needs h < 2.8 / lambda (dopri5's stability bound), 7000
        // steps for 2 s; the bdf steps are set by accuracy
        assert!(s.integrator_steps.0 < 2000, "{:?}", s.integrator_steps);
        // no directional derivatives: finite differences (one rhs per colour, 2 colours)
        assert!(s.stiff.jacobians >= 1 && s.stiff.factorizations >= s.stiff.jacobians, "{:?}", s.stiff);
        assert!(s.stiff.rhs > s.integrator_steps.0, "{:?}", s.stiff);
    }
}

/// The largest error of x1, x2 over the rows against the closed form of `tests/cfmu/linear.c`
/// (x2 = e^-t, x1 = (1 - 1/(lambda - 1)) e^(-lambda t) + e^-t / (lambda - 1)).
fn linear_error(r: &Results, lambda: f64) -> f64 {
    let (t, x1, x2) = (r.column("time").unwrap(), r.column("x1").unwrap(), r.column("x2").unwrap());
    let mut worst = 0.0f64;
    for k in 0..t.len() {
        let e2 = (-t[k]).exp();
        let e1 = (1.0 - 1.0 / (lambda - 1.0)) * (-lambda * t[k]).exp() + e2 / (lambda - 1.0);
        worst = nan_max(nan_max(worst, (x1[k] - e1).abs()), (x2[k] - e2).abs());
    }
    worst
}

fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

#[test]
fn the_default_solver_switches_to_bdf_on_a_stiff_system_and_matches_the_closed_form() {
    let dir = work_dir("stiff-auto");
    let fmu = build_linear(&dir);
    let lambda = 1e4;
    // RK4 alone at the communication step of 0.01 s: h lambda = 100, far outside its
    // stability interval (2.785): the fast mode grows by |R(-100)| = 3.9e6 per step until
    // the states overflow (an error) or, if it ends first, the rows are wrong
    match try_run(&fmu, "lin", &[], 2.0, 0.01, Solver::Rk4 { max_step: None }) {
        Ok((r, _)) => {
            let e = linear_error(&r, lambda);
            assert!(e.is_nan() || e >= 1.0, "rk4 alone cannot be right here: {e:e}");
        }
        // measured: x1 = NaN at t = 0.47 s
        Err(e) => assert!(e.to_string().contains("NaN"), "{e}"),
    }
    // the default: RK4 that tests each step (h rho = 2 |k3 - k2| / |k2 - k1| = h lambda for
    // a linear system) and continues with bdf (rtol 1e-6, atol 1e-8) from the first stiff step
    let (r, s) = run(&fmu, "lin", &[], 2.0, 0.01, Solver::default());
    let worst = linear_error(&r, lambda);
    eprintln!("auto: largest error {worst:e}, notes {:?}, bdf {:?}", s.notes, s.stiff);
    // as bdf_on_a_stiff_linear_system_matches_the_closed_form: each step's local error is
    // below rtol |x| + atol (|x| <= 1), adding up to a few rtol over the decaying solution:
    // 10 rtol
    assert!(worst < 10.0 * 1e-6, "{worst:e}");
    assert_eq!(r.column("time").unwrap().len(), 201);
    // the switch at the first step (t = 0; h rho = 100 up to rounding), named in a note
    let note = s.notes.iter().find(|n| n.contains("stiff at")).expect("a note on the switch");
    assert!(note.starts_with("lin: stiff at t = 0 s: an RK4 step of 1e-2 s has h*rho = 1.000e2"), "{note}");
    assert!(s.stiff.steps > 0 && s.stiff.jacobians >= 1, "{:?}", s.stiff);
    // a step that is not stiff is not switched: RK4 at 1e-4 s (h lambda = 1) gives the rows
    // of rk4 alone to the bit, and no note
    let small = Solver::Auto { max_step: Some(1e-4), rtol: 1e-6, atol: 1e-8 };
    let (a, sa) = run(&fmu, "lin", &[], 0.05, 0.01, small);
    let (b, _) = run(&fmu, "lin", &[], 0.05, 0.01, Solver::Rk4 { max_step: Some(1e-4) });
    for c in ["x1", "x2"] {
        let bits = |r: &Results| r.column(c).unwrap().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b), "{c}");
    }
    assert!(sa.notes.iter().all(|n| !n.contains("stiff at")), "{:?}", sa.notes);
}

/// dopri5 on the stiff linear system (lambda = 1e4) is right but slow, and says why once:
/// Hairer and Wanner's stiffness test (h lambda above 3.25 on 15 tested steps, the tests
/// from the 1000th accepted step on; `integrator/dopri5.rs`) names the instance, the time
/// and the solvers that suit it.
#[test]
fn dopri5_on_a_stiff_system_notes_once_that_it_is_stiff() {
    let dir = work_dir("stiff-dopri5");
    let fmu = build_linear(&dir);
    let (r, s) = run(&fmu, "lin", &[], 10.0, 0.01, Solver::Dopri5 { rtol: 1e-6, atol: 1e-8 });
    let notes: Vec<&String> = s.notes.iter().filter(|n| n.contains("stiff at")).collect();
    assert_eq!(notes.len(), 1, "{:?}", s.notes);
    assert!(notes[0].starts_with("lin: stiff at t = "), "{}", notes[0]);
    assert!(notes[0].contains("--solver auto (the default) or bdf suits a stiff system"), "{}", notes[0]);
    // held by stability: h < 3.7 / lambda (the largest h lambda its steps reach), more than
    // 2.7e4 steps for 10 s, where bdf needs fewer than 2000 for 2 s
    assert!(s.integrator_steps.0 > 27_000, "{:?}", s.integrator_steps);
    // and right: the local errors below rtol |x| + atol, damped by the decay: 10 rtol
    let worst = linear_error(&r, 1e4);
    assert!(worst < 1e-5, "{worst:e}");
}

#[test]
fn bdf_on_van_der_pol_uses_the_fmus_directional_derivatives_and_matches_dopri5() {
    let dir = work_dir("stiff-vdp");
    let fmu = build_vdp(&dir);
    let mu = [("mu", "1000")];
    let record = |solver: Solver| {
        let options = ImportOptions { interface: Some(Interface::ModelExchange), ..ImportOptions::default() };
        let mut b = SystemBuilder::new();
        b.add_instance("vdp", Fmu::load_with(&fmu, &options).unwrap()).unwrap();
        b.set_text("vdp.mu", mu[0].1).unwrap();
        let mut e = Experiment::new(2000.0, 1.0);
        e.solver = solver;
        e.record = Some(vec!["vdp.x0".into(), "vdp.x1".into(), "vdp.directional_calls".into()]);
        simulate(&b.build(), &e).unwrap()
    };
    let (bdf, s) = record(Solver::Bdf { rtol: 1e-8, atol: 1e-10 });
    // the reference: Dormand-Prince at rtol 1e-12, an explicit method unrelated to BDF
    let (reference, sr) = record(Solver::Dopri5 { rtol: 1e-12, atol: 1e-14 });
    eprintln!("bdf {:?} {:?}; dopri5 {:?}", s.integrator_steps, s.stiff, sr.integrator_steps);
    // the Jacobian from the FMU: its two columns share row der(x1), two calls per Jacobian
    let calls = *bdf.column("directional_calls").unwrap().last().unwrap();
    assert_eq!(calls, 2.0 * s.stiff.jacobians as f64, "{:?}", s.stiff);
    assert!(s.stiff.jacobians > 0);
    // stiff: far fewer steps than the explicit method
    assert!(s.integrator_steps.0 * 20 < sr.integrator_steps.0, "{:?} vs {:?}", s.integrator_steps, sr.integrator_steps);
    let (x, y) = (bdf.column("x0").unwrap(), reference.column("x0").unwrap());
    let worst = x.iter().zip(&y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    eprintln!("x0: largest difference {worst:e}");
    // the solution crosses two fast transitions (x0 jumps between about +-1 and -+2 within
    // a few 1/mu s, near 807 s and 1614 s); on the slow branches x0 differs by the
    // tolerance, and a row after a transition carries the transition's timing difference
    // times x0's slope there (measured 7e-5): 1e-3 bounds it
    assert!(worst < 1e-3, "{worst}");
    // the half period (-3 + 2 ln 2) mu + O(mu^-1/3): x0 changes sign near 807 s
    let t = bdf.column("time").unwrap();
    let k = x.iter().position(|v| *v < 0.0).unwrap();
    assert!((t[k] - 0.5 * (3.0 - 2.0 * 2f64.ln()) * 1000.0).abs() < 5.0, "{}", t[k]);
}

#[test]
fn bdf_equals_dopri5_on_the_plant_at_tight_tolerances() {
    let set = [("v_x_start", "0.35"), ("delta_fl", "0.2"), ("delta_fr", "0.2"), ("tau_rl", "0.02"), ("mu_rr", "0.3")];
    let (a, _) = run(&plant_fmu(), "p", &set, 2.0, 1e-3, Solver::Dopri5 { rtol: 1e-10, atol: 1e-12 });
    let (b, s) = run(&plant_fmu(), "p", &set, 2.0, 1e-3, Solver::Bdf { rtol: 1e-10, atol: 1e-12 });
    assert_eq!(a.names, b.names);
    let mut worst = 0.0f64;
    for (x, y) in a.values.iter().zip(&b.values) {
        worst = worst.max((x - y).abs() / x.abs().max(1.0));
    }
    eprintln!("plant bdf vs dopri5: {worst:e}, {:?}", s.stiff);
    // both with local errors below 1e-10 |x| per step: 2000 communication steps of
    // several internal steps each add to at most ~1e-6 without damping
    assert!(worst < 1e-6, "{worst}");
    assert!(b.column("psi").unwrap()[2000].abs() > 1e-2, "the car turned");
}

#[test]
fn bdf_takes_the_jacobian_of_an_fmi3_fmu_from_fmi3_get_directional_derivative() {
    // the same library behind both archives: fmi3GetDirectionalDerivative gives the
    // columns fmi2GetDirectionalDerivative gives, so the two runs take the same steps to
    // the bit; finite differences would show as jacobian_rhs > 0 and other steps
    let set = [("v_x_start", "0.35"), ("delta_fl", "0.2"), ("delta_fr", "0.2"), ("tau_rl", "0.02")];
    let solver = Solver::Bdf { rtol: 1e-6, atol: 1e-8 };
    let (a, sa) = run(&plant_fmu(), "p", &set, 2.0, 1e-2, solver);
    let (b, sb) = run(&plant_fmu3(), "p", &set, 2.0, 1e-2, solver);
    eprintln!("FMI 2.0 {:?}; FMI 3.0 {:?}", sa.stiff, sb.stiff);
    assert!(sa.stiff.jacobians > 0 && sa.stiff.jacobian_rhs == 0, "{:?}", sa.stiff);
    assert_eq!(sb.stiff, sa.stiff);
    assert_eq!(a.names, b.names);
    assert!(a.values == b.values, "the FMI 3.0 run's rows differ from the FMI 2.0 run's");
}

#[test]
fn bdf_finds_the_bouncing_balls_events_where_dopri5_does() {
    let dir = work_dir("stiff-ball");
    let fmu = build_ball(&dir);
    let g: f64 = 9.81;
    let t1 = (2.0 / g).sqrt();
    let state_events = |solver: Solver| -> Vec<f64> {
        let (_, s) = run(&fmu, "ball", &[], 2.5, 0.01, solver);
        s.events.iter().filter(|e| e.kind == "state").map(|e| e.time).collect()
    };
    let rtol = 1e-8;
    let bdf = state_events(Solver::Bdf { rtol, atol: rtol / 100.0 });
    let dp = state_events(Solver::Dopri5 { rtol, atol: rtol / 100.0 });
    eprintln!("bdf {bdf:?}\ndopri5 {dp:?}");
    assert_eq!(bdf.len(), dp.len());
    assert!(bdf.len() >= 8, "{bdf:?}");
    // the k-th bounce at t1 (1 + 2 e (1 - e^(k-1)) / (1 - e)) (flights of 2 v_k / g, v_k = e^k g t1)
    let e: f64 = 0.7;
    for (k, (a, b)) in bdf.iter().zip(&dp).enumerate() {
        let exact = t1 * (1.0 + 2.0 * e * (1.0 - e.powi(k as i32)) / (1.0 - e));
        // an event time is off by the state error over the impact speed (v_k = e^k 4.4 m/s):
        // a global error of 10 rtol over v_8 = 0.25 m/s is 4e-7 s
        assert!((a - exact).abs() < 1e-6, "bounce {k}: bdf {a} vs {exact}");
        assert!((a - b).abs() < 1e-6, "bounce {k}: bdf {a} vs dopri5 {b}");
    }
}

#[test]
fn bdf_integrates_a_coupled_model_exchange_group_with_its_events() {
    // the ball's velocity feeds the discrete counter (tests/cfmu/latch.c, an input: steps
    // end at every communication point); each bounce is an event of both, counted at its time
    let dir = work_dir("stiff-coupled");
    let mut b = SystemBuilder::new();
    b.add_instance("ball", Fmu::load(&build_ball(&dir)).unwrap()).unwrap();
    b.add_instance("counter", Fmu::load(&common::build_latch(&dir)).unwrap()).unwrap();
    b.connect("ball.v", "counter.u").unwrap();
    let mut e = Experiment::new(1.5, 0.01);
    let rtol = 1e-10;
    e.solver = Solver::Bdf { rtol, atol: rtol / 100.0 };
    let (r, s) = simulate(&b.build(), &e).unwrap();
    let g: f64 = 9.81;
    let t1 = (2.0 / g).sqrt();
    let exact = [t1, t1 + 2.0 * 0.7 * t1];
    let state: Vec<f64> = s.events.iter().filter(|e| e.kind == "state").map(|e| e.time).collect();
    assert_eq!(state.len(), 2, "{:?}", s.events);
    for (a, b) in state.iter().zip(exact) {
        // the state error (a few rtol) over the impact speed (>= 3 m/s)
        assert!((a - b).abs() < 1e-8, "{a} vs {b}");
    }
    assert_counted_at_bounces(&r, &state, "bdf");
    assert!(s.stiff.jacobians > 0, "{:?}", s.stiff);
}

#[test]
fn cosim_run_solver_bdf_reports_its_work_in_the_summary() {
    let dir = work_dir("stiff-cli");
    let fmu = build_vdp(&dir);
    let (csv, json) = (dir.join("out.csv"), dir.join("summary.json"));
    let run = |extra: &[&str]| {
        let mut args = vec!["run", fmu.to_str().unwrap(), "--solver", "bdf", "--set", "mu=1000", "--stop-time", "1000"];
        args.extend_from_slice(&[
            "--step",
            "1",
            "--output",
            csv.to_str().unwrap(),
            "--summary",
            json.to_str().unwrap(),
        ]);
        args.extend_from_slice(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_cosim")).args(&args).output().unwrap()
    };
    let out = run(&[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let work = &summary["bdf"];
    let (rhs, jacobians, factorizations) =
        (work["rhs"].as_u64().unwrap(), work["jacobians"].as_u64().unwrap(), work["factorizations"].as_u64().unwrap());
    let steps = summary["integrator_steps"]["accepted"].as_u64().unwrap();
    eprintln!("{work} {steps}");
    // a Newton iteration per step takes at least one right-hand side; a factorization per
    // Jacobian at least
    assert!(steps > 0 && rhs >= steps && factorizations >= jacobians && jacobians >= 1, "{work} {steps}");
    // the row at 1000 s: x0 on its way back after the first transition (near 807 s)
    let last = std::fs::read_to_string(&csv).unwrap().lines().last().unwrap().to_string();
    let x0: f64 = last.split(',').nth(1).unwrap().parse().unwrap();
    assert!(x0 < -1.0 && x0 > -2.1, "{last}");
    // a tolerance no step can meet is refused before the run
    let out = run(&["--rtol", "1e-20"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("the bdf relative tolerance 1e-20 is below"));
}

#[test]
fn bdf_ends_a_step_at_a_time_event_and_restarts_there() {
    // a kick of +2 m/s at t = 0.123 s (not a communication point of the 0.01 s grid)
    let dir = work_dir("stiff-kick");
    let fmu = build_ball(&dir);
    let rtol = 1e-8;
    let (r, s) =
        run(&fmu, "ball", &[("t_kick", "0.123"), ("kick", "2")], 0.3, 0.01, Solver::Bdf { rtol, atol: rtol / 100.0 });
    let time: Vec<f64> = s.events.iter().filter(|e| e.kind == "time").map(|e| e.time).collect();
    assert_eq!(time, [0.123], "{:?}", s.events);
    // v' = -g: every BDF order is exact for a linear v (to rounding); h is the parabola
    // 1 - g t^2 / 2 + 2 (t - 0.123) to the tolerance (order-1 start steps are not exact)
    let (v, h) = (r.column("v").unwrap(), r.column("h").unwrap());
    assert!((v[30] - (-9.81 * 0.3 + 2.0)).abs() < 1e-12, "{}", v[30]);
    assert!((h[30] - (1.0 - 9.81 * 0.09 / 2.0 + 2.0 * (0.3 - 0.123))).abs() < 10.0 * rtol, "{}", h[30]);
}

#[test]
fn the_jacobian_from_directional_derivatives_or_differences_one_call_per_column_group() {
    // van der Pol's columns x0 (row der(x1)) and x1 (rows der(x0), der(x1)) share a row:
    // two groups, so two calls per Jacobian either way
    let run_vdp = |fmu: &Path| {
        let mut b = SystemBuilder::new();
        b.add_instance("vdp", Fmu::load(fmu).unwrap()).unwrap();
        b.set_text("vdp.mu", "1000").unwrap();
        let mut e = Experiment::new(1000.0, 1.0);
        e.solver = Solver::Bdf { rtol: 1e-7, atol: 1e-9 };
        e.record = Some(vec!["vdp.x0".into(), "vdp.directional_calls".into(), "vdp.derivative_calls".into()]);
        simulate(&b.build(), &e).unwrap()
    };
    let last = |r: &Results, name: &str| *r.column(name).unwrap().last().unwrap();
    let (with, s) = run_vdp(&build_vdp(&work_dir("jacobian-directional")));
    let (without, t) = run_vdp(&common::build_vdp_without_directional_derivatives(&work_dir("jacobian-differences")));
    eprintln!("directional {:?}\ndifferences {:?}", s.stiff, t.stiff);
    // the FMU's own counts of its calls equal the summary's
    assert_eq!(last(&with, "directional_calls"), 2.0 * s.stiff.jacobians as f64);
    assert_eq!(last(&with, "derivative_calls"), s.stiff.rhs as f64);
    assert_eq!(s.stiff.jacobian_rhs, 0);
    assert_eq!(last(&without, "directional_calls"), 0.0);
    assert_eq!(last(&without, "derivative_calls"), t.stiff.rhs as f64);
    assert_eq!(t.stiff.jacobian_rhs, 2 * t.stiff.jacobians, "{:?}", t.stiff);
    // the same solution to the tolerance (the difference Jacobian is only an approximation
    // of the iteration matrix, not of the solution): x0 at 1000 s
    let (a, b) = (last(&with, "x0"), last(&without, "x0"));
    assert!((a - b).abs() < 1e-5, "{a} vs {b}");
}

#[test]
fn bdf_runs_the_closed_loop_in_model_exchange_keeping_its_jacobian_across_events() {
    // plant, controller and maneuver in ME: the sampled controller and maneuver make time
    // events every 1 ms; the method restarts at each with the Jacobian it has
    let ssp = plant_fmu().parent().unwrap().parent().unwrap().join("ssp/nigel_closed_loop.ssp");
    let options = ImportOptions { interface: Some(Interface::ModelExchange), ..ImportOptions::default() };
    let system = nigel_cosim::read_ssp(&ssp, &options).unwrap().system;
    let run = |solver: Solver| {
        let mut e = Experiment::new(2.0, 1e-3);
        e.solver = solver;
        e.record = Some(vec!["plant.x".into(), "plant.y".into(), "plant.psi".into(), "plant.v_x".into()]);
        simulate(&system, &e).unwrap()
    };
    let (bdf, s) = run(Solver::Bdf { rtol: 1e-8, atol: 1e-10 });
    let (dp, _) = run(Solver::Dopri5 { rtol: 1e-10, atol: 1e-12 });
    let worst = bdf.values.iter().zip(&dp.values).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    eprintln!("closed loop bdf vs dopri5: {worst:e}; {:?}, {} events", s.stiff, s.events.len());
    // some 18000 steps (2000 restarts at order 1), each with a local error below
    // 1e-8 |x| + 1e-10 (|x| < 3 here): at most ~5e-4 added up, measured 4e-9; 1e-6 is
    // well above what the error control allows in practice
    assert!(worst < 1e-6, "{worst}");
    assert!(s.events.len() >= 2000, "{}", s.events.len());
    assert!(s.stiff.jacobians * 10 < s.events.len() as u64, "{:?}", s.stiff);
}

#[test]
fn isolate_run_summary_reports_the_bdf_work_and_events_of_the_run_in_one_process() {
    let dir = work_dir("stiff-isolate-summary");
    let fmu = build_ball(&dir);
    let summary = |extra: &[&str]| -> serde_json::Value {
        let json = dir.join(format!("summary{}.json", extra.len()));
        let mut args = vec![
            "run",
            fmu.to_str().unwrap(),
            "--solver",
            "bdf",
            "--rtol",
            "1e-8",
            "--stop-time",
            "2",
            "--step",
            "0.01",
        ];
        args.extend_from_slice(&["--summary", json.to_str().unwrap()]);
        args.extend_from_slice(extra);
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cosim")).args(&args).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
    };
    let (alone, isolated) = (summary(&[]), summary(&["--isolate=run"]));
    // the same computation in the host process: the same counts, exactly
    for key in ["bdf", "integrator_steps", "event_times", "events", "steps"] {
        assert_eq!(alone[key], isolated[key], "{key}: {alone} vs {isolated}");
    }
    let work = &isolated["bdf"];
    assert!(work["rhs"].as_u64().unwrap() > 0 && work["jacobians"].as_u64().unwrap() > 0, "{work}");
    assert!(work["factorizations"].as_u64().unwrap() >= work["jacobians"].as_u64().unwrap(), "{work}");
    // the bounces before 2 s: at t1 (1 + 2 e (1 - e^(k-1)) / (1 - e)), k = 1 .. 4 (0.45, 1.08,
    // 1.53, 1.84 s; the fifth at 2.05 s)
    assert_eq!(isolated["events"].as_u64(), Some(4), "{isolated}");
}

#[test]
fn past_the_balls_accumulation_point_bdf_and_dopri5_both_go_on_in_free_fall_from_their_last_bounce() {
    // The bounces accumulate at t_inf = t1 (1 + 2 e / (1 - e)) = 2.5587 s: infinitely many,
    // each flight 2 v_k / g shorter than the last. After a bounce the indicator h is exactly 0
    // (neither side): a flight that lies within one integrator step is not seen, and from the
    // first such flight on the ball falls through the floor. Both solvers: the same event test
    // (a strict sign at a step's start), so each finds the bounces whose flight is longer than
    // its steps and then falls freely from the last one it found, to the stop time.
    let dir = work_dir("stiff-ball-zeno");
    let fmu = build_ball(&dir);
    let (g, e): (f64, f64) = (9.81, 0.7);
    let t1 = (2.0 / g).sqrt();
    let t_inf = t1 * (1.0 + 2.0 * e / (1.0 - e));
    for solver in [Solver::Bdf { rtol: 1e-8, atol: 1e-10 }, Solver::Dopri5 { rtol: 1e-8, atol: 1e-10 }] {
        let (r, s) = run(&fmu, "ball", &[], 3.0, 0.01, solver);
        let bounces: Vec<f64> = s.events.iter().filter(|e| e.kind == "state").map(|e| e.time).collect();
        eprintln!("{solver:?}: {} bounces, the last at {:?}", bounces.len(), bounces.last());
        // the flights at the last located bounces are a few ms: both get within 10 ms of t_inf
        assert!(bounces.len() >= 15 && *bounces.last().unwrap() > t_inf - 0.01, "{bounces:?}");
        let mut tk = t1;
        let mut vk = e * g * t1;
        for (k, t) in bounces.iter().enumerate() {
            // an event time is off by the state error (1e-9 m at these tolerances) over the
            // impact speed, down to 7e-5 m/s at the 31st bounce (bdf finds 31): 1.5e-5 s; 1e-4 s
            // bounds it
            assert!((t - tk).abs() < 1e-4, "bounce {}: {t} vs {tk}", k + 1);
            if k + 1 < bounces.len() {
                tk += 2.0 * vk / g;
                vk *= e;
            }
        }
        // from the last bounce found (closed form: at tk with speed vk) a free fall to 3 s
        let s_end = 3.0 - tk;
        let (h_end, v_end) = (vk * s_end - 0.5 * g * s_end * s_end, vk - g * s_end);
        let (h, v) = (*r.column("h").unwrap().last().unwrap(), *r.column("v").unwrap().last().unwrap());
        // the last bounce's time error (< 1e-4 s) times the speeds (< 4.4 m/s, g): < 1e-3
        assert!((h - h_end).abs() < 1e-3 && (v - v_end).abs() < 1e-3, "{solver:?}: ({h}, {v}) vs ({h_end}, {v_end})");
        assert!(h < -0.9, "fell through the floor: {h}");
    }
}
