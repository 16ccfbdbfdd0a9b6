//! The test-bench FMU (`nigel_maneuver`): the benchmark of docs/benchmark.md,
//! [`nigel_benchmark::Benchmark`], behind the shared FMI 2.0 layer. This file is only the
//! binding: the declaration of the variables and a small [`Model`] impl.
//!
//! At the end of initialization the FMU computes, from `nigel-vehicle`, the reference of
//! the chosen fidelity (the nominal open-loop run with the speed loop, 1 ms samples, for
//! `duration` seconds) and, for the figure-8, the switching table from the nominal
//! paper-fidelity run. Then at every sample instant `t_k = t_start + k 1 ms` (the layer's
//! sample clock, [`fmi2_export::sampled`]: a time event; inside `fmi2DoStep` in
//! Co-Simulation) it latches the outputs of sample `k` and holds them until `t_(k+1)`. The
//! last sample is at `t = duration`: there the simulation ends (Model Exchange
//! `terminateSimulation`; a Co-Simulation step past it `fmi2Discard` with `fmi2Terminated`),
//! and a stop time past it is refused. `beta_meas` and `yaw_rate_meas` depend directly on the inputs
//! `beta` and `yaw_rate` (declared in the ModelStructure); everything else on `k` alone.

// `!(x > 0.0)` is deliberate: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::sync::{Arc, OnceLock};

use core::f64::consts::TAU;
use fmi2_export::model_description::DefaultExperiment;
use fmi2_export::{
    declared_name, per_wheel, si_unit, Capabilities, Declaration, DeclarationSpec, Dependencies, InstantiateContext,
    Interfaces, Model, ModelResult, SampleEnd, Start, VarDecl,
};
use nigel_benchmark::{
    BenchSample, BenchSampler, Benchmark, DisturbanceSettings, Fidelity, Maneuver, Scenario, DEFAULT_SPEED,
    DEFAULT_STEER_AMPLITUDE, MAX_WIND_AMPLITUDE, MU_MAX, SAMPLE_PERIOD,
};

/// The model identifier (file name of the shared library and of the `.fmu`).
pub const MODEL_IDENTIFIER: &str = "nigel_maneuver";

/// Longest reference the FMU computes (10 minutes: 600,000 samples, about 50 MB and 1.5 s
/// at initialization); `duration` above it is refused.
pub const MAX_DURATION: f64 = 600.0;

/// Slowest `speed_target` [m/s]: the reference and its speed loop need the car moving.
pub const MIN_SPEED_TARGET: f64 = 0.01;

/// What a value reference stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Var {
    Beta,
    YawRate,
    SteerFeedForward(usize),
    BetaRef,
    YawRateRef,
    SpeedRef,
    XRef,
    YRef,
    PsiRef,
    Friction(usize),
    WindX,
    WindY,
    BetaMeas,
    YawRateMeas,
    SteerAmplitude,
    SpeedTarget,
    Duration,
    Maneuver,
    Fidelity,
    Seed,
    FrictionVariation,
    Wind,
    MeasurementNoise,
    FrictionMean,
    FrictionAmplitude,
    FrictionFrequency,
    FrictionNoise,
    FrictionPhase(usize),
    WindAmplitude,
    WindNoise,
    WindDirection,
    WindStart,
    BetaNoise,
    YawRateNoise,
}

