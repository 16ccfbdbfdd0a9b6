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
//! Sampled data: the layer keeps the sample clock ([`fmi2_export::sampled`]) and at every
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

use std::sync::OnceLock;

use fmi2_export::model_description::DefaultExperiment;
use fmi2_export::{
    declared_name, per_wheel, per_wheel_columns, si_unit, Capabilities, Declaration, DeclarationSpec, Dependencies,
    InstantiateContext, Interfaces, Model, ModelResult, Start, VarDecl,
};
use nigel_benchmark::control::{ALONG_TRACK_SPEED_MAX, FORCE_MAX, KI_SPEED, KP_SPEED, K_ALONG_TRACK};
use nigel_benchmark::gains::{POLE_PLACEMENT, ROBUST, ROBUST_TRACKING};
use nigel_benchmark::{ControllerInputs, ControllerOutputs, ControllerSettings, SampledController};

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

/// Largest magnitude of a custom gain (rad of steering per rad of slip or per rad/s of
/// yaw rate): the baked gains are below 1; 100 saturates the steering at 1 mrad of error.
pub const CUSTOM_GAIN_MAX: f64 = 100.0;

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
    // the along-track error reads x, y and the reference pose (not psi); the PI its integrator
    // (a known in Initialization Mode only: the layer keeps it out of the Outputs list)
    let speed_deps = {
        let mut d = vec![
            vr::SPEED,
            vr::SPEED_REF,
            vr::POSE,
            vr::POSE + 1,
            vr::POSE_REF,
            vr::POSE_REF + 1,
            vr::POSE_REF + 2,
            vr::SPEED_INTEGRAL,
        ];
        d.sort_unstable();
        d
    };
    v.extend(per_wheel("delta", vr::DELTA, Var::Steer, |d, i| {
        d.discrete_output(Dependencies::On(steer_deps(i as u32))).unit("rad").describe(
            "steering command delta_ff + K (q - q_ref), q = [beta, yaw_rate] (robust_tracking: \
             delta_ff + K_track e), clamped to +-delta_max; held over a sample",
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
    // (name, vr, binding, start, min, max, unit, description): ranges the law can use; the
    // model checks nothing of its own (the declaration's min/max are refused at the set)
    type Parameter = (&'static str, u32, Var, f64, f64, f64, &'static str, &'static str);
    let params: [Parameter; 8] = [
        (
            "sample_period",
            vr::SAMPLE_PERIOD,
            Var::SamplePeriod,
            1e-3,
            MIN_SAMPLE_PERIOD,
            MAX_SAMPLE_PERIOD,
            "s",
            "sample period of the law",
        ),
        ("kp_speed", vr::KP_SPEED, Var::KpSpeed, KP_SPEED, 0.0, 1e4, "N.s/m", "speed PI proportional gain"),
        ("ki_speed", vr::KI_SPEED, Var::KiSpeed, KI_SPEED, 0.0, 1e5, "N/m", "speed PI integral gain"),
        ("force_max", vr::FORCE_MAX, Var::ForceMax, FORCE_MAX, 1e-3, 1e3, "N", "largest total drive force"),
        ("r_wheel", vr::R_WHEEL, Var::WheelRadius, 0.0325, 1e-3, 1.0, "m", "wheel radius (force to torque)"),
        (
            "delta_max",
            vr::DELTA_MAX,
            Var::SteerLimit,
            core::f64::consts::FRAC_PI_2,
            1e-3,
            core::f64::consts::FRAC_PI_2,
            "rad",
            "steering clamp (the plant's limit)",
        ),
        (
            "k_along_track",
            vr::K_ALONG_TRACK,
            Var::AlongTrackGain,
            K_ALONG_TRACK,
            0.0,
            100.0,
            "1/s",
            "robust_tracking: speed command correction per metre of along-track error",
        ),
        (
            "along_track_speed_max",
            vr::ALONG_TRACK_SPEED_MAX,
            Var::AlongTrackSpeedMax,
            ALONG_TRACK_SPEED_MAX,
            0.0,
            10.0,
            "m/s",
            "robust_tracking: largest along-track speed correction",
        ),
    ];
    for (name, r, b, start, min, max, unit, text) in params {
        v.push(VarDecl::real(name, r, b).parameter(Start::Real(start)).unit(unit).describe(text).min(min).max(max));
    }
    // the gains: a row per wheel, a column per state (beta, yaw_rate) or pose error (e_y, e_psi)
    const GAIN_UNITS: [&str; 2] = ["rad/rad", "rad.s/rad"];
    const POSE_GAIN_UNITS: [&str; 2] = ["rad/m", "rad/rad"];
    v.extend(per_wheel_columns(&["k_beta", "k_yaw_rate"], vr::K_CUSTOM, Var::CustomGain, |d, i, j| {
        d.tunable_parameter(Start::Real(ROBUST[i][j]))
            .min(-CUSTOM_GAIN_MAX)
            .max(CUSTOM_GAIN_MAX)
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

    /// An input, a held output or the integrator: what the law reads or writes, not its settings.
    fn is_input_or_held(b: Var) -> bool {
        matches!(
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
                | Var::Steer(_)
                | Var::Torque(_)
                | Var::DriveForce
                | Var::SpeedIntegral
        )
    }

    /// The slot of Real variable `b` (`None`: a value computed on reading).
    #[inline(always)]
    fn slot(&mut self, b: Var) -> Option<&mut f64> {
        let (x, s, o) = (&mut self.inputs, &mut self.settings, &mut self.held);
        Some(match b {
            Var::Beta => &mut x.beta,
            Var::YawRate => &mut x.yaw_rate,
            Var::Speed => &mut x.speed,
            Var::BetaRef => &mut x.beta_ref,
            Var::YawRateRef => &mut x.yaw_rate_ref,
            Var::SpeedRef => &mut x.speed_ref,
            Var::SteerFeedForward(i) => &mut x.delta_ff[i],
            Var::Pose(i) => [&mut x.x, &mut x.y, &mut x.psi].into_iter().nth(i)?,
            Var::PoseRef(i) => [&mut x.x_ref, &mut x.y_ref, &mut x.psi_ref].into_iter().nth(i)?,
            Var::Steer(i) => &mut o.delta[i],
            Var::Torque(i) => &mut o.tau[i],
            Var::DriveForce => &mut o.force,
            Var::SpeedIntegral => &mut self.integral,
            Var::SamplePeriod => &mut s.sample_period,
            Var::KpSpeed => &mut s.kp_speed,
            Var::KiSpeed => &mut s.ki_speed,
            Var::ForceMax => &mut s.force_max,
            Var::WheelRadius => &mut s.r_wheel,
            Var::SteerLimit => &mut s.delta_max,
            Var::AlongTrackGain => &mut s.k_along_track,
            Var::AlongTrackSpeedMax => &mut s.along_track_speed_max,
            Var::CustomGain(i, j) => &mut self.custom[i][j],
            Var::GainInUse(..) | Var::PoseGainInUse(..) | Var::Controller => return None,
        })
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

    fn get_real(&mut self, b: Var) -> ModelResult<f64> {
        // the held outputs an importer reads at every sample: a field
        if let Some(x) = self.slot(b) {
            return Ok(*x);
        }
        match b {
            Var::GainInUse(i, j) => Ok(self.gain_in_use()[i][j]),
            Var::PoseGainInUse(i, j) => Ok(self.pose_gain_in_use()[i][j]),
            _ => Err("controller is an Integer, not a Real".into()),
        }
    }

    /// The declaration's ranges are the only checks; a parameter empties the validated law.
    fn set_real(&mut self, b: Var, value: f64) -> ModelResult {
        let slot = self.slot(b).ok_or("the gains in use are calculated and controller is an Integer")?;
        *slot = value;
        if !Self::is_input_or_held(b) {
            self.validated = None;
        }
        Ok(())
    }

    /// Every Real setter accepts what the declaration lets through.
    fn setter_may_refuse(b: Var) -> bool {
        matches!(b, Var::GainInUse(..) | Var::PoseGainInUse(..) | Var::Controller)
    }

    fn get_integer(&mut self, _b: Var) -> ModelResult<i32> {
        Ok(self.mode)
    }

    /// `controller` (the only Integer; its range 1..5 is declared).
    fn set_integer(&mut self, _b: Var, value: i32) -> ModelResult {
        self.validated = None;
        self.mode = value;
        Ok(())
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
fmi2_export::export_fmi2!(Controller);

/// The law and its timing, for `documentation/index.html`.
pub const DOCUMENTATION: &str = include_str!("documentation.html");
