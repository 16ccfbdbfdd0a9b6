//! The polytopic plant: Eq. 2.2 of the paper at the 16 corners of the friction box.
//!
//! The matrices come from [`nigel_vehicle::linear_model`], the same code and parameter
//! type the plant FMU uses. The model is affine in the four friction coefficients, so the
//! polytope's vertices are the model evaluated at the `2^4` combinations of `mu_min` and
//! `mu_max`.

use std::fmt;

use nalgebra::DMatrix;
use nigel_vehicle::{linear_model, tracking_model, DisturbanceColumn, VehicleParams};
use serde::Serialize;

/// Which wheels steer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Architecture {
    /// All four wheels steer independently: inputs `[delta_FL, delta_FR, delta_RL, delta_RR]`.
    #[serde(rename = "4WD4WS")]
    FourWheelSteering,
    /// Only the front wheels steer: inputs `[delta_FL, delta_FR]` (the rear columns of `B`
    /// are removed).
    #[serde(rename = "Ackermann")]
    Ackermann,
}

impl Architecture {
    /// Indices (0 = FL, 1 = FR, 2 = RL, 3 = RR) of the steered wheels, i.e. the columns of
    /// the full `B` that are kept.
    pub fn steered_wheels(&self) -> &'static [usize] {
        match self {
            Architecture::FourWheelSteering => &[0, 1, 2, 3],
            Architecture::Ackermann => &[0, 1],
        }
    }
    /// Number of control inputs.
    pub fn n_inputs(&self) -> usize {
        self.steered_wheels().len()
    }
    /// Display name (`4WD4WS` or `Ackermann`).
    pub fn name(&self) -> &'static str {
        match self {
            Architecture::FourWheelSteering => "4WD4WS",
            Architecture::Ackermann => "Ackermann",
        }
    }
}

/// Which disturbance column and geometry (see `docs/synthesis.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum DisturbanceVariant {
    /// The paper's synthesis: `d2 = (l_f - l_r)/2` as printed in Eq. 2.2 and the geometry
    /// of the authors' script ([`VehicleParams::paper_synthesis`], `l_r = 0.07924`).
    #[serde(rename = "paper")]
    Paper,
    /// The physical model: `d2 = (l_f - l_r)/(2 I_z)` and Table II
    /// ([`VehicleParams::table2`], `l_r = 0.07929`).
    #[serde(rename = "physical")]
    Physical,
}

impl DisturbanceVariant {
    /// The parameter set that goes with the variant.
    pub fn default_params(&self) -> VehicleParams {
        match self {
            DisturbanceVariant::Paper => VehicleParams::paper_synthesis(),
            DisturbanceVariant::Physical => VehicleParams::table2(),
        }
    }
    fn column(&self) -> DisturbanceColumn {
        match self {
            DisturbanceVariant::Paper => DisturbanceColumn::Paper,
            DisturbanceVariant::Physical => DisturbanceColumn::Physical,
        }
    }
    /// `paper` or `physical`.
    pub fn name(&self) -> &'static str {
        match self {
            DisturbanceVariant::Paper => "paper",
            DisturbanceVariant::Physical => "physical",
        }
    }
}

/// Everything that defines the polytopic design model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantSpec {
    /// Vehicle parameters.
    pub params: VehicleParams,
    /// Steering architecture.
    pub architecture: Architecture,
    /// Disturbance column.
    pub disturbance: DisturbanceVariant,
    /// Design speed `v` (m/s).
    pub speed: f64,
    /// Lower friction bound (every wheel).
    pub mu_min: f64,
    /// Upper friction bound (every wheel).
    pub mu_max: f64,
}

impl PlantSpec {
    /// The paper's design model: `paper` variant, `v = 0.35`, `mu in [0.1, 1.0]`.
    pub fn paper(architecture: Architecture) -> Self {
        Self::with_variant(architecture, DisturbanceVariant::Paper)
    }

    /// The physical design model: Table II, physical `d2`, `v = 0.35`, `mu in [0.1, 1.0]`.
    pub fn physical(architecture: Architecture) -> Self {
        Self::with_variant(architecture, DisturbanceVariant::Physical)
    }