/// Value references (Reals unless stated).
pub mod vr {
    pub const BETA: u32 = 0;
    pub const YAW_RATE: u32 = 1;
    /// `delta_ff_fl .. delta_ff_rr`: 10..14.
    pub const DELTA_FF: u32 = 10;
    pub const BETA_REF: u32 = 14;
    pub const YAW_RATE_REF: u32 = 15;
    pub const SPEED_REF: u32 = 16;
    pub const X_REF: u32 = 17;
    pub const Y_REF: u32 = 18;
    pub const PSI_REF: u32 = 19;
    /// `mu_fl .. mu_rr`: 20..24.
    pub const MU: u32 = 20;
    pub const WIND_X: u32 = 24;
    pub const WIND_Y: u32 = 25;
    pub const BETA_MEAS: u32 = 26;
    pub const YAW_RATE_MEAS: u32 = 27;
    pub const STEER_AMPLITUDE: u32 = 30;
    pub const SPEED_TARGET: u32 = 31;
    pub const DURATION: u32 = 32;
    /// The disturbance settings ([`nigel_benchmark::DisturbanceSettings`]): 40..54.
    pub const FRICTION_MEAN: u32 = 40;
    pub const FRICTION_AMPLITUDE: u32 = 41;
    pub const FRICTION_FREQUENCY: u32 = 42;
    pub const FRICTION_NOISE: u32 = 43;
    /// `friction_phase_fl .. friction_phase_rr`: 44..48.
    pub const FRICTION_PHASE: u32 = 44;
    pub const WIND_AMPLITUDE: u32 = 48;
    pub const WIND_NOISE: u32 = 49;
    pub const WIND_DIRECTION: u32 = 50;
    pub const WIND_START: u32 = 51;
    pub const BETA_NOISE: u32 = 52;
    pub const YAW_RATE_NOISE: u32 = 53;
    /// Integer value references (`maneuver` and `fidelity` take the 1-based values of
    /// [`super::maneuver_value`] and [`super::fidelity_value`]).
    pub const MANEUVER: u32 = 0;
    pub const FIDELITY: u32 = 1;
    /// Integer.
    pub const SEED: u32 = 2;
    /// Boolean value references.
    pub const FRICTION_VARIATION: u32 = 0;
    pub const WIND: u32 = 1;
    pub const MEASUREMENT_NOISE: u32 = 2;
}

/// Value (1-based) of the Integer parameter `maneuver` for a maneuver, in the order of
/// [`Maneuver::ALL`]: 1 straight, 2 lane_change, 3 skidpad, 4 fishhook, 5 slalom, 6 figure_8.
/// The switches are plain Integers, not FMI Enumerations, so that every importer (libcosim
/// and ecos ignore Enumerations) can set them; the list is in the variable's description.
pub fn maneuver_value(m: Maneuver) -> i32 {
    Maneuver::ALL.iter().position(|&x| x == m).map_or(0, |i| i as i32 + 1)
}

/// Value (1-based) of the Integer parameter `fidelity`: paper 1, real 2.
pub fn fidelity_value(f: Fidelity) -> i32 {
    Fidelity::ALL.iter().position(|&x| x == f).map_or(0, |i| i as i32 + 1)
}

/// What a maneuver's steering program is (for the description of `maneuver`).
fn program(m: Maneuver) -> &'static str {
    match m {
        Maneuver::Straight => "no steering",
        Maneuver::LaneChange => "impulse at 14.8 s",
        Maneuver::Skidpad => "step 2.5 .. 27.5 s",
        Maneuver::Fishhook => "ramp 2.5 .. 25 s, hold to 27.5 s",
        Maneuver::Slalom => "sine 2.5 .. 27.5 s, 15 periods",
        Maneuver::Figure8 => "square wave switched at the nominal car's closest approach to the origin",
    }
}

/// The description of `maneuver`: "the maneuver: 1 straight (no steering), 2 lane_change (...), ...".
fn maneuver_items() -> &'static str {
    let items: Vec<String> =
        Maneuver::ALL.iter().map(|&m| format!("{} {} ({})", maneuver_value(m), m.name(), program(m))).collect();
    declared_name(format!("the maneuver: {}", items.join(", ")))
}

/// The description of `fidelity`: "... 1 paper (...), 2 real (...)".
fn fidelity_items() -> &'static str {
    let items: Vec<String> = Fidelity::ALL
        .iter()
        .map(|&f| {
            let text = match f {
                Fidelity::Paper => "Table II, true measurements: the sim column",
                Fidelity::Real => "friction circle, servo, motor limit; noisy measurements",
            };
            format!("{} {} ({text})", fidelity_value(f), f.name())
        })
        .collect();
    declared_name(format!("the reference plant and the measurement noise: {}", items.join(", ")))
}

