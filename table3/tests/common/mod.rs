//! Shared by the integration tests: the self-check table of the issue (an independent
//! implementation of docs/benchmark.md, seed 0) and cached tables.
#![allow(dead_code)]

use nigel_table3::{Controller, Fidelity, Maneuver, Table};

/// `(maneuver, open_loop, robust)` epsilon, seed 0, sim column.
pub const SELF_CHECK_SIM: [(Maneuver, f64, f64); 6] = [
    (Maneuver::Straight, 0.0205799, 0.0238091),
    (Maneuver::LaneChange, 0.0593189, 0.0420524),
    (Maneuver::Skidpad, 0.791631, 0.325539),
    (Maneuver::Fishhook, 0.292381, 0.114311),
    (Maneuver::Slalom, 1.12056, 0.509415),
    (Maneuver::Figure8, 0.617197, 0.262837),
];

/// The same for the real column.
pub const SELF_CHECK_REAL: [(Maneuver, f64, f64); 6] = [
    (Maneuver::Straight, 0.0205799, 0.0198954),
    (Maneuver::LaneChange, 0.0298599, 0.0184275),
    (Maneuver::Skidpad, 0.874354, 0.463698),
    (Maneuver::Fishhook, 0.290312, 0.135593),
    (Maneuver::Slalom, 0.970792, 0.500319),
    (Maneuver::Figure8, 0.650735, 0.42491),
];

/// Relative tolerance of the robust cells against the self-check. The self-check's robust gain
/// is another solution of the same LMIs than the baked `gains::ROBUST` (the optimum is flat in
/// `K` to about 1e-5; `nigel-benchmark`'s `tests/table3.rs` runs the self-check's own gain
/// against it to 1e-5), and across the two the robust cells move by up to 2.0e-4 (sim straight
/// and lane change, measured): 5e-4 holds that, and a change of the definition moves the cells
/// by percents.
pub const ROBUST_CELL_TOLERANCE: f64 = 5e-4;

/// Asserts the 24 cells of the self-check against `table` (1e-4 relative in sim, 1e-3 in
/// real; the self-check prints six significant digits, so 1e-4 is also about its rounding;
/// the robust cells of the sim column to [`ROBUST_CELL_TOLERANCE`]).
pub fn assert_self_check(table: &Table) {
    let mut worst: [f64; 2] = [0.0; 2];
    for (f, rows, tol) in [(Fidelity::Paper, SELF_CHECK_SIM, 1e-4), (Fidelity::Real, SELF_CHECK_REAL, 1e-3)] {
        for (m, open, robust) in rows {
            for (c, expected, tol) in
                [(Controller::OpenLoop, open, tol), (Controller::Robust, robust, f64::max(tol, ROBUST_CELL_TOLERANCE))]
            {
                let got = table.get(f, m, c).unwrap_or_else(|| panic!("no cell {f:?} {m} {c}")).metric.eps;
                let rel = (got - expected).abs() / expected;
                let i = if f == Fidelity::Paper { 0 } else { 1 };
                worst[i] = worst[i].max(rel);
                assert!(
                    rel < tol,
                    "{} {m} {c}: epsilon {got} vs self-check {expected} (relative {rel:.2e} > {tol:e})",
                    f.column()
                );
            }
        }
    }
    eprintln!("self-check: worst relative difference sim {:.2e}, real {:.2e}", worst[0], worst[1]);
}

/// The tracking controller's claim on one table: `robust_tracking` has the lowest epsilon of the four
/// controllers in all 12 rows, and its steering stays inside `delta_max`, like every run's.
pub fn assert_tracking_lowest(table: &Table) {
    let mut rows = 0;
    for f in Fidelity::ALL {
        for m in Maneuver::ALL {
            let eps = |c| table.get(f, m, c).unwrap_or_else(|| panic!("no cell {f:?} {m} {c}")).metric.eps;
            let tracking = eps(Controller::RobustTracking);
            for c in Controller::TABLE {
                assert!(tracking < eps(c), "{} {m}: robust_tracking {tracking} >= {c} {}", f.column(), eps(c));
            }
            assert_eq!(table.lowest(f, m), Some(Controller::RobustTracking));
            eprintln!(
                "{} {m}: eps(robust_tracking) / eps(robust) = {:.3}",
                f.column(),
                tracking / eps(Controller::Robust)
            );
            rows += 1;
        }
    }
    assert_eq!(rows, 12);
    for c in &table.cells {
        assert!(c.metric.max_delta < core::f64::consts::FRAC_PI_2, "{c:?}");
    }
}
