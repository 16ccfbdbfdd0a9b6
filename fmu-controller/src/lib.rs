//! The controller FMU (`nigel_controller`): the sampled law of docs/benchmark.md,
//! [`nigel_benchmark::SampledController`], behind the shared FMI 2.0 layer. This file is
//! only the binding: the declaration of the variables and a small [`Model`] impl.
//!
//! Beyond the paper, `controller = robust_tracking` (the last item, 5) feeds back
//! the pose too: the inputs `x, y, psi` (the measured pose, e.g. the plant's outputs) and
//! `x_ref, y_ref, psi_ref` (the test bench's reference pose) give the tracking errors of
//! `nigel_vehicle::tracking` (heading difference wrapped to `(-pi, pi]`, so unwrapped
//! headings are fine), the steering is `delta = delta_ff + K_track [e_y, e_psi, beta -
//! beta_ref, yaw_rate - yaw_rate_ref]` and the along-track error corrects the speed command
//! (`k_along_track`, `along_track_speed_max`; see `nigel_benchmark::control`). The other
//! modes never read the pose inputs.
//!
//! Sampled data: the layer keeps the sample clock ([`fmi_export::sampled`]) and at every
//! sample instant `t_k = t_start + k sample_period` calls [`Model::sample`] (a time event in
//! Model Exchange; inside `fmi2DoStep`, or lazily at the first read or step after the
//! importer set the inputs of that instant, in Co-Simulation). There the speed integrator first takes the step of the previous sample
//! (`I_k = I_(k-1) + e_(k-1) T` unless that sample saturated: it advances when time moves
//! past `t_(k-1)`), then the law runs on the inputs of `t_k` with `I_k`, and its outputs
//! are latched and held until `t_(k+1)`. So `speed_integral` read at `t_k` is the `I_k`
//! of the outputs read there. The outputs depend
//! directly on the inputs (declared in the ModelStructure), so a master that sets the
//! inputs at `t_k` and reads the outputs before `fmi2DoStep` sees the law applied to them.

// `!(x > 0.0)` is deliberate: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use core::f64::consts::FRAC_PI_2;
use fmi_export::model_description::DefaultExperiment;
use fmi_export::{
    Capabilities, DeclarationSpec, Dependencies, Field, InstantiateContext, Interfaces, Model, ModelResult, VarDecl,
    Variables,
};
use nigel_benchmark::control::{ALONG_TRACK_SPEED_MAX, FORCE_MAX, KI_SPEED, KP_SPEED, K_ALONG_TRACK};
use nigel_benchmark::gains::{POLE_PLACEMENT, ROBUST, ROBUST_TRACKING};
use nigel_benchmark::{ControllerInputs, ControllerOutputs, ControllerSettings, SampledController, WHEELS};

/// The model identifier (file name of the shared library and of the `.fmu`).
pub const MODEL_IDENTIFIER: &str = "nigel_controller";

/// Smallest sample period accepted [s] (a longer `fmi2DoStep` than the layer's
/// `MAX_SAMPLES_PER_STEP` samples is refused before it starts).
pub const MIN_SAMPLE_PERIOD: f64 = 1e-6;

/// Largest sample period accepted [s]: the law's gains are for a sampled loop much faster
/// than the car's yaw dynamics (time constants of 0.1 s and more).
pub const MAX_SAMPLE_PERIOD: f64 = 0.1;

/// The values of the Integer parameter `controller` (1-based; the list is in the
/// variable's description and the FMU documentation). A plain Integer, not an FMI
/// Enumeration, so that every importer (libcosim and ecos ignore Enumerations) can set it.
pub mod mode {
    /// `K = 0`: the steering is the feed-forward alone.
    pub const OPEN_LOOP: i32 = 1;
    /// The non-robust pole-placement baseline.
    pub const POLE_PLACEMENT: i32 = 2;
    /// The robust mixed H2/H-inf gain (default).
    pub const ROBUST: i32 = 3;
    /// The tunable gains `k_beta_* / k_yaw_rate_*`.
    pub const CUSTOM: i32 = 4;
    /// Beyond the paper: the robust tracking gain `K_track` on the pose and state errors,
    /// with the along-track speed correction.
    pub const ROBUST_TRACKING: i32 = 5;
}