fn build_declaration() -> DeclarationSpec<Var> {
    let none = || Dependencies::On(vec![]);
    let mut v: Vec<VarDecl<Var>> = vec![
        VarDecl::real("beta", vr::BETA, Var::Beta)
            .input(Start::Real(0.0))
            .unit("rad")
            .describe("the plant's true body slip angle"),
        VarDecl::real("yaw_rate", vr::YAW_RATE, Var::YawRate)
            .input(Start::Real(0.0))
            .unit("rad/s")
            .describe("the plant's true yaw rate"),
    ];
    v.extend(per_wheel("delta_ff", vr::DELTA_FF, Var::SteerFeedForward, |d, _| {
        d.discrete_output(none()).unit("rad").describe("the maneuver's steering program (front +f, rear -f)")
    }));
    let outputs: [(&'static str, u32, Var, &'static str, &'static str); 6] = [
        ("beta_ref", vr::BETA_REF, Var::BetaRef, "rad", "reference body slip angle"),
        ("yaw_rate_ref", vr::YAW_RATE_REF, Var::YawRateRef, "rad/s", "reference yaw rate"),
        ("speed_ref", vr::SPEED_REF, Var::SpeedRef, "m/s", "speed to hold (the parameter speed_target)"),
        ("x_ref", vr::X_REF, Var::XRef, "m", "reference pose: world X"),
        ("y_ref", vr::Y_REF, Var::YRef, "m", "reference pose: world Y"),
        ("psi_ref", vr::PSI_REF, Var::PsiRef, "rad", "reference pose: heading (unwrapped)"),
    ];
    for (name, r, b, unit, text) in outputs {
        v.push(VarDecl::real(name, r, b).discrete_output(none()).unit(unit).describe(text));
    }
    v.extend(per_wheel("mu", vr::MU, Var::Friction, |d, _| {
        d.discrete_output(none()).describe(
            "road friction friction_amplitude sin(2 pi friction_frequency theta - friction_phase_i) + friction_mean \
             + friction_noise (u - 1/2), theta = 2 pi t / 30 s (0.4 when off)",
        )
    }));
    v.push(
        VarDecl::real("wind_x", vr::WIND_X, Var::WindX)
            .discrete_output(none())
            .unit("N")
            .describe("wind force along world X: cos(wind_direction) F_w (zero with the default direction)"),
    );
    v.push(VarDecl::real("wind_y", vr::WIND_Y, Var::WindY).discrete_output(none()).unit("N").describe(
        "wind force along world Y: sin(wind_direction) F_w, \
                 F_w = wind_amplitude ([t >= wind_start] + wind_noise chi)",
    ));
    v.push(
        VarDecl::real("beta_meas", vr::BETA_MEAS, Var::BetaMeas)
            .discrete_output(Dependencies::On(vec![vr::BETA]))
            .unit("rad")
            .describe("what the controller measures: beta (+ beta_noise g in the real fidelity)"),
    );
    v.push(
        VarDecl::real("yaw_rate_meas", vr::YAW_RATE_MEAS, Var::YawRateMeas)
            .discrete_output(Dependencies::On(vec![vr::YAW_RATE]))
            .unit("rad/s")
            .describe("what the controller measures: yaw rate (+ yaw_rate_noise g in the real fidelity)"),
    );
    v.push(
        VarDecl::real("steer_amplitude", vr::STEER_AMPLITUDE, Var::SteerAmplitude)
            .parameter(Start::Real(DEFAULT_STEER_AMPLITUDE))
            .min(0.0)
            .max(core::f64::consts::FRAC_PI_2)
            .unit("rad")
            .describe("amplitude a of the steering programs (30 deg)"),
    );
    v.push(
        VarDecl::real("speed_target", vr::SPEED_TARGET, Var::SpeedTarget)
            .parameter(Start::Real(DEFAULT_SPEED))
            .min(MIN_SPEED_TARGET)
            .max(10.0)
            .unit("m/s")
            .describe("speed the reference holds and the output speed_ref gives (start speed of the reference)"),
    );
    v.push(
        VarDecl::real("duration", vr::DURATION, Var::Duration)
            .parameter(Start::Real(30.0))
            .min(SAMPLE_PERIOD)
            .max(MAX_DURATION)
            .unit("s")
            .describe("length of the reference computed at initialization (30 s); a run may not go past it"),
    );
    v.push(
        VarDecl::integer("maneuver", vr::MANEUVER, Var::Maneuver)
            .parameter(Start::Integer(maneuver_value(Maneuver::Straight)))
            .min(1.0)
            .max(Maneuver::ALL.len() as f64)
            .describe(maneuver_items()),
    );
    v.push(
        VarDecl::integer("fidelity", vr::FIDELITY, Var::Fidelity)
            .parameter(Start::Integer(fidelity_value(Fidelity::Paper)))
            .min(1.0)
            .max(Fidelity::ALL.len() as f64)
            .describe(fidelity_items()),
    );
    v.push(
        VarDecl::integer("seed", vr::SEED, Var::Seed)
            .parameter(Start::Integer(0))
            .min(0.0)
            .describe("seed of every noise stream (counter-based SplitMix64)"),
    );
    v.push(
        VarDecl::boolean("friction_variation", vr::FRICTION_VARIATION, Var::FrictionVariation)
            .parameter(Start::Boolean(true))
            .describe("friction sinusoids plus noise (else mu = 0.4)"),
    );
    v.push(
        VarDecl::boolean("wind", vr::WIND, Var::Wind).parameter(Start::Boolean(true)).describe("wind along world +Y"),
    );
    v.push(
        VarDecl::boolean("measurement_noise", vr::MEASUREMENT_NOISE, Var::MeasurementNoise)
            .parameter(Start::Boolean(true))
            .describe("Gaussian noise on beta_meas, yaw_rate_meas (real fidelity only)"),
    );
    let defaults = DisturbanceSettings::default();
    // the disturbance settings: fixed parameters, the paper's values as start values
    let setting = |name, r, b, start: f64, (min, max): (f64, f64), text| {
        VarDecl::real(name, r, b).parameter(Start::Real(start)).min(min).max(max).describe(text)
    };
    v.push(setting(
        "friction_mean",
        vr::FRICTION_MEAN,
        Var::FrictionMean,
        defaults.friction_mean,
        (0.0, MU_MAX),
        "friction the sinusoid oscillates around (0.55); friction_mean -+ (friction_amplitude + \
             friction_noise / 2) must stay in [0, 3]",
    ));
    v.push(setting(
        "friction_amplitude",
        vr::FRICTION_AMPLITUDE,
        Var::FrictionAmplitude,
        defaults.friction_amplitude,
        (0.0, MU_MAX),
        "amplitude of the friction sinusoid (0.35)",
    ));
    v.push(setting(
        "friction_frequency",
        vr::FRICTION_FREQUENCY,
        Var::FrictionFrequency,
        defaults.friction_frequency,
        (0.0, 1000.0),
        "factor f of theta = 2 pi t / 30 s in the sinusoid's argument 2 pi f theta (12: about 75 periods in 30 s)",
    ));
    v.push(setting(
        "friction_noise",
        vr::FRICTION_NOISE,
        Var::FrictionNoise,
        defaults.friction_noise,
        (0.0, 2.0 * MU_MAX),
        "width of the uniform friction noise, centred on zero (0.1: -0.05 .. 0.05)",
    ));
    v.push(
        setting(
            "wind_amplitude",
            vr::WIND_AMPLITUDE,
            Var::WindAmplitude,
            defaults.wind_amplitude,
            (0.0, MAX_WIND_AMPLITUDE),
            "wind step from wind_start (0.25 N)",
        )
        .unit("N"),
    );
    v.push(setting(
        "wind_noise",
        vr::WIND_NOISE,
        Var::WindNoise,
        defaults.wind_noise,
        (0.0, 10.0),
        "uniform wind noise from t = 0, relative to wind_amplitude (0.1)",
    ));
    v.push(
        setting(
            "wind_direction",
            vr::WIND_DIRECTION,
            Var::WindDirection,
            defaults.wind_direction,
            (-TAU, TAU),
            "direction the wind blows towards in the world frame, from +X towards +Y (pi/2: along +Y)",
        )
        .unit("rad"),
    );
    v.push(
        setting(
            "wind_start",
            vr::WIND_START,
            Var::WindStart,
            defaults.wind_start,
            (0.0, MAX_DURATION),
            "time the wind step starts, at the nearest 1 ms sample (1 s)",
        )
        .unit("s"),
    );
    v.push(
        setting(
            "beta_noise",
            vr::BETA_NOISE,
            Var::BetaNoise,
            defaults.beta_noise,
            (0.0, 1.0),
            "standard deviation of the Gaussian noise on beta_meas (0.005 rad; real fidelity only)",
        )
        .unit("rad"),
    );
    v.push(
        setting(
            "yaw_rate_noise",
            vr::YAW_RATE_NOISE,
            Var::YawRateNoise,
            defaults.yaw_rate_noise,
            (0.0, 10.0),
            "standard deviation of the Gaussian noise on yaw_rate_meas (0.01 rad/s; real fidelity only)",
        )
        .unit("rad/s"),
    );
    v.extend(per_wheel("friction_phase", vr::FRICTION_PHASE, Var::FrictionPhase, |d, i| {
        d.parameter(Start::Real(defaults.friction_phase[i]))
            .min(-2.0 * TAU)
            .max(2.0 * TAU)
            .unit("rad")
            .describe("phase of the wheel's friction sinusoid (FL 0, FR pi/2, RL pi, RR 3 pi/2)")
    }));
    DeclarationSpec {
        model_name: "nigel_maneuver",
        model_identifier: MODEL_IDENTIFIER,
        description:
            "Benchmark test bench of docs/benchmark.md: steering programs, reference (nominal open-loop run), \
                      friction and wind disturbances, measurement noise (counter-based SplitMix64)",
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
        ],
        default_experiment: Some(DefaultExperiment {
            start_time: Some(0.0),
            stop_time: Some(30.0),
            tolerance: None,
            step_size: Some(SAMPLE_PERIOD),
        }),
        variables: v,
    }
}

