//! What the synthesis test binaries share: the paper's plant.

use nigel_synthesis::{Architecture, PlantSpec, Polytope};

/// The paper's four-wheel-steering plant as the polytope the syntheses take.
pub fn paper_4ws() -> Polytope {
    PlantSpec::paper(Architecture::FourWheelSteering).polytope().unwrap()
}