    /// `v = 0.35`, `mu in [0.1, 1.0]` with the variant's own parameters.
    pub fn with_variant(architecture: Architecture, disturbance: DisturbanceVariant) -> Self {
        PlantSpec {
            params: disturbance.default_params(),
            architecture,
            disturbance,
            speed: 0.35,
            mu_min: 0.1,
            mu_max: 1.0,
        }
    }

    /// Refuses NaN, infinite, negative or inconsistent values with the reason.
    pub fn validate(&self) -> Result<(), PlantError> {
        self.params.validate().map_err(|e| PlantError::Params(e.to_string()))?;
        if !(self.speed.is_finite() && self.speed > 0.0) {
            return Err(PlantError::Invalid { name: "speed", value: self.speed, reason: "must be finite and > 0" });
        }
        if !(self.mu_min.is_finite() && self.mu_min > 0.0) {
            return Err(PlantError::Invalid { name: "mu_min", value: self.mu_min, reason: "must be finite and > 0" });
        }
        if !(self.mu_max.is_finite() && self.mu_max >= self.mu_min) {
            return Err(PlantError::Invalid {
                name: "mu_max",
                value: self.mu_max,
                reason: "must be finite and >= mu_min",
            });
        }
        if self.params.c.iter().all(|&c| c == 0.0) {
            return Err(PlantError::Invalid { name: "c", value: 0.0, reason: "all cornering stiffnesses are zero" });
        }
        Ok(())
    }

    /// The polytope (validates first).
    pub fn polytope(&self) -> Result<Polytope, PlantError> {
        self.validate()?;
        let mut vertices = Vec::with_capacity(16);
        for j in 0..16usize {
            let mut mu = [0.0; 4];
            for (i, m) in mu.iter_mut().enumerate() {
                *m = if (j >> (3 - i)) & 1 == 1 { self.mu_max } else { self.mu_min };
            }
            vertices.push(self.vertex_at(mu));
        }
        let lm = linear_model(&self.params, [self.mu_min; 4], self.speed);
        let d = lm.disturbance(self.disturbance.column());
        Ok(Polytope {
            spec: *self,
            vertices,
            bw: DMatrix::from_column_slice(2, 1, d.as_slice()),
            model: DesignModel::SideslipYawRate,
        })
    }

    fn vertex_at(&self, mu: [f64; 4]) -> Vertex {
        let lm = linear_model(&self.params, mu, self.speed);
        let a = DMatrix::from_iterator(2, 2, lm.a.iter().copied());
        let wheels = self.architecture.steered_wheels();
        let mut b = DMatrix::zeros(2, wheels.len());
        for (col, &w) in wheels.iter().enumerate() {
            b[(0, col)] = lm.b[(0, w)];
            b[(1, col)] = lm.b[(1, w)];
        }
        Vertex { mu, a, b }
    }

    fn tracking_vertex_at(&self, mu: [f64; 4]) -> Vertex {
        let tm = tracking_model(&self.params, mu, self.speed, self.disturbance.column());
        let a = DMatrix::from_iterator(4, 4, tm.a.iter().copied());
        let wheels = self.architecture.steered_wheels();
        let b = DMatrix::from_fn(4, wheels.len(), |i, col| tm.b[(i, wheels[col])]);
        Vertex { mu, a, b }
    }
}

/// Performance-output weights of the tracking design: `z = [q_y e_y; q_psi e_psi; r_u u]`.
///
/// Each weight is the reciprocal of the size of its quantity that is "as bad as" the
/// others (Bryson's rule): `lateral = 1 / e_y` [1/m], `heading = 1 / e_psi` [1/rad],
/// `steering = 1 / delta` [1/rad]. `gamma` and `nu` are then in units of these normalised
/// outputs per newton of lateral force.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TrackingWeights {
    /// `q_y` [1/m], weight of the lateral error `e_y`.
    pub lateral: f64,
    /// `q_psi` [1/rad], weight of the heading error `e_psi`.
    pub heading: f64,
    /// `r_u` [1/rad], weight of every steering correction `u_i`.
    pub steering: f64,
}

impl TrackingWeights {
    /// The weights chosen from the study in `synthesis/examples/tracking_study.rs`
    /// (see [`crate::tracking`] for the reasoning): 2 cm of lateral error, 0.1 rad of
    /// heading error and 0.1 rad of steering correction are equally bad.
    pub fn chosen() -> Self {
        Self::from_allowances(0.02, 0.1, 0.1)
    }