/// The test-bench instance.
#[derive(Clone, Debug)]
pub struct TestBench {
    scenario: Scenario,
    duration: f64,
    beta: f64,
    yaw_rate: f64,
    /// Computed at the end of initialization (shared by FMU-state copies; the reference and
    /// the disturbance table are shared with the process cache).
    bench: Option<Arc<BenchSampler>>,
    /// The outputs of the last sample, held until the next one.
    held: BenchSample,
}

impl TestBench {
    /// The scenario of the parameters (`duration` in whole samples; its range is declared).
    fn scenario_now(&self) -> Result<Scenario, String> {
        let scenario = Scenario { n_samples: self.last_sample() as usize, ..self.scenario };
        scenario.validate().map_err(|e| e.to_string())?;
        Ok(scenario)
    }

    /// The sample at `t = duration`: the reference covers samples `0 ..= last`.
    fn last_sample(&self) -> u64 {
        (self.duration / SAMPLE_PERIOD).round() as u64
    }

    /// The slot of Real variable `b` (`None` for the other base types).
    #[inline(always)]
    fn slot(&mut self, b: Var) -> Option<&mut f64> {
        let o = &mut self.held;
        let d = &mut self.scenario.disturbance_settings;
        Some(match b {
            Var::Beta => &mut self.beta,
            Var::YawRate => &mut self.yaw_rate,
            Var::SteerFeedForward(i) => &mut o.delta_ff[i],
            Var::BetaRef => &mut o.beta_ref,
            Var::YawRateRef => &mut o.yaw_rate_ref,
            Var::SpeedRef => &mut o.speed_ref,
            Var::XRef => &mut o.x_ref,
            Var::YRef => &mut o.y_ref,
            Var::PsiRef => &mut o.psi_ref,
            Var::Friction(i) => &mut o.mu[i],
            Var::WindX => &mut o.wind_x,
            Var::WindY => &mut o.wind_y,
            Var::BetaMeas => &mut o.beta_meas,
            Var::YawRateMeas => &mut o.yaw_rate_meas,
            Var::SteerAmplitude => &mut self.scenario.steer_amplitude,
            Var::SpeedTarget => &mut self.scenario.speed_ref,
            Var::Duration => &mut self.duration,
            Var::FrictionMean => &mut d.friction_mean,
            Var::FrictionAmplitude => &mut d.friction_amplitude,
            Var::FrictionFrequency => &mut d.friction_frequency,
            Var::FrictionNoise => &mut d.friction_noise,
            Var::FrictionPhase(i) => &mut d.friction_phase[i],
            Var::WindAmplitude => &mut d.wind_amplitude,
            Var::WindNoise => &mut d.wind_noise,
            Var::WindDirection => &mut d.wind_direction,
            Var::WindStart => &mut d.wind_start,
            Var::BetaNoise => &mut d.beta_noise,
            Var::YawRateNoise => &mut d.yaw_rate_noise,
            _ => return None,
        })
    }
}

