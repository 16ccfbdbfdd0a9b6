//! Discrete inputs that connections feed into Model Exchange instances change in Event Mode
//! only (FMI 3.0 section 3.2.1, FMI 2.0 section 3.2.3): the importing layer holds back a
//! set of a discrete input in Continuous-Time Mode (dropped when the FMU holds the value,
//! else waiting), and the master sets the waiting ones in an input event at the start of
//! the instance's next step (issue 35 item 3, for connections as for input files).

mod common;
use common::{build_counter, work_dir};
use nigel_cosim::{simulate, Algorithm, Experiment, Fmu, ImportOptions, Interface, SystemBuilder, Value};

const XML: &str = include_str!("cfmu/fmi3_counter.xml");

/// A Co-Simulation counter `p` (its Int32 output n counts its steps) feeds the discrete
/// Int32 input k of a Model Exchange counter `c`, and p's Boolean nb (= !b, b false: a
/// constant true) c's Boolean input b. The counter refuses `fmi3SetInt32` / `fmi3SetBoolean`
/// of k and b in Continuous-Time Mode (as the Reference FMUs do).
///
/// By hand, both algorithms, steps of 0.1 s: after step j, p.n = j; the master sets c.k = j
/// at the start of c's step j + 1 (jacobi: its inputs are the outputs of the step before;
/// ordered: set after step j, waiting in Continuous-Time Mode), in an input event at
/// t = 0.1 j. The row at t = 0.1 j is recorded before that event: c.m = 2 k = 2 (j - 1) for
/// j >= 1 (0 at t = 0); c.b is true from initialization on, never set again, c.nb = 0.
/// Input events at 0.1 .. 0.9 s (9: the value set after the last step waits for no step).
#[test]
fn connected_discrete_inputs_of_model_exchange_change_in_input_events() {
    let dir = work_dir("me-discrete-connected");
    let Some(path) = build_counter(&dir, "fmi3_counter", XML) else { return };
    let me = ImportOptions { interface: Some(Interface::ModelExchange), ..ImportOptions::default() };
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        let mut b = SystemBuilder::new();
        b.add_instance("p", Fmu::load(&path).unwrap()).unwrap();
        b.add_instance("c", Fmu::load_with(&path, &me).unwrap()).unwrap();
        b.set("p.b", Value::Boolean(false)).unwrap();
        b.connect("p.n", "c.k").unwrap();
        b.connect("p.nb", "c.b").unwrap();
        let mut e = Experiment::new(1.0, 0.1);
        e.algorithm = algorithm;
        e.record = Some(vec!["p.n".into(), "c.k".into(), "c.m".into(), "c.nb".into()]);
        let (r, summary) = simulate(&b.build(), &e).unwrap_or_else(|err| panic!("{algorithm:?}: {err}"));
        assert_eq!(r.rows(), 11);
        let (n, m, nb) = (r.column("p.n").unwrap(), r.column("c.m").unwrap(), r.column("c.nb").unwrap());
        for j in 0..11 {
            assert_eq!(n[j], j as f64, "{algorithm:?}: p.n at row {j}");
            assert_eq!(m[j], 2.0 * j.saturating_sub(1) as f64, "{algorithm:?}: c.m at row {j}");
            assert_eq!(nb[j], 0.0, "{algorithm:?}: c.nb at row {j}");
        }
        let inputs: Vec<f64> =
            summary.events.iter().filter(|e| e.kind == "input" && e.instance == "c").map(|e| e.time).collect();
        let expected: Vec<f64> = (1..10).map(|j| r.column("time").unwrap()[j]).collect();
        assert_eq!(inputs, expected, "{algorithm:?}: one input event per change of p.n");
    }
}
