//! Robust state-feedback synthesis for the Nigel vehicle (paper Section IV).
//!
//! Mixed H2/H-inf state feedback with D-stability over the 16-vertex friction polytope,
//! solved as semidefinite programs with clarabel, and verified without trusting the
//! solver. See `docs/synthesis.md` for the contract.
//!
//! * [`plant`]: the polytopic design model, built from [`nigel_vehicle::VehicleParams`].
//! * [`region`]: pole regions (half-plane, sector, disk, intersections) as data.
//! * [`lmi`]: a small typed LMI layer over clarabel's PSD cones.
//! * [`design`]: the problems (min H-inf, min H2 under an H-inf bound, weighted, the
//!   authors' Pareto sweep, the pole-placement baseline).
//! * [`verify`]: closed-loop poles, H-inf and H2 norms computed from `K` alone, two ways each.
//! * [`report`]: the serialisable summary the `synthesize` CLI prints and writes.
//! * [`plot`]: the SVG figure (Pareto curve and pole map).
//! * [`tracking`]: the robust path-tracking design on the 4-state tracking error
//!   model of [`nigel_vehicle::tracking`], and its linear closed-loop study.
//!
//! Conventions: `gamma` is always the bound on the induced L2 gain (not its square);
//! `nu` bounds the H2 norm; strict LMIs carry the margin [`design::DEFAULT_MARGIN`].

#![warn(missing_docs)]

// Links the system OpenBLAS that clarabel's PSD cones call through BLAS/LAPACK.
extern crate openblas_src;

pub mod design;
pub mod lmi;
pub mod plant;
pub mod plot;
pub mod region;
pub mod report;
pub mod tracking;
pub mod verify;

pub use design::{
    min_h2, min_hinf, mirror_pairs, pareto_sweep, pole_placement_baseline, weighted, Baseline, Design, ParetoPoint,
    ParetoSweep, SweepOptions, SweepProgress, SynthesisError, SynthesisOptions, DEFAULT_MARGIN,
};
pub use lmi::{SolveError, SolverSettings, SolverStats};
pub use plant::{
    Architecture, DesignModel, DisturbanceVariant, PlantError, PlantSpec, Polytope, TrackingSpec, TrackingWeights,
    Vertex,
};
pub use region::{PoleRegion, Region, RegionError};
pub use verify::{verify_design, ClosedLoop, VerificationReport, VerifyOptions};