const NOT_A_REAL: &str = "not a Real variable";

impl Model for TestBench {
    type Binding = Var;

    fn declaration() -> &'static Declaration<Var> {
        static DECLARATION: OnceLock<Declaration<Var>> = OnceLock::new();
        DECLARATION.get_or_init(|| {
            Declaration::new(build_declaration()).unwrap_or_else(|e| panic!("test-bench declaration is invalid: {e}"))
        })
    }

    fn instantiate(_context: &InstantiateContext) -> ModelResult<Self> {
        let scenario = Scenario::new(Maneuver::Straight, Fidelity::Paper);
        Ok(TestBench {
            scenario,
            duration: 30.0,
            beta: 0.0,
            yaw_rate: 0.0,
            bench: None,
            held: Benchmark::initial_sample(&scenario, 0.0, 0.0),
        })
    }

    fn get_real(&mut self, b: Var) -> ModelResult<f64> {
        self.slot(b).map(|x| *x).ok_or_else(|| NOT_A_REAL.into())
    }

    /// The declaration's ranges are the only checks.
    fn set_real(&mut self, b: Var, value: f64) -> ModelResult {
        *self.slot(b).ok_or(NOT_A_REAL)? = value;
        Ok(())
    }

    fn setter_may_refuse(b: Var) -> bool {
        matches!(b, Var::Maneuver | Var::Fidelity | Var::Seed)
    }

    fn get_integer(&mut self, b: Var) -> ModelResult<i32> {
        match b {
            Var::Maneuver => Ok(maneuver_value(self.scenario.maneuver)),
            Var::Fidelity => Ok(fidelity_value(self.scenario.fidelity)),
            _ => Ok(self.scenario.seed as i32),
        }
    }

    /// The declared ranges (1 .. the number of items, seed >= 0) make each conversion exact.
    fn set_integer(&mut self, b: Var, value: i32) -> ModelResult {
        let index = usize::try_from(value - 1).unwrap_or(0);
        match b {
            Var::Maneuver => self.scenario.maneuver = *Maneuver::ALL.get(index).ok_or("not a maneuver")?,
            Var::Fidelity => self.scenario.fidelity = *Fidelity::ALL.get(index).ok_or("not a fidelity")?,
            _ => self.scenario.seed = u64::try_from(value).map_err(|_| "a seed is >= 0")?,
        }
        Ok(())
    }

    fn get_boolean(&mut self, b: Var) -> ModelResult<bool> {
        let s = &self.scenario;
        Ok(match b {
            Var::FrictionVariation => s.friction_variation,
            Var::Wind => s.wind,
            _ => s.measurement_noise,
        })
    }

    fn set_boolean(&mut self, b: Var, value: bool) -> ModelResult {
        let s = &mut self.scenario;
        match b {
            Var::FrictionVariation => s.friction_variation = value,
            Var::Wind => s.wind = value,
            _ => s.measurement_noise = value,
        }
        Ok(())
    }

    /// Computes the reference (and the figure-8 table) unless it is there for these parameters.
    fn exit_initialization(&mut self) -> ModelResult {
        let scenario = self.scenario_now()?;
        if self.bench.as_ref().is_some_and(|b| *b.scenario() == scenario) {
            return Ok(());
        }
        // the process keeps the recent references (they depend on neither the seed, the
        // switches nor the disturbance settings) and the disturbance tables per seed and
        // settings: many instances compute each once
        self.bench = Some(Arc::new(BenchSampler::prepare(scenario).map_err(|e| e.to_string())?));
        Ok(())
    }

    fn sample_period(&self) -> Option<f64> {
        Some(SAMPLE_PERIOD)
    }

    fn sample_end(&self) -> Option<SampleEnd> {
        Some(SampleEnd { last: self.last_sample(), variable: "duration" })
    }

    /// The outputs of sample `k`; before the reference exists (Initialization Mode) sample 0
    /// is the benchmark's initial sample.
    fn sample(&mut self, k: u64, _time: f64) -> ModelResult {
        self.held = match &self.bench {
            Some(bench) => bench.sample(k as usize, self.beta, self.yaw_rate).ok_or("past the reference's end")?,
            None if k == 0 => Benchmark::initial_sample(&self.scenario, self.beta, self.yaw_rate),
            None => return Err("the reference was not computed (initialization did not end)".into()),
        };
        Ok(())
    }
}

#[cfg(feature = "fmi-export")]
fmi2_export::export_fmi2!(TestBench);

/// What the test bench computes, for `documentation/index.html`.
pub const DOCUMENTATION: &str = include_str!("documentation.html");