/// The description of `controller`: its values and what each selects.
pub const CONTROLLER_ITEMS: &str =
    "which steering feedback: 1 open_loop (K = 0, the feed-forward alone), 2 pole_placement \
     (non-robust baseline, Re(s) < -2 at mu = 0.4), 3 robust (mixed H2/H-inf gain, the default), 4 custom (the \
     tunable gains k_beta_* / k_yaw_rate_*), 5 robust_tracking (beyond the paper: the robust tracking gain K_track \
     on the pose errors and the along-track speed correction; reads the pose inputs)";

/// Largest magnitude of a custom gain (rad of steering per rad of slip or per rad/s of
/// yaw rate): the baked gains are below 1; 100 saturates the steering at 1 mrad of error.
pub const CUSTOM_GAIN_MAX: f64 = 100.0;

/// A pose input (world frame), read by `robust_tracking` only.
fn pose<B>(d: VarDecl<B>, unit: &'static str, measured: bool) -> VarDecl<B> {
    d.input(0.0).unit(unit).describe(if measured {
        "measured pose (world frame; heading may be unwrapped), read by robust_tracking only"
    } else {
        "reference pose (the test bench's x_ref, y_ref, psi_ref), read by robust_tracking only"
    })
}

/// A parameter: name, start, min, max (ranges the law can use: the model checks nothing of
/// its own), unit, description, field.
type Parameter = (&'static str, f64, f64, f64, &'static str, &'static str, fn(&mut Controller, usize) -> &mut f64);

/// A Real input: name, start, unit, description, field.
type Signal = (&'static str, f64, &'static str, &'static str, fn(&mut Controller, usize) -> &mut f64);

fn build_declaration() -> DeclarationSpec<Field<Controller>> {
    let mut v = Variables::<Field<Controller>>::new();
    // the measured and reference signals, in value-reference order
    let signals: [Signal; 6] = [
        ("beta", 0.0, "rad", "measured body slip angle atan2(v_y, v_x)", |m, _| &mut m.inputs.beta),
        ("yaw_rate", 0.0, "rad/s", "measured yaw rate", |m, _| &mut m.inputs.yaw_rate),
        ("speed", 0.35, "m/s", "measured speed hypot(v_x, v_y)", |m, _| &mut m.inputs.speed),
        ("beta_ref", 0.0, "rad", "reference body slip angle", |m, _| &mut m.inputs.beta_ref),
        ("yaw_rate_ref", 0.0, "rad/s", "reference yaw rate", |m, _| &mut m.inputs.yaw_rate_ref),
        ("speed_ref", 0.35, "m/s", "speed the PI holds", |m, _| &mut m.inputs.speed_ref),
    ];
    let [beta, yaw_rate, speed, beta_ref, yaw_rate_ref, speed_ref] = signals
        .map(|(name, start, unit, text, field)| v.real(name).input(start).unit(unit).describe(text).field(field));
    let delta_ff = v
        .family("delta_ff", &WHEELS, |d, _| {
            d.input(0.0).unit("rad").describe("feed-forward steering (the maneuver's program)")
        })
        .field(|m, i| &mut m.inputs.delta_ff[i]);
    let x = pose(v.real("x"), "m", true).field(|m, _| &mut m.inputs.x);
    let x_ref = pose(v.real("x_ref"), "m", false).field(|m, _| &mut m.inputs.x_ref);
    let y = pose(v.real("y"), "m", true).field(|m, _| &mut m.inputs.y);
    let y_ref = pose(v.real("y_ref"), "m", false).field(|m, _| &mut m.inputs.y_ref);
    let psi = pose(v.real("psi"), "rad", true).field(|m, _| &mut m.inputs.psi);
    let psi_ref = pose(v.real("psi_ref"), "rad", false).field(|m, _| &mut m.inputs.psi_ref);
    let poses = [x, x_ref, y, y_ref, psi, psi_ref];
    let steering = v
        .family("delta", &WHEELS, |d, i| {
            let mut on = vec![beta, yaw_rate, beta_ref, yaw_rate_ref, delta_ff[i]];
            on.extend(poses);
            d.discrete_output(on).unit("rad").describe(
                "steering command delta_ff + K (q - q_ref), q = [beta, yaw_rate] (robust_tracking: \
             delta_ff + K_track e), clamped to +-delta_max; held over a sample",
            )
        })
        .field(|m, i| &mut m.held.delta[i]);
    let mut speed_outputs = v
        .family("tau", &WHEELS, |d, _| {
            d.discrete_output(Dependencies::All).unit("N.m").describe("drive torque F r_wheel / 4; held over a sample")
        })
        .field(|m, i| &mut m.held.tau[i]);
    speed_outputs.push(
        v.real("drive_force")
            .discrete_output(Dependencies::All)
            .unit("N")
            .describe("total drive force F = kp e + ki I, |F| <= force_max")
            .field(|m, _| &mut m.held.force),
    );
    let speed_integral = v
        .real("speed_integral")
        .discrete_state(0.0)
        .unit("m")
        .describe("speed-error integrator I (frozen while F saturates)")
        .field(|m, _| &mut m.integral);
    // the along-track error reads x, y and the reference pose (not psi); the PI its integrator
    // (a known in Initialization Mode only: the layer keeps it out of the Outputs list)
    for &output in &speed_outputs {
        v.set_dependencies(output, [speed, speed_ref, x, y, x_ref, y_ref, psi_ref, speed_integral]);
    }
    let held_outputs: Vec<_> = steering.into_iter().chain(speed_outputs).collect();
    let parameters: [Parameter; 8] = [
        ("sample_period", 1e-3, MIN_SAMPLE_PERIOD, MAX_SAMPLE_PERIOD, "s", "sample period of the law", |m, _| {
            &mut m.settings.sample_period
        }),
        ("kp_speed", KP_SPEED, 0.0, 1e4, "N.s/m", "speed PI proportional gain", |m, _| &mut m.settings.kp_speed),
        ("ki_speed", KI_SPEED, 0.0, 1e5, "N/m", "speed PI integral gain", |m, _| &mut m.settings.ki_speed),
        ("force_max", FORCE_MAX, 1e-3, 1e3, "N", "largest total drive force", |m, _| &mut m.settings.force_max),
        ("r_wheel", 0.0325, 1e-3, 1.0, "m", "wheel radius (force to torque)", |m, _| &mut m.settings.r_wheel),
        ("delta_max", FRAC_PI_2, 1e-3, FRAC_PI_2, "rad", "steering clamp (the plant's limit)", |m, _| {
            &mut m.settings.delta_max
        }),
        (
            "k_along_track",
            K_ALONG_TRACK,
            0.0,
            100.0,
            "1/s",
            "robust_tracking: speed command correction per metre of along-track error",
            |m, _| &mut m.settings.k_along_track,
        ),
        (
            "along_track_speed_max",
            ALONG_TRACK_SPEED_MAX,
            0.0,
            10.0,
            "m/s",
            "robust_tracking: largest along-track speed correction",
            |m, _| &mut m.settings.along_track_speed_max,
        ),
    ];
    for (name, start, min, max, unit, text, field) in parameters {
        v.real(name).parameter(start).unit(unit).describe(text).min(min).max(max).field(field);
    }
    // the gains: a row per wheel, a column per state (beta, yaw_rate) or pose error (e_y, e_psi)
    const GAIN_UNITS: [&str; 2] = ["rad/rad", "rad.s/rad"];
    const POSE_GAIN_UNITS: [&str; 2] = ["rad/m", "rad/rad"];
    v.family_columns(&["k_beta", "k_yaw_rate"], &WHEELS, |d, i, j| {
        d.tunable_parameter(ROBUST[i][j])
            .min(-CUSTOM_GAIN_MAX)
            .max(CUSTOM_GAIN_MAX)
            .unit(GAIN_UNITS[j])
            .describe("custom gain (used when controller = custom; tunable between steps)")
    })
    .field(|m, k| &mut m.custom.as_flattened_mut()[k]);
    v.family_columns(&["gain_beta", "gain_yaw_rate"], &WHEELS, |d, _, j| {
        d.calculated_parameter().unit(GAIN_UNITS[j]).describe("the gain in use (from controller and the custom gains)")
    })
    .computed(|m, k| m.gain_in_use().as_flattened()[k]);
    v.family_columns(&["gain_e_y", "gain_e_psi"], &WHEELS, |d, _, j| {
        d.calculated_parameter()
            .unit(POSE_GAIN_UNITS[j])
            .describe("the pose gain in use (K_track's e_y, e_psi columns with robust_tracking, else 0)")
    })
    .computed(|m, k| m.pose_gain_in_use().as_flattened()[k]);
    v.integer("controller")
        .parameter(mode::ROBUST)
        .min(f64::from(mode::OPEN_LOOP))
        .max(f64::from(mode::ROBUST_TRACKING))
        .describe(CONTROLLER_ITEMS)
        .field(|m, _| &mut m.mode);
    DeclarationSpec {
        model_name: "nigel_controller",
        model_identifier: MODEL_IDENTIFIER,
        description: "Nigel's sampled controller: delta = delta_ff + K ([beta, yaw_rate] - ref) clamped to \
                      +-delta_max, and the speed-hold PI with anti-windup (docs/benchmark.md); robust gain baked \
                      from the synthesis; robust_tracking adds pose feedback and the along-track correction",
        version: env!("CARGO_PKG_VERSION"),
        interfaces: Interfaces { model_exchange: true, co_simulation: true },
        capabilities: Capabilities { fmu_state: true, serialize_fmu_state: true, directional_derivatives: false },
        default_experiment: Some(DefaultExperiment::fixed_step(30.0, 1e-3)),
        variables: v.into_vec(),
        clocks: sample_clock(held_outputs),
        ..Default::default()
    }
}

/// The FMI 3.0 description declares the sample
/// period as the periodic input clock `sample_clock` (interval fixed: the parameter
/// `sample_period`, read with `fmi3GetIntervalDecimal` in Initialization Mode; shift 0)
/// governing the held outputs, which then change only at its activations, and priority 0
/// for Scheduled Execution. The FMI 2.0 description is the same either way (no clocks in
/// FMI 2.0: that archive samples by time).
fn sample_clock(held_outputs: Vec<fmi_export::VarHandle>) -> Vec<fmi_export::ClockDecl> {
    vec![fmi_export::ClockDecl {
        name: "sample_clock",
        description: "the sample instants t_k = t_start + k sample_period: activate it at each to run the law",
        interval: fmi_export::ClockInterval::Fixed,
        governs: held_outputs,
        priority: 0,
    }]
}

/// The controller instance.
#[derive(Clone, Debug)]
pub struct Controller {
    inputs: ControllerInputs,
    settings: ControllerSettings,
    custom: [[f64; 2]; 4],
    mode: i32,
    integral: f64,
    /// The outputs of the last sample, held until the next one.
    held: ControllerOutputs,
    /// `e T` of the last sample (0 if it saturated): what the integrator adds when the
    /// next sample comes.
    pending_increment: f64,
    /// The law of `settings`, `custom` and `mode` once validated (its integrator is not
    /// used): a sample does not validate the settings again. Emptied by every setter of a
    /// parameter and of the `controller` switch.
    validated: Option<SampledController>,
}

impl Controller {
    /// The gain on `[beta - beta_ref, yaw_rate - yaw_rate_ref]` the `controller` parameter
    /// selects (for `robust_tracking` the last two columns of `K_track`).
    pub fn gain_in_use(&self) -> [[f64; 2]; 4] {
        match self.mode {
            mode::OPEN_LOOP => [[0.0; 2]; 4],
            mode::POLE_PLACEMENT => POLE_PLACEMENT,
            mode::CUSTOM => self.custom,
            mode::ROBUST_TRACKING => ROBUST_TRACKING.map(|row| [row[2], row[3]]),
            _ => ROBUST,
        }
    }

    /// The gain on `[e_y, e_psi]` the `controller` parameter selects (zero but for
    /// `robust_tracking`: the first two columns of `K_track`).
    pub fn pose_gain_in_use(&self) -> [[f64; 2]; 4] {
        match self.mode {
            mode::ROBUST_TRACKING => ROBUST_TRACKING.map(|row| [row[0], row[1]]),
            _ => [[0.0; 2]; 4],
        }
    }

    /// The law with the settings in use (the gains the `controller` switch selects; the
    /// along-track loop belongs to the tracking controller), validated once after they change.
    fn law(&mut self) -> Result<SampledController, String> {
        if self.validated.is_none() {
            let tracking = self.mode == mode::ROBUST_TRACKING;
            let settings = ControllerSettings {
                gain: self.gain_in_use(),
                pose_gain: self.pose_gain_in_use(),
                k_along_track: if tracking { self.settings.k_along_track } else { 0.0 },
                ..self.settings
            };
            self.validated = Some(SampledController::new(settings).map_err(|e| e.to_string())?);
        }
        let mut c = self.validated.unwrap_or_else(|| unreachable!("validated above"));
        c.set_integral(self.integral);
        Ok(c)
    }
}

impl Model for Controller {
    type Binding = Field<Controller>;

    fmi_export::declare_model!(Field<Controller>, build_declaration());

    fn instantiate(_context: &InstantiateContext) -> ModelResult<Self> {
        // every variable 0 until the layer applies the declared start values
        Ok(Controller {
            inputs: ControllerInputs::default(),
            settings: ControllerSettings::default(),
            custom: ROBUST,
            mode: mode::ROBUST,
            integral: 0.0,
            held: ControllerOutputs { delta: [0.0; 4], tau: [0.0; 4], force: 0.0, saturated: false },
            pending_increment: 0.0,
            validated: None,
        })
    }

    /// A parameter or the `controller` switch changed: the law is validated again.
    fn parameters_changed(&mut self) {
        self.validated = None;
    }

    fn exit_initialization(&mut self) -> ModelResult {
        self.law()?;
        Ok(())
    }

    fn sample_period(&self) -> Option<f64> {
        Some(self.settings.sample_period)
    }

    /// The integrator first takes the step of the previous sample (time has moved past
    /// it), then the law runs on the inputs of `t_k` and its outputs are latched.
    fn sample(&mut self, k: u64, _time: f64) -> ModelResult {
        if k > 0 {
            self.integral += self.pending_increment;
        }
        let law = self.law()?;
        (self.held, self.pending_increment) = law.outputs_and_increment(&self.inputs);
        Ok(())
    }

    fn save_internal(&self, out: &mut Vec<f64>) {
        out.push(self.held.saturated as u8 as f64);
        out.push(self.pending_increment);
    }

    fn load_internal(&mut self, data: &[f64]) -> ModelResult {
        match *data {
            [saturated, pending] if (saturated == 0.0 || saturated == 1.0) && pending.is_finite() => {
                self.held.saturated = saturated == 1.0;
                self.pending_increment = pending;
                Ok(())
            }
            _ => Err(format!(
                "controller internal data: the saturation flag (0 or 1) and the finite pending integrator step \
                 expected, got {} numbers",
                data.len()
            )
            .into()),
        }
    }
}

#[cfg(feature = "fmi-export")]
fmi_export::export_fmi!(Controller);

/// The law and its timing, for `documentation/index.html`.
pub const DOCUMENTATION: &str = include_str!("documentation.html");
