//! The controller FMU (`nigel_controller`): the sampled law of docs/benchmark.md,
//! [`nigel_benchmark::SampledController`], behind the shared FMI 2.0 layer. This file is
//! only the binding: the declaration of the variables and a small [`Model`] impl.
//!
//! Beyond the paper (issue 9), `controller = robust_tracking` (the last item, 5) feeds back
//! the pose too: the inputs `x, y, psi` (the measured pose, e.g. the plant's outputs) and
//! `x_ref, y_ref, psi_ref` (the test bench's reference pose) give the tracking errors of
//! `nigel_vehicle::tracking` (heading difference wrapped to `(-pi, pi]`, so unwrapped
//! headings are fine), the steering is `delta = delta_ff + K_track [e_y, e_psi, beta -
//! beta_ref, yaw_rate - yaw_rate_ref]` and the along-track error corrects the speed command
//! (`k_along_track`, `along_track_speed_max`; see `nigel_benchmark::control`). The other
//! modes never read the pose inputs.
//!
//! Sampled data: at every sample instant `t_k = t_start + k sample_period` the layer calls
//! [`Model::event_update`] (a time event in Model Exchange; inside `fmi2DoStep`, or lazily at
//! the first read or step after the importer set the inputs of that instant, in
//! Co-Simulation). There the speed integrator first takes the step of the previous sample
//! (`I_k = I_(k-1) + e_(k-1) T` unless that sample saturated: it advances when time moves
//! past `t_(k-1)`), then the law runs on the inputs of `t_k` with `I_k`, and its outputs
//! are latched and held until `t_(k+1)`. So `speed_integral` read at `t_k` is the `I_k`
//! of the outputs read there. The outputs depend
//! directly on the inputs (declared in the ModelStructure), so a master that sets the
//! inputs at `t_k` and reads the outputs before `fmi2DoStep` sees the law applied to them.

// `!(x > 0.0)` is deliberate: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::sync::OnceLock;

use fmi2_export::model_description::DefaultExperiment;
use fmi2_export::{
    declared_name, per_wheel, per_wheel_columns, si_unit, Capabilities, Declaration, DeclarationSpec, Dependencies,
    EventUpdate, InstantiateContext, Interface, Interfaces, Model, ModelResult, Start, VarDecl,
};
use nigel_benchmark::control::{ALONG_TRACK_SPEED_MAX, FORCE_MAX, KI_SPEED, KP_SPEED, K_ALONG_TRACK};
use nigel_benchmark::gains::{POLE_PLACEMENT, ROBUST, ROBUST_TRACKING};
use nigel_benchmark::{ControllerInputs, ControllerOutputs, ControllerSettings, SampledController};

/// The model identifier (file name of the shared library and of the `.fmu`).
pub const MODEL_IDENTIFIER: &str = "nigel_controller";

/// Most samples the controller runs in Co-Simulation without the importer reading or setting
/// a value in between (1000 s at 1 ms): a longer run (a 10^9 s `fmi2DoStep`, a sample period of 1e-300 s)
/// is refused with `fmi2Error` instead of hanging the importer.
pub const MAX_SAMPLES_UNATTENDED: u64 = 1_000_000;

/// Smallest sample period accepted [s].
pub const MIN_SAMPLE_PERIOD: f64 = 1e-6;

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

/// What a value reference stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Var {
    Beta,
    YawRate,
    Speed,
    BetaRef,
    YawRateRef,
    SpeedRef,
    SteerFeedForward(usize),
    Steer(usize),
    Torque(usize),
    DriveForce,
    SpeedIntegral,
    SamplePeriod,
    KpSpeed,
    KiSpeed,
    ForceMax,
    WheelRadius,
    SteerLimit,
    /// Tunable custom gain, wheel `i`, column `j` (0 = beta, 1 = yaw rate).
    CustomGain(usize, usize),
    /// The gain in use (calculated parameter), wheel `i`, column `j`.
    GainInUse(usize, usize),
    /// The pose gain in use (calculated parameter), wheel `i`, column `j` (0 = e_y, 1 = e_psi).
    PoseGainInUse(usize, usize),
    /// Measured pose input: 0 = x, 1 = y, 2 = psi.
    Pose(usize),
    /// Reference pose input: 0 = x_ref, 1 = y_ref, 2 = psi_ref.
    PoseRef(usize),
    AlongTrackGain,
    AlongTrackSpeedMax,
    Controller,
}

