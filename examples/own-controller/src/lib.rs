//! One's own steering controller as an FMI 2.0 Co-Simulation FMU (`own_controller`): the
//! smallest credible replacement of `nigel_controller` in the closed loop. Every input and
//! output the closed-loop SSP connects is declared with the same name, causality and unit,
//! so the SSP's connections fit unchanged; the pose inputs are accepted and not read.
//!
//! Sampled every `T = 1 ms` at `t_k = k T` (the layer keeps the clock), outputs held:
//! - steering: `delta_i = delta_ff_i + s_i k_yaw_rate (yaw_rate_ref - yaw_rate)`, with
//!   `s_i = +1` for the front wheels and `-1` for the rear ones (more yaw rate wanted: the
//!   front wheels steer into the turn, the rear ones against it), clamped to `+-delta_max`;
//! - drive: `F = clamp(kp_speed (speed_ref - speed), -force_max, force_max)`, the torque of
//!   each wheel `tau_i = F r_wheel / 4`.

use fmi_export::model_description::DefaultExperiment;
use fmi_export::{DeclarationSpec, Field, InstantiateContext, Interfaces, Model, ModelResult, Variables};
use nigel_vehicle::WHEELS;

/// The sample period of the law \[s\].
pub const SAMPLE_PERIOD: f64 = 1e-3;

/// The scalar inputs `(name, unit, start)`, kept in `OwnController::inputs` in this order.
pub const INPUTS: [(&str, &str, f64); 12] = [
    ("beta", "rad", 0.0),
    ("yaw_rate", "rad/s", 0.0),
    ("speed", "m/s", 0.35),
    ("beta_ref", "rad", 0.0),
    ("yaw_rate_ref", "rad/s", 0.0),
    ("speed_ref", "m/s", 0.35),
    ("x", "m", 0.0),
    ("x_ref", "m", 0.0),
    ("y", "m", 0.0),
    ("y_ref", "m", 0.0),
    ("psi", "rad", 0.0),
    ("psi_ref", "rad", 0.0),
];
const YAW_RATE: usize = 1;
const SPEED: usize = 2;
const YAW_RATE_REF: usize = 4;
const SPEED_REF: usize = 5;

/// The parameters `(name, unit, start, min, max, description)`, kept in
/// `OwnController::parameters` in this order.
pub const PARAMETERS: [(&str, &str, f64, f64, f64, &str); 5] = [
    ("k_yaw_rate", "rad.s/rad", 0.3, 0.0, 10.0, "steering per yaw-rate error (front +, rear -)"),
    ("kp_speed", "N.s/m", 53.6, 0.0, 1e4, "drive force per speed error"),
    ("force_max", "N", 20.0, 1e-3, 1e3, "largest total drive force"),
    ("r_wheel", "m", 0.0325, 1e-3, 1.0, "wheel radius (force to torque)"),
    ("delta_max", "rad", core::f64::consts::FRAC_PI_2, 1e-3, core::f64::consts::FRAC_PI_2, "steering clamp"),
];
const K_YAW_RATE: usize = 0;
const KP_SPEED: usize = 1;
const FORCE_MAX: usize = 2;
const R_WHEEL: usize = 3;
const DELTA_MAX: usize = 4;

fn build_declaration() -> DeclarationSpec<Field<OwnController>> {
    let mut v = Variables::<Field<OwnController>>::new();
    let inputs: Vec<_> = INPUTS
        .iter()
        .enumerate()
        .map(|(i, (name, unit, start))| v.real(name).input(*start).unit(unit).at(i).field(|m, i| &mut m.inputs[i]))
        .collect();
    let delta_ff = v
        .family("delta_ff", &WHEELS, |d, _| d.input(0.0).unit("rad").describe("feed-forward steering"))
        .field(|m, i| &mut m.delta_ff[i]);
    v.family("delta", &WHEELS, |d, i| {
        d.discrete_output([inputs[YAW_RATE], inputs[YAW_RATE_REF], delta_ff[i]])
            .unit("rad")
            .describe("delta_ff + s k_yaw_rate (yaw_rate_ref - yaw_rate), s = +1 front, -1 rear")
    })
    .field(|m, i| &mut m.delta[i]);
    let speed_inputs = [inputs[SPEED], inputs[SPEED_REF]];
    v.family("tau", &WHEELS, |d, _| d.discrete_output(speed_inputs).unit("N.m").describe("drive torque F r_wheel / 4"))
        .field(|m, i| &mut m.tau[i]);
    v.real("drive_force")
        .discrete_output(speed_inputs)
        .unit("N")
        .describe("F = kp_speed (speed_ref - speed), |F| <= force_max")
        .field(|m, _| &mut m.drive_force);
    for (j, (name, unit, start, min, max, text)) in PARAMETERS.iter().enumerate() {
        v.real(name)
            .parameter(*start)
            .unit(unit)
            .min(*min)
            .max(*max)
            .describe(text)
            .at(j)
            .field(|m, j| &mut m.parameters[j]);
    }
    DeclarationSpec {
        model_name: "own_controller",
        model_identifier: "own_controller",
        description: "A user's own sampled (1 ms) steering controller: P on the yaw rate, P on the speed",
        version: env!("CARGO_PKG_VERSION"),
        interfaces: Interfaces { model_exchange: false, co_simulation: true },
        default_experiment: Some(DefaultExperiment::fixed_step(30.0, SAMPLE_PERIOD)),
        variables: v.into_vec(),
        ..Default::default()
    }
}

/// The controller instance: its inputs, parameters and held outputs.
#[derive(Clone, Debug)]
pub struct OwnController {
    inputs: [f64; INPUTS.len()],
    delta_ff: [f64; 4],
    parameters: [f64; PARAMETERS.len()],
    delta: [f64; 4],
    tau: [f64; 4],
    drive_force: f64,
}

impl OwnController {
    /// The law on the current inputs: `(delta, F)`.
    pub fn law(&self) -> ([f64; 4], f64) {
        let p = &self.parameters;
        let yaw_rate_error = self.inputs[YAW_RATE_REF] - self.inputs[YAW_RATE];
        let side = [1.0, 1.0, -1.0, -1.0];
        let delta = core::array::from_fn(|i| {
            (self.delta_ff[i] + side[i] * p[K_YAW_RATE] * yaw_rate_error).clamp(-p[DELTA_MAX], p[DELTA_MAX])
        });
        let force = (p[KP_SPEED] * (self.inputs[SPEED_REF] - self.inputs[SPEED])).clamp(-p[FORCE_MAX], p[FORCE_MAX]);
        (delta, force)
    }
}

impl Model for OwnController {
    type Binding = Field<OwnController>;

    fmi_export::declare_model!(Field<OwnController>, build_declaration());

    fn instantiate(_: &InstantiateContext) -> ModelResult<Self> {
        Ok(OwnController {
            inputs: INPUTS.map(|(_, _, start)| start),
            delta_ff: [0.0; 4],
            parameters: PARAMETERS.map(|(_, _, start, ..)| start),
            delta: [0.0; 4],
            tau: [0.0; 4],
            drive_force: 0.0,
        })
    }

    fn sample_period(&self) -> Option<f64> {
        Some(SAMPLE_PERIOD)
    }

    fn sample(&mut self, _k: u64, _time: f64) -> ModelResult {
        let (delta, force) = self.law();
        self.delta = delta;
        self.drive_force = force;
        self.tau = [force * self.parameters[R_WHEEL] / 4.0; 4];
        Ok(())
    }
}

#[cfg(feature = "fmi-export")]
fmi_export::export_fmi!(OwnController);