    /// The weights `1 / allowance` from the allowed lateral error \[m\], heading error \[rad\]
    /// and steering correction \[rad\].
    pub fn from_allowances(lateral: f64, heading: f64, steering: f64) -> Self {
        TrackingWeights { lateral: 1.0 / lateral, heading: 1.0 / heading, steering: 1.0 / steering }
    }

    /// Refuses NaN, infinite and negative weights, and a zero steering weight (without
    /// it the H2/H-inf problems have no reason to keep the gain finite).
    pub fn validate(&self) -> Result<(), PlantError> {
        for (name, value) in [("lateral weight", self.lateral), ("heading weight", self.heading)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(PlantError::Invalid { name, value, reason: "must be finite and >= 0" });
            }
        }
        if !(self.steering.is_finite() && self.steering > 0.0) {
            return Err(PlantError::Invalid {
                name: "steering weight",
                value: self.steering,
                reason: "must be finite and > 0",
            });
        }
        Ok(())
    }
}

/// Which linear model a [`Polytope`] holds: its states and its performance outputs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DesignModel {
    /// Eq. 2.2 of the paper: `x = [beta, r]`, `z = [x; u]` (the paper's design).
    SideslipYawRate,
    /// The tracking error model ([`nigel_vehicle::tracking`]):
    /// `x = [e_y, e_psi, beta - beta_ref, r - r_ref]`, `z = [q_y e_y; q_psi e_psi; r_u u]`.
    Tracking {
        /// The output weights.
        weights: TrackingWeights,
    },
}

impl DesignModel {
    /// Number of states.
    pub fn n_states(&self) -> usize {
        match self {
            DesignModel::SideslipYawRate => 2,
            DesignModel::Tracking { .. } => nigel_vehicle::N_TRACKING_STATES,
        }
    }
    /// Names of the states (the columns of `K`).
    pub fn state_names(&self) -> &'static [&'static str] {
        match self {
            DesignModel::SideslipYawRate => &["beta", "r"],
            DesignModel::Tracking { .. } => &nigel_vehicle::TRACKING_STATE_NAMES,
        }
    }
    /// Refuses invalid weights.
    pub fn validate(&self) -> Result<(), PlantError> {
        match self {
            DesignModel::SideslipYawRate => Ok(()),
            DesignModel::Tracking { weights } => weights.validate(),
        }
    }
}

/// The tracking design model: the plant's friction polytope, speed and disturbance column,
/// with the tracking error states and the output weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackingSpec {
    /// Vehicle, architecture, disturbance column, speed and friction box.
    pub plant: PlantSpec,
    /// Performance-output weights.
    pub weights: TrackingWeights,
}

impl TrackingSpec {
    /// The tracking design: Table II with the physical disturbance column
    /// (`d2 = x_c / I_z`), four-wheel steering, `v = 0.35 m/s`, `mu in [0.1, 1.0]`, and the
    /// [`TrackingWeights::chosen`] weights.
    pub fn default_design() -> Self {
        TrackingSpec { plant: PlantSpec::physical(Architecture::FourWheelSteering), weights: TrackingWeights::chosen() }
    }

    /// Refuses invalid plants and weights.
    pub fn validate(&self) -> Result<(), PlantError> {
        self.plant.validate()?;
        self.weights.validate()
    }

    /// The 16-vertex polytope of the tracking model (validates first). Vertex order as
    /// [`PlantSpec::polytope`].
    pub fn polytope(&self) -> Result<Polytope, PlantError> {
        self.validate()?;
        let corners = self.plant.polytope()?;
        let vertices = corners.vertices.iter().map(|v| self.plant.tracking_vertex_at(v.mu)).collect();
        let tm = tracking_model(
            &self.plant.params,
            [self.plant.mu_min; 4],
            self.plant.speed,
            self.plant.disturbance.column(),
        );
        Ok(Polytope {
            spec: self.plant,
            vertices,
            bw: DMatrix::from_column_slice(4, 1, tm.d.as_slice()),
            model: DesignModel::Tracking { weights: self.weights },
        })
    }
}