/// Value references (Reals unless stated).
pub mod vr {
    pub const BETA: u32 = 0;
    pub const YAW_RATE: u32 = 1;
    pub const SPEED: u32 = 2;
    pub const BETA_REF: u32 = 3;
    pub const YAW_RATE_REF: u32 = 4;
    pub const SPEED_REF: u32 = 5;
    /// `delta_ff_fl .. delta_ff_rr`: 6..10.
    pub const DELTA_FF: u32 = 6;
    /// `delta_fl .. delta_rr`: 10..14.
    pub const DELTA: u32 = 10;
    /// `tau_fl .. tau_rr`: 14..18.
    pub const TAU: u32 = 14;
    pub const DRIVE_FORCE: u32 = 18;
    pub const SPEED_INTEGRAL: u32 = 20;
    pub const SAMPLE_PERIOD: u32 = 30;
    pub const KP_SPEED: u32 = 31;
    pub const KI_SPEED: u32 = 32;
    pub const FORCE_MAX: u32 = 33;
    pub const R_WHEEL: u32 = 34;
    pub const DELTA_MAX: u32 = 35;
    /// `k_beta_fl, k_yaw_rate_fl, k_beta_fr, ...`: 40..48 (row-major, wheel then column).
    pub const K_CUSTOM: u32 = 40;
    /// `gain_beta_fl, gain_yaw_rate_fl, ...`: 50..58, the gain in use.
    pub const GAIN_IN_USE: u32 = 50;
    /// `x, y, psi`: 60..63, the measured pose.
    pub const POSE: u32 = 60;
    /// `x_ref, y_ref, psi_ref`: 63..66, the reference pose.
    pub const POSE_REF: u32 = 63;
    pub const K_ALONG_TRACK: u32 = 36;
    pub const ALONG_TRACK_SPEED_MAX: u32 = 37;
    /// `gain_e_y_fl, gain_e_psi_fl, ...`: 70..78, the pose gain in use.
    pub const POSE_GAIN_IN_USE: u32 = 70;
    /// Integer value reference of `controller`.
    pub const CONTROLLER: u32 = 0;
}

/// The description of `controller`: its values and what each selects.
pub const CONTROLLER_ITEMS: &str =
    "which steering feedback: 1 open_loop (K = 0, the feed-forward alone), 2 pole_placement \
     (non-robust baseline, Re(s) < -2 at mu = 0.4), 3 robust (mixed H2/H-inf gain, the default), 4 custom (the \
     tunable gains k_beta_* / k_yaw_rate_*), 5 robust_tracking (beyond the paper: the robust tracking gain K_track \
     on the pose errors and the along-track speed correction; reads the pose inputs)";

const POSE_NAMES: [&str; 3] = ["x", "y", "psi"];
const POSE_UNITS: [&str; 3] = ["m", "m", "rad"];

