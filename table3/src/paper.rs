//! The paper's Table III (epsilon; as printed, reproduced in docs/benchmark.md), for comparison.

use nigel_benchmark::{Controller, Fidelity, Maneuver};

/// `[maneuver][controller]` in the order of [`Maneuver::ALL`] and [`Controller::TABLE`]:
/// `(sim, real)`.
pub const TABLE3: [[(f64, f64); 3]; 6] = [
    [(3.81e-2, 5.03e-2), (9.73e-2, 6.04e-2), (1.83e-2, 1.82e-2)], // straight
    [(7.59e-2, 6.59e-2), (5.78e-2, 3.38e-2), (1.20e-2, 1.18e-2)], // lane-change
    [(1.09e-1, 1.01e-1), (7.91e-2, 8.36e-2), (2.14e-2, 2.06e-2)], // skidpad
    [(5.52e-2, 6.79e-2), (4.23e-2, 7.75e-2), (1.50e-2, 1.82e-2)], // fishhook
    [(1.82e-1, 1.91e-1), (2.87e-1, 2.52e-1), (6.14e-2, 6.15e-2)], // slalom
    [(1.43e-1, 4.15e-1), (6.85e-2, 5.47e-1), (4.67e-2, 1.07e-1)], // figure-8
];

/// The paper's epsilon for a cell (`None` for a controller not in the table).
pub fn epsilon(fidelity: Fidelity, maneuver: Maneuver, controller: Controller) -> Option<f64> {
    let m = Maneuver::ALL.iter().position(|&x| x == maneuver)?;
    let c = Controller::TABLE.iter().position(|&x| x == controller)?;
    let (sim, real) = TABLE3[m][c];
    Some(match fidelity {
        Fidelity::Paper => sim,
        Fidelity::Real => real,
    })
}