/// A refused plant specification.
#[derive(Clone, Debug, PartialEq)]
pub enum PlantError {
    /// The vehicle parameters were refused by [`VehicleParams::validate`].
    Params(String),
    /// A design-model value is out of range.
    Invalid {
        /// Which value.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
}

impl fmt::Display for PlantError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlantError::Params(s) => write!(f, "vehicle {s}"),
            PlantError::Invalid { name, value, reason } => write!(f, "{name} = {value} is invalid: {reason}"),
        }
    }
}

impl std::error::Error for PlantError {}

/// One linear plant `x' = A x + B u + B_w w` (a vertex or any point of the polytope).
#[derive(Clone, Debug, PartialEq)]
pub struct Vertex {
    /// Friction coefficients FL, FR, RL, RR.
    pub mu: [f64; 4],
    /// `A(mu)`, n_states x n_states.
    pub a: DMatrix<f64>,
    /// `B(mu)`, n_states x n_inputs (steered wheels only).
    pub b: DMatrix<f64>,
}

/// The polytopic design model.
#[derive(Clone, Debug, PartialEq)]
pub struct Polytope {
    /// What it was built from.
    pub spec: PlantSpec,
    /// The 16 vertices; vertex `j` has `mu_i = mu_max` where bit `3 - i` of `j` is set
    /// (FL is the most significant bit), so vertex 0 is all `mu_min` and 15 all `mu_max`.
    pub vertices: Vec<Vertex>,
    /// Disturbance input `B_w`, n_states x 1 (independent of mu).
    pub bw: DMatrix<f64>,
    /// Which model (states and performance outputs).
    pub model: DesignModel,
}

impl Polytope {
    /// Number of states (2 for the paper's model, 4 for tracking).
    pub fn n_states(&self) -> usize {
        self.model.n_states()
    }
    /// Number of control inputs (4 or 2).
    pub fn n_inputs(&self) -> usize {
        self.spec.architecture.n_inputs()
    }
    /// Number of performance outputs: `z = [x; u]` (paper) or `[q_y e_y; q_psi e_psi; r_u u]`
    /// (tracking).
    pub fn n_outputs(&self) -> usize {
        match self.model {
            DesignModel::SideslipYawRate => self.n_states() + self.n_inputs(),
            DesignModel::Tracking { .. } => 2 + self.n_inputs(),
        }
    }
    /// `C`, the state part of `z`: `[I_2; 0]` (paper) or `[diag(q_y, q_psi) 0; 0]` (tracking).
    pub fn c(&self) -> DMatrix<f64> {
        let (n, nz) = (self.n_states(), self.n_outputs());
        match self.model {
            DesignModel::SideslipYawRate => DMatrix::from_fn(nz, n, |i, j| if i == j { 1.0 } else { 0.0 }),
            DesignModel::Tracking { weights } => {
                let mut c = DMatrix::zeros(nz, n);
                c[(0, 0)] = weights.lateral;
                c[(1, 1)] = weights.heading;
                c
            }
        }
    }
    /// `D_u`, the input part of `z`: `[0; I_m]` (paper) or `[0; r_u I_m]` (tracking).
    pub fn d_u(&self) -> DMatrix<f64> {
        let (m, nz) = (self.n_inputs(), self.n_outputs());
        let (first, weight) = match self.model {
            DesignModel::SideslipYawRate => (self.n_states(), 1.0),
            DesignModel::Tracking { weights } => (2, weights.steering),
        };
        DMatrix::from_fn(nz, m, |i, j| if i == first + j { weight } else { 0.0 })
    }
    /// Names of the states (the columns of `K`).
    pub fn state_names(&self) -> &'static [&'static str] {
        self.model.state_names()
    }
    /// The plant at any friction vector (for interior points and the nominal model).
    pub fn at(&self, mu: [f64; 4]) -> Vertex {
        match self.model {
            DesignModel::SideslipYawRate => self.spec.vertex_at(mu),
            DesignModel::Tracking { .. } => self.spec.tracking_vertex_at(mu),
        }
    }
    /// Refuses an invalid plant or model.
    pub fn validate(&self) -> Result<(), PlantError> {
        self.spec.validate()?;
        self.model.validate()
    }
}