fn build_declaration() -> DeclarationSpec<Var> {
    let mut v: Vec<VarDecl<Var>> = vec![
        VarDecl::real("beta", vr::BETA, Var::Beta)
            .input(Start::Real(0.0))
            .unit("rad")
            .describe("measured body slip angle atan2(v_y, v_x)"),
        VarDecl::real("yaw_rate", vr::YAW_RATE, Var::YawRate)
            .input(Start::Real(0.0))
            .unit("rad/s")
            .describe("measured yaw rate"),
        VarDecl::real("speed", vr::SPEED, Var::Speed)
            .input(Start::Real(0.35))
            .unit("m/s")
            .describe("measured speed hypot(v_x, v_y)"),
        VarDecl::real("beta_ref", vr::BETA_REF, Var::BetaRef)
            .input(Start::Real(0.0))
            .unit("rad")
            .describe("reference body slip angle"),
        VarDecl::real("yaw_rate_ref", vr::YAW_RATE_REF, Var::YawRateRef)
            .input(Start::Real(0.0))
            .unit("rad/s")
            .describe("reference yaw rate"),
        VarDecl::real("speed_ref", vr::SPEED_REF, Var::SpeedRef)
            .input(Start::Real(0.35))
            .unit("m/s")
            .describe("speed the PI holds"),
    ];
    v.extend(per_wheel("delta_ff", vr::DELTA_FF, Var::SteerFeedForward, |d, _| {
        d.input(Start::Real(0.0)).unit("rad").describe("feed-forward steering (the maneuver's program)")
    }));
    for (i, (name, unit)) in POSE_NAMES.iter().zip(POSE_UNITS).enumerate() {
        v.push(
            VarDecl::real(name, vr::POSE + i as u32, Var::Pose(i))
                .input(Start::Real(0.0))
                .unit(unit)
                .describe("measured pose (world frame; heading may be unwrapped), read by robust_tracking only"),
        );
        v.push(
            VarDecl::real(declared_name(format!("{name}_ref")), vr::POSE_REF + i as u32, Var::PoseRef(i))
                .input(Start::Real(0.0))
                .unit(unit)
                .describe("reference pose (the test bench's x_ref, y_ref, psi_ref), read by robust_tracking only"),
        );
    }
    let pose_inputs: Vec<u32> = (0..3).flat_map(|i| [vr::POSE + i, vr::POSE_REF + i]).collect();
    let steer_deps = |i: u32| {
        let mut d = vec![vr::BETA, vr::YAW_RATE, vr::BETA_REF, vr::YAW_RATE_REF, vr::DELTA_FF + i];
        d.extend(&pose_inputs);
        d.sort_unstable();
        d
    };
    // the along-track error reads x, y and the reference pose (not psi)
    let speed_deps = {
        let mut d =
            vec![vr::SPEED, vr::SPEED_REF, vr::POSE, vr::POSE + 1, vr::POSE_REF, vr::POSE_REF + 1, vr::POSE_REF + 2];
        d.sort_unstable();
        d
    };
    v.extend(per_wheel("delta", vr::DELTA, Var::Steer, |d, i| {
        d.discrete_output(Dependencies::On(steer_deps(i as u32))).unit("rad").describe(
            "steering command delta_ff + K (x - x_ref) (robust_tracking: delta_ff + K_track e), clamped to \
             +-delta_max; held over a sample",
        )
    }));
    v.extend(per_wheel("tau", vr::TAU, Var::Torque, |d, _| {
        d.discrete_output(Dependencies::On(speed_deps.clone()))
            .unit("N.m")
            .describe("drive torque F r_wheel / 4; held over a sample")
    }));
    v.push(
        VarDecl::real("drive_force", vr::DRIVE_FORCE, Var::DriveForce)
            .discrete_output(Dependencies::On(speed_deps.clone()))
            .unit("N")
            .describe("total drive force F = kp e + ki I, |F| <= force_max"),
    );
    v.push(
        VarDecl::real("speed_integral", vr::SPEED_INTEGRAL, Var::SpeedIntegral)
            .discrete_state(Start::Real(0.0))
            .unit("m")
            .describe("speed-error integrator I (frozen while F saturates)"),
    );
    let params: [(&'static str, u32, Var, f64, &'static str, &'static str); 8] = [
        ("sample_period", vr::SAMPLE_PERIOD, Var::SamplePeriod, 1e-3, "s", "sample period of the law"),
        ("kp_speed", vr::KP_SPEED, Var::KpSpeed, KP_SPEED, "N.s/m", "speed PI proportional gain"),
        ("ki_speed", vr::KI_SPEED, Var::KiSpeed, KI_SPEED, "N/m", "speed PI integral gain"),
        ("force_max", vr::FORCE_MAX, Var::ForceMax, FORCE_MAX, "N", "largest total drive force"),
        ("r_wheel", vr::R_WHEEL, Var::WheelRadius, 0.0325, "m", "wheel radius (force to torque)"),
        (
            "delta_max",
            vr::DELTA_MAX,
            Var::SteerLimit,
            core::f64::consts::FRAC_PI_2,
            "rad",
            "steering clamp (the plant's limit)",
        ),
        (
            "k_along_track",
            vr::K_ALONG_TRACK,
            Var::AlongTrackGain,
            K_ALONG_TRACK,
            "1/s",
            "robust_tracking: speed command correction per metre of along-track error",
        ),
        (
            "along_track_speed_max",
            vr::ALONG_TRACK_SPEED_MAX,
            Var::AlongTrackSpeedMax,
            ALONG_TRACK_SPEED_MAX,
            "m/s",
            "robust_tracking: largest along-track speed correction",
        ),
    ];
    for (name, r, b, start, unit, text) in params {
        let min = if b == Var::SamplePeriod { MIN_SAMPLE_PERIOD } else { 0.0 };
        let mut p = VarDecl::real(name, r, b).parameter(Start::Real(start)).unit(unit).describe(text).min(min);
        if b == Var::SteerLimit {
            p = p.max(core::f64::consts::FRAC_PI_2);
        }
        v.push(p);
    }
    // the gains: a row per wheel, a column per state (beta, yaw_rate) or pose error (e_y, e_psi)
    const GAIN_UNITS: [&str; 2] = ["rad/rad", "rad.s/rad"];
    const POSE_GAIN_UNITS: [&str; 2] = ["rad/m", "rad/rad"];
    v.extend(per_wheel_columns(&["k_beta", "k_yaw_rate"], vr::K_CUSTOM, Var::CustomGain, |d, i, j| {
        d.tunable_parameter(Start::Real(ROBUST[i][j]))
            .unit(GAIN_UNITS[j])
            .describe("custom gain (used when controller = custom; tunable between steps)")
    }));
    v.extend(per_wheel_columns(&["gain_beta", "gain_yaw_rate"], vr::GAIN_IN_USE, Var::GainInUse, |d, _, j| {
        d.calculated_parameter().unit(GAIN_UNITS[j]).describe("the gain in use (from controller and the custom gains)")
    }));
    v.extend(per_wheel_columns(&["gain_e_y", "gain_e_psi"], vr::POSE_GAIN_IN_USE, Var::PoseGainInUse, |d, _, j| {
        d.calculated_parameter()
            .unit(POSE_GAIN_UNITS[j])
            .describe("the pose gain in use (K_track's e_y, e_psi columns with robust_tracking, else 0)")
    }));
    v.push(
        VarDecl::integer("controller", vr::CONTROLLER, Var::Controller)
            .parameter(Start::Integer(mode::ROBUST))
            .min(f64::from(mode::OPEN_LOOP))
            .max(f64::from(mode::ROBUST_TRACKING))
            .describe(CONTROLLER_ITEMS),
    );
    DeclarationSpec {
        model_name: "nigel_controller",
        model_identifier: MODEL_IDENTIFIER,
        description: "Nigel's sampled controller: delta = delta_ff + K ([beta, yaw_rate] - ref) clamped to \
                      +-delta_max, and the speed-hold PI with anti-windup (docs/benchmark.md); robust gain baked \
                      from the synthesis; robust_tracking adds pose feedback and the along-track correction",
        version: env!("CARGO_PKG_VERSION"),
        interfaces: Interfaces { model_exchange: true, co_simulation: true },
        capabilities: Capabilities { fmu_state: true, serialize_fmu_state: true, directional_derivatives: false },
        enumerations: Vec::new(),
        units: vec![
            si_unit("rad", 0, 0, 0, 1),
            si_unit("rad/s", 0, 0, -1, 1),
            si_unit("m/s", 0, 1, -1, 0),
            si_unit("m", 0, 1, 0, 0),
            si_unit("s", 0, 0, 1, 0),
            si_unit("N", 1, 1, -2, 0),
            si_unit("N.m", 1, 2, -2, 0),
            si_unit("N.s/m", 1, 0, -1, 0),
            si_unit("N/m", 1, 0, -2, 0),
            si_unit("rad/rad", 0, 0, 0, 0),
            si_unit("rad.s/rad", 0, 0, 1, 0),
            si_unit("rad/m", 0, -1, 0, 1),
            si_unit("1/s", 0, 0, -1, 0),
        ],
        default_experiment: Some(DefaultExperiment {
            start_time: Some(0.0),
            stop_time: Some(30.0),
            tolerance: None,
            step_size: Some(1e-3),
        }),
        variables: v,
    }
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
    /// Samples run so far (the next sample is `k`).
    k: u64,
    /// Time of sample 0.
    start_time: f64,
    /// Co-Simulation: samples run since the importer last read or set a value.
    unattended: u64,
    interface: Interface,
    /// The law of `settings`, `custom` and `mode` once validated (its integrator is not
    /// used): a sample does not validate the settings again. Emptied by every setter of a
    /// parameter (`set_real`'s parameter arms) and of the `controller` switch.
    validated: Option<SampledController>,
}

impl Controller {
    /// `set_real` of a Real parameter (the settings the law is validated against, and the
    /// custom gains); the model is unchanged when the value is refused.
    fn set_real_parameter(&mut self, b: Var, value: f64) -> ModelResult {
        let s = &mut self.settings;
        match b {
            Var::SamplePeriod => {
                if !(value >= MIN_SAMPLE_PERIOD) {
                    return Err(format!("sample_period = {value} refused: must be >= {MIN_SAMPLE_PERIOD} s").into());
                }
                s.sample_period = value;
            }
            Var::KpSpeed => Self::set_parameter(&mut s.kp_speed, "kp_speed", value, false)?,
            Var::KiSpeed => Self::set_parameter(&mut s.ki_speed, "ki_speed", value, false)?,
            Var::ForceMax => Self::set_parameter(&mut s.force_max, "force_max", value, true)?,
            Var::WheelRadius => Self::set_parameter(&mut s.r_wheel, "r_wheel", value, true)?,
            Var::SteerLimit => Self::set_parameter(&mut s.delta_max, "delta_max", value, true)?,
            Var::AlongTrackGain => {
                if !(value >= 0.0) {
                    return Err(format!("k_along_track = {value} refused: must be >= 0").into());
                }
                s.k_along_track = value;
            }
            Var::AlongTrackSpeedMax => {
                if !(value >= 0.0) {
                    return Err(format!("along_track_speed_max = {value} refused: must be >= 0").into());
                }
                s.along_track_speed_max = value;
            }
            Var::CustomGain(i, j) => self.custom[i][j] = value,
            Var::GainInUse(..) | Var::PoseGainInUse(..) => return Err("the gains in use are calculated".into()),
            Var::Controller => return Err("controller is an Integer, not a Real".into()),
            _ => return Err(format!("{b:?} is not a Real parameter").into()),
        }
        Ok(())
    }

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

    /// The law with the settings in use and the integrator `I`; the settings are validated
    /// once after they change.
    fn law(&mut self) -> Result<SampledController, String> {
        let mut c = match self.validated {
            Some(c) => c,
            None => {
                let c = self.validate_law()?;
                self.validated = Some(c);
                c
            }
        };
        c.set_integral(self.integral);
        Ok(c)
    }

    /// The settings in use (the gains the `controller` switch selects), validated.
    fn validate_law(&self) -> Result<SampledController, String> {
        let tracking = self.mode == mode::ROBUST_TRACKING;
        let settings = ControllerSettings {
            gain: self.gain_in_use(),
            pose_gain: self.pose_gain_in_use(),
            // the along-track loop belongs to the tracking controller; the paper's run the PI of docs/benchmark.md
            k_along_track: if tracking { self.settings.k_along_track } else { 0.0 },
            ..self.settings
        };
        SampledController::new(settings).map_err(|e| e.to_string())
    }

    /// The outputs an importer reads: the held sample, or before the first sample the law
    /// on the current inputs (what the initial event will latch).
    fn outputs(&mut self) -> ModelResult<ControllerOutputs> {
        if self.k > 0 {
            return Ok(self.held);
        }
        Ok(self.law()?.outputs(&self.inputs))
    }

    /// The value of `b` with the outputs `o`; `None` if `b` is not a Real.
    #[inline(always)]
    fn value(&self, o: &ControllerOutputs, b: Var) -> Option<f64> {
        let x = &self.inputs;
        let s = &self.settings;
        Some(match b {
            Var::Beta => x.beta,
            Var::YawRate => x.yaw_rate,
            Var::Speed => x.speed,
            Var::BetaRef => x.beta_ref,
            Var::YawRateRef => x.yaw_rate_ref,
            Var::SpeedRef => x.speed_ref,
            Var::SteerFeedForward(i) => x.delta_ff[i],
            Var::Steer(i) => o.delta[i],
            Var::Torque(i) => o.tau[i],
            Var::DriveForce => o.force,
            Var::SpeedIntegral => self.integral,
            Var::SamplePeriod => s.sample_period,
            Var::KpSpeed => s.kp_speed,
            Var::KiSpeed => s.ki_speed,
            Var::ForceMax => s.force_max,
            Var::WheelRadius => s.r_wheel,
            Var::SteerLimit => s.delta_max,
            Var::CustomGain(i, j) => self.custom[i][j],
            Var::GainInUse(i, j) => self.gain_in_use()[i][j],
            Var::PoseGainInUse(i, j) => self.pose_gain_in_use()[i][j],
            Var::Pose(i) => [x.x, x.y, x.psi][i],
            Var::PoseRef(i) => [x.x_ref, x.y_ref, x.psi_ref][i],
            Var::AlongTrackGain => s.k_along_track,
            Var::AlongTrackSpeedMax => s.along_track_speed_max,
            Var::Controller => return None,
        })
    }

    /// `get_real` off its fast path: before the first sample (the law on the current
    /// inputs, what the initial event will latch) and for a variable that is not a Real.
    #[cold]
    #[inline(never)]
    fn get_real_before_first_sample(&mut self, b: Var) -> ModelResult<f64> {
        if b == Var::Controller {
            return Err("controller is an Integer, not a Real".into());
        }
        let outputs = match b {
            // only the outputs of the law need it (a parameter reads without valid settings)
            Var::Steer(_) | Var::Torque(_) | Var::DriveForce => self.outputs()?,
            _ => self.held,
        };
        self.value(&outputs, b).ok_or_else(|| format!("{b:?} is not a Real").into())
    }

    fn set_parameter(slot: &mut f64, name: &str, value: f64, positive: bool) -> ModelResult {
        if positive && !(value > 0.0) {
            return Err(format!("{name} = {value} refused: must be > 0").into());
        }
        *slot = value;
        Ok(())
    }
}

impl Model for Controller {
    type Binding = Var;

    fn declaration() -> &'static Declaration<Var> {
        static DECLARATION: OnceLock<Declaration<Var>> = OnceLock::new();
        DECLARATION.get_or_init(|| {
            Declaration::new(build_declaration()).unwrap_or_else(|e| panic!("controller declaration is invalid: {e}"))
        })
    }

    fn instantiate(context: &InstantiateContext) -> ModelResult<Self> {
        let settings = ControllerSettings { k_along_track: K_ALONG_TRACK, ..ControllerSettings::default() };
        Ok(Controller {
            // every input 0 until the layer applies the declared start values
            inputs: ControllerInputs::default(),
            settings,
            custom: ROBUST,
            mode: mode::ROBUST,
            integral: 0.0,
            held: ControllerOutputs { delta: [0.0; 4], tau: [0.0; 4], force: 0.0, saturated: false },
            pending_increment: 0.0,
            k: 0,
            start_time: 0.0,
            unattended: 0,
            interface: context.interface,
            validated: None,
        })
    }

    fn get_real(&mut self, b: Var) -> ModelResult<f64> {
        self.unattended = 0;
        // an importer reads the held outputs at every sample: that path is a lookup
        if self.k > 0 {
            if let Some(value) = self.value(&self.held, b) {
                return Ok(value);
            }
        }
        self.get_real_before_first_sample(b)
    }

    fn set_real(&mut self, b: Var, value: f64) -> ModelResult {
        let x = &mut self.inputs;
        match b {
            Var::Beta => x.beta = value,
            Var::YawRate => x.yaw_rate = value,
            Var::Speed => x.speed = value,
            Var::BetaRef => x.beta_ref = value,
            Var::YawRateRef => x.yaw_rate_ref = value,
            Var::SpeedRef => x.speed_ref = value,
            Var::SteerFeedForward(i) => x.delta_ff[i] = value,
            Var::Pose(0) => x.x = value,
            Var::Pose(1) => x.y = value,
            Var::Pose(_) => x.psi = value,
            Var::PoseRef(0) => x.x_ref = value,
            Var::PoseRef(1) => x.y_ref = value,
            Var::PoseRef(_) => x.psi_ref = value,
            // held outputs come back through here when an FMU state is restored
            Var::Steer(i) => self.held.delta[i] = value,
            Var::Torque(i) => self.held.tau[i] = value,
            Var::DriveForce => self.held.force = value,
            Var::SpeedIntegral => self.integral = value,
            // a parameter: the law is validated again at its next use
            _ => {
                self.set_real_parameter(b, value)?;
                self.validated = None;
            }
        }
        // only an accepted set counts as the importer attending (a refused one changes nothing)
        self.unattended = 0;
        Ok(())
    }

    /// The inputs have no check of their own.
    fn setter_may_refuse(b: Var) -> bool {
        !matches!(
            b,
            Var::Beta
                | Var::YawRate
                | Var::Speed
                | Var::BetaRef
                | Var::YawRateRef
                | Var::SpeedRef
                | Var::SteerFeedForward(_)
                | Var::Pose(_)
                | Var::PoseRef(_)
        )
    }

    fn get_integer(&mut self, b: Var) -> ModelResult<i32> {
        match b {
            Var::Controller => Ok(self.mode),
            _ => Err(format!("{b:?} is not an Integer").into()),
        }
    }

    fn set_integer(&mut self, b: Var, value: i32) -> ModelResult {
        self.validated = None;
        match b {
            Var::Controller if (mode::OPEN_LOOP..=mode::ROBUST_TRACKING).contains(&value) => {
                self.mode = value;
                Ok(())
            }
            Var::Controller => Err(format!("controller = {value} refused: not one of 1..5").into()),
            _ => Err(format!("{b:?} is not an Integer").into()),
        }
    }

    fn exit_initialization(&mut self) -> ModelResult {
        self.law()?;
        if !self.integral.is_finite() {
            return Err(format!("speed_integral = {} refused: must be finite", self.integral).into());
        }
        Ok(())
    }

    fn event_update(&mut self, time: f64) -> ModelResult<EventUpdate> {
        // in Model Exchange every event is one fmi2NewDiscreteStates call of the importer
        self.unattended += (self.interface == Interface::CoSimulation) as u64;
        if self.unattended > MAX_SAMPLES_UNATTENDED {
            return Err(format!(
                "more than {MAX_SAMPLES_UNATTENDED} samples (sample_period = {} s) without the importer reading or \
                 setting a value: the step to beyond t = {time} s is refused",
                self.settings.sample_period
            )
            .into());
        }
        if self.k == 0 {
            self.start_time = time;
        } else {
            // time has moved past the previous sample: its integrator step
            self.integral += self.pending_increment;
        }
        let law = self.law()?;
        (self.held, self.pending_increment) = law.outputs_and_increment(&self.inputs);
        self.k += 1;
        // sample instants from the start time and an integer count: no drift
        let next = self.start_time + self.k as f64 * self.settings.sample_period;
        Ok(EventUpdate::next_at(next))
    }

    fn save_internal(&self, out: &mut Vec<f64>) {
        out.push(self.k as f64);
        out.push(self.start_time);
        out.push(self.held.saturated as u8 as f64);
        out.push(self.pending_increment);
    }

    fn load_internal(&mut self, data: &[f64]) -> ModelResult {
        let [k, start_time, saturated, pending] = data else {
            return Err(format!("controller internal data: 4 numbers expected, got {}", data.len()).into());
        };
        if !(*k >= 0.0 && k.fract() == 0.0 && *k < 9e15 && start_time.is_finite() && pending.is_finite()) {
            return Err(format!("controller internal data {data:?} refused").into());
        }
        if !(*saturated == 0.0 || *saturated == 1.0) {
            return Err(format!("controller internal data {data:?} refused").into());
        }
        self.k = *k as u64;
        self.start_time = *start_time;
        self.held.saturated = *saturated == 1.0;
        self.pending_increment = *pending;
        Ok(())
    }
}

