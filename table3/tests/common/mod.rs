//! Shared by the integration tests: the self-check table of the issue (an independent
//! implementation of docs/benchmark.md, seed 0) and cached tables.
#![allow(dead_code)]

use nigel_table3::{Controller, Fidelity, Maneuver, Table};

#[path = "../../../benchmark/tests/common/self_check.rs"]
mod self_check;
use self_check::self_check_cells;

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
    for (f, m, open, robust) in self_check_cells() {
        let tol = if f == Fidelity::Paper { 1e-4 } else { 1e-3 };
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

/// The two tests of the self-check on the table `$table()` (a cached `&'static Table`), named
/// `$self_check` (the 24 cells, [`assert_self_check`]) and `$tracking_lowest` (robust
/// tracking lowest in all 12 rows, [`assert_tracking_lowest`]).
macro_rules! self_check_tests {
    ($table:ident, $self_check:ident, $tracking_lowest:ident) => {
        #[test]
        fn $self_check() {
            common::assert_self_check($table());
        }

        #[test]
        fn $tracking_lowest() {
            common::assert_tracking_lowest($table());
        }
    };
}
pub(crate) use self_check_tests;
