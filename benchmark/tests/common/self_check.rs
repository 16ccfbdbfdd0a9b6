//! The self-check table of Table III (seed 0, epsilon) from an independent implementation of
//! docs/benchmark.md, shared by the benchmark's test (`tests/table3.rs`) and the table3
//! crate's tests (`table3/tests/common/mod.rs`, included with `#[path]`).

use nigel_benchmark::{Fidelity, Maneuver};

/// `(maneuver, [open_loop, robust] in the sim column, [open_loop, robust] in the real one)`.
pub const SELF_CHECK: [(Maneuver, [f64; 2], [f64; 2]); 6] = [
    (Maneuver::Straight, [0.0205799, 0.0238091], [0.0205799, 0.0198954]),
    (Maneuver::LaneChange, [0.0593189, 0.0420524], [0.0298599, 0.0184275]),
    (Maneuver::Skidpad, [0.791631, 0.325539], [0.874354, 0.463698]),
    (Maneuver::Fishhook, [0.292381, 0.114311], [0.290312, 0.135593]),
    (Maneuver::Slalom, [1.12056, 0.509415], [0.970792, 0.500319]),
    (Maneuver::Figure8, [0.617197, 0.262837], [0.650735, 0.42491]),
];

/// The self-check's cells as `(column, maneuver, open_loop, robust)`: the sim column's six,
/// then the real column's.
pub fn self_check_cells() -> impl Iterator<Item = (Fidelity, Maneuver, f64, f64)> {
    [Fidelity::Paper, Fidelity::Real].into_iter().flat_map(|f| {
        SELF_CHECK.iter().map(move |&(m, sim, real)| {
            let [open_loop, robust] = if f == Fidelity::Paper { sim } else { real };
            (f, m, open_loop, robust)
        })
    })
}