#[cfg(feature = "fmi-export")]
fmi2_export::export_fmi2!(Controller);

/// The law and its timing, for `documentation/index.html`.
pub const DOCUMENTATION: &str = r#"<h2>Law (docs/benchmark.md)</h2>
<pre>
x = [beta, yaw_rate],  x_ref = [beta_ref, yaw_rate_ref]
delta_i = clamp(delta_ff_i + K_i (x - x_ref), -delta_max, delta_max)      (rows i = FL, FR, RL, RR)
e = speed_ref - speed,   F = kp_speed e + ki_speed I
if |F| > force_max:  F = +-force_max and I is frozen,   else  I := I + e sample_period  (at the next sample)
tau_i = F r_wheel / 4
</pre>
<p>The Integer parameter <code>controller</code> (1 .. 5; a plain Integer rather than an FMI Enumeration, so
that every importer can set it) selects K: 1 <code>open_loop</code> (K = 0), 2 <code>pole_placement</code> (the
non-robust baseline, Re(s) &lt; -2 at mu = 0.4), 3 <code>robust</code> (the mixed H2/H-inf gain of the paper variant,
4WD4WS, Pareto point; default), 4 <code>custom</code> (the tunable <code>k_beta_*</code>, <code>k_yaw_rate_*</code>,
which start at the robust gain and may change between steps) or 5 <code>robust_tracking</code> (below). The gain in use is readable as <code>gain_*</code>.
The robust and pole-placement gains are baked from the synthesis crate
(<code>cargo run --release -p nigel-synthesis --bin bake-gains</code>).</p>
<h2>Robust tracking (controller = 5, robust_tracking, beyond the paper)</h2>
<pre>
e_x   =  cos(psi_ref) (x - x_ref) + sin(psi_ref) (y - y_ref)      along-track error, + = ahead
e_y   = -sin(psi_ref) (x - x_ref) + cos(psi_ref) (y - y_ref)      lateral error, + = left of the reference
e_psi = psi - psi_ref wrapped to (-pi, pi]
delta_i = clamp(delta_ff_i + K_track,i [e_y, e_psi, beta - beta_ref, yaw_rate - yaw_rate_ref], -delta_max, delta_max)
speed_command = speed_ref - clamp(k_along_track e_x, -along_track_speed_max, along_track_speed_max)
e = speed_command - speed   (the PI above otherwise unchanged)
</pre>
<p>K_track is the robust mixed H2/H-inf tracking gain (issue 9: the same 16-vertex friction polytope, D-stability
Re(s) &lt; -0.5 and a 135-degree sector), readable as <code>gain_e_y_*</code>, <code>gain_e_psi_*</code>,
<code>gain_beta_*</code>, <code>gain_yaw_rate_*</code>. Connect <code>x, y, psi</code> to the plant's pose and
<code>x_ref, y_ref, psi_ref</code> to the test bench's reference pose; the other modes ignore them.</p>
<h2>Sampling</h2>
<p>The law runs at t_k = t_start + k sample_period on the inputs at t_k; the outputs are held until t_(k+1).
The outputs depend directly on the inputs: an importer that sets the inputs at t_k and reads the outputs before
<code>fmi2DoStep</code> gets the law applied to them. <code>speed_integral</code> read at t_k is the I used there;
it takes the step of sample k when time moves past t_k. A Co-Simulation step spanning several samples runs them in
order (one 10 ms step equals ten 1 ms steps with the same inputs, bit for bit); in Model Exchange the samples are
time events.</p>"#;
