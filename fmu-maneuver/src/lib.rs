//! The test-bench FMU (`nigel_maneuver`): the benchmark of docs/benchmark.md,
//! [`nigel_benchmark::Benchmark`], behind the shared FMI 2.0 layer. This file is only the
//! binding: the declaration of the variables and a small [`Model`] impl.
//!
//! At the end of initialization the FMU computes, from `nigel-vehicle`, the reference of
//! the chosen fidelity (the nominal open-loop run with the speed loop, 1 ms samples, for
//! `duration` seconds) and, for the figure-8, the switching table from the nominal
//! paper-fidelity run. Then at every sample instant `t_k = t_start + k 1 ms` (a time event;
//! inside `fmi2DoStep` in Co-Simulation) it latches the outputs of sample `k` and holds
//! them until `t_(k+1)`. `beta_meas` and `yaw_rate_meas` depend directly on the inputs
//! `beta` and `yaw_rate` (declared in the ModelStructure); everything else on `k` alone.

// `!(x > 0.0)` is deliberate: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::sync::{Arc, OnceLock};

use fmi2_export::model_description::DefaultExperiment;
use fmi2_export::{
    declared_name, per_wheel, si_unit, Capabilities, Declaration, DeclarationSpec, Dependencies, EventUpdate,
    InstantiateContext, Interfaces, Model, ModelResult, Start, VarDecl,
};
use nigel_benchmark::{
    BenchSample, BenchSampler, Benchmark, Fidelity, Maneuver, Scenario, DEFAULT_SPEED, DEFAULT_STEER_AMPLITUDE,
    SAMPLE_PERIOD,
};

/// The model identifier (file name of the shared library and of the `.fmu`).
pub const MODEL_IDENTIFIER: &str = "nigel_maneuver";

/// Longest reference the FMU computes (10 minutes: 600,000 samples, about 50 MB and 1.5 s
/// at initialization); `duration` above it is refused.
pub const MAX_DURATION: f64 = 600.0;

/// Samples of the longest reference.
const MAX_SAMPLES: usize = 600_000;

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
        d.discrete_output(none()).describe("road friction 0.35 sin(2 pi f theta - phi_i) + 0.55 + noise (0.4 when off)")
    }));
    v.push(
        VarDecl::real("wind_x", vr::WIND_X, Var::WindX)
            .discrete_output(none())
            .unit("N")
            .describe("wind force along world X (zero in docs/benchmark.md)"),
    );
    v.push(
        VarDecl::real("wind_y", vr::WIND_Y, Var::WindY)
            .discrete_output(none())
            .unit("N")
            .describe("wind force along world Y: 0.25 [t >= 1 s] + 0.025 chi"),
    );
    v.push(
        VarDecl::real("beta_meas", vr::BETA_MEAS, Var::BetaMeas)
            .discrete_output(Dependencies::On(vec![vr::BETA]))
            .unit("rad")
            .describe("what the controller measures: beta (+ 0.005 g in the real fidelity)"),
    );
    v.push(
        VarDecl::real("yaw_rate_meas", vr::YAW_RATE_MEAS, Var::YawRateMeas)
            .discrete_output(Dependencies::On(vec![vr::YAW_RATE]))
            .unit("rad/s")
            .describe("what the controller measures: yaw rate (+ 0.01 g in the real fidelity)"),
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
            .min(0.0)
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
    DeclarationSpec {
        model_name: "nigel_maneuver",
        model_identifier: MODEL_IDENTIFIER,
        description: "Benchmark test bench of docs/benchmark.md: steering programs, reference (nominal open-loop run), \
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
    /// Samples run so far (the next sample is `k`).
    k: u64,
    /// Time of sample 0.
    start_time: f64,
}

impl TestBench {
    fn scenario_now(&self) -> Result<Scenario, String> {
        let d = self.duration;
        if !(SAMPLE_PERIOD..=MAX_DURATION).contains(&d) {
            return Err(format!("duration = {d} refused: must be in [1 ms, {MAX_DURATION} s]"));
        }
        let scenario = Scenario { n_samples: (d / SAMPLE_PERIOD).round() as usize, ..self.scenario };
        scenario.validate().map_err(|e| e.to_string())?;
        Ok(scenario)
    }

    /// The outputs an importer reads: the held sample, or before the first sample what
    /// the initial event will latch.
    fn outputs(&self) -> BenchSample {
        if self.k > 0 {
            return self.held;
        }
        Benchmark::initial_sample(&self.scenario, self.beta, self.yaw_rate)
    }

    /// The value of `b` with the outputs `o`; `None` if `b` is not a Real.
    #[inline(always)]
    fn value(&self, o: &BenchSample, b: Var) -> Option<f64> {
        Some(match b {
            Var::Beta => self.beta,
            Var::YawRate => self.yaw_rate,
            Var::SteerFeedForward(i) => o.delta_ff[i],
            Var::BetaRef => o.beta_ref,
            Var::YawRateRef => o.yaw_rate_ref,
            Var::SpeedRef => o.speed_ref,
            Var::XRef => o.x_ref,
            Var::YRef => o.y_ref,
            Var::PsiRef => o.psi_ref,
            Var::Friction(i) => o.mu[i],
            Var::WindX => o.wind_x,
            Var::WindY => o.wind_y,
            Var::BetaMeas => o.beta_meas,
            Var::YawRateMeas => o.yaw_rate_meas,
            Var::SteerAmplitude => self.scenario.steer_amplitude,
            Var::SpeedTarget => self.scenario.speed_ref,
            Var::Duration => self.duration,
            _ => return None,
        })
    }

    /// `get_real` off its fast path: before the first sample (what the initial event will
    /// latch) and for a variable that is not a Real.
    #[cold]
    #[inline(never)]
    fn get_real_before_first_sample(&self, b: Var) -> ModelResult<f64> {
        self.value(&self.outputs(), b).ok_or_else(|| format!("{b:?} is not a Real").into())
    }
}

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
            k: 0,
            start_time: 0.0,
        })
    }

    fn get_real(&mut self, b: Var) -> ModelResult<f64> {
        // an importer reads some 20 held outputs at every sample: that path is a lookup
        if self.k > 0 {
            if let Some(value) = self.value(&self.held, b) {
                return Ok(value);
            }
        }
        self.get_real_before_first_sample(b)
    }

    fn set_real(&mut self, b: Var, value: f64) -> ModelResult {
        let h = &mut self.held;
        match b {
            Var::Beta => self.beta = value,
            Var::YawRate => self.yaw_rate = value,
            // held outputs come back through here when an FMU state is restored
            Var::SteerFeedForward(i) => h.delta_ff[i] = value,
            Var::BetaRef => h.beta_ref = value,
            Var::YawRateRef => h.yaw_rate_ref = value,
            Var::SpeedRef => h.speed_ref = value,
            Var::XRef => h.x_ref = value,
            Var::YRef => h.y_ref = value,
            Var::PsiRef => h.psi_ref = value,
            Var::Friction(i) => h.mu[i] = value,
            Var::WindX => h.wind_x = value,
            Var::WindY => h.wind_y = value,
            Var::BetaMeas => h.beta_meas = value,
            Var::YawRateMeas => h.yaw_rate_meas = value,
            Var::SteerAmplitude => {
                if !(0.0..=core::f64::consts::FRAC_PI_2).contains(&value) {
                    return Err(format!("steer_amplitude = {value} refused: must be in [0, pi/2] rad").into());
                }
                self.scenario.steer_amplitude = value;
            }
            Var::SpeedTarget => {
                if !(value > 0.0 && value <= 10.0) {
                    return Err(format!("speed_target = {value} refused: must be in (0, 10] m/s").into());
                }
                self.scenario.speed_ref = value;
            }
            Var::Duration => {
                if !(SAMPLE_PERIOD..=MAX_DURATION).contains(&value) {
                    return Err(format!("duration = {value} refused: must be in [1 ms, {MAX_DURATION} s]").into());
                }
                self.duration = value;
            }
            _ => return Err(format!("{b:?} is not a Real").into()),
        }
        Ok(())
    }

    /// The inputs have no check of their own.
    fn setter_may_refuse(b: Var) -> bool {
        !matches!(b, Var::Beta | Var::YawRate)
    }

    fn get_integer(&mut self, b: Var) -> ModelResult<i32> {
        match b {
            Var::Maneuver => Ok(maneuver_value(self.scenario.maneuver)),
            Var::Fidelity => Ok(fidelity_value(self.scenario.fidelity)),
            Var::Seed => Ok(self.scenario.seed as i32),
            _ => Err(format!("{b:?} is not an Integer").into()),
        }
    }

    fn set_integer(&mut self, b: Var, value: i32) -> ModelResult {
        match b {
            Var::Maneuver => {
                let m = usize::try_from(value - 1).ok().and_then(|i| Maneuver::ALL.get(i));
                self.scenario.maneuver =
                    *m.ok_or_else(|| format!("maneuver = {value} refused: not one of 1..{}", Maneuver::ALL.len()))?;
            }
            Var::Fidelity => {
                let f = usize::try_from(value - 1).ok().and_then(|i| Fidelity::ALL.get(i));
                self.scenario.fidelity = *f.ok_or_else(|| format!("fidelity = {value} refused: not one of 1..2"))?;
            }
            Var::Seed => {
                self.scenario.seed =
                    u64::try_from(value).map_err(|_| format!("seed = {value} refused: must be >= 0"))?;
            }
            _ => return Err(format!("{b:?} is not an Integer").into()),
        }
        Ok(())
    }

    fn get_boolean(&mut self, b: Var) -> ModelResult<bool> {
        match b {
            Var::FrictionVariation => Ok(self.scenario.friction_variation),
            Var::Wind => Ok(self.scenario.wind),
            Var::MeasurementNoise => Ok(self.scenario.measurement_noise),
            _ => Err(format!("{b:?} is not a Boolean").into()),
        }
    }

    fn set_boolean(&mut self, b: Var, value: bool) -> ModelResult {
        match b {
            Var::FrictionVariation => self.scenario.friction_variation = value,
            Var::Wind => self.scenario.wind = value,
            Var::MeasurementNoise => self.scenario.measurement_noise = value,
            _ => return Err(format!("{b:?} is not a Boolean").into()),
        }
        Ok(())
    }

    /// Computes the reference (and the figure-8 table) unless it is there for these parameters.
    fn exit_initialization(&mut self) -> ModelResult {
        let scenario = self.scenario_now()?;
        if self.bench.as_ref().is_some_and(|b| *b.scenario() == scenario) {
            return Ok(());
        }
        // the process keeps the recent references (they depend on neither the seed nor the
        // switches) and the disturbance tables per seed: many instances compute each once
        self.bench = Some(Arc::new(BenchSampler::prepare(scenario).map_err(|e| e.to_string())?));
        Ok(())
    }

    fn event_update(&mut self, time: f64) -> ModelResult<EventUpdate> {
        let Some(bench) = self.bench.as_ref() else {
            return Err("the reference was not computed (initialization did not end)".into());
        };
        if self.k == 0 {
            self.start_time = time;
        }
        let k = self.k as usize;
        self.held = bench.sample(k, self.beta, self.yaw_rate).ok_or_else(|| {
            format!(
                "t = {time} s is past the benchmark's end: the reference covers {} s (parameter duration)",
                self.duration
            )
        })?;
        self.k += 1;
        // sample instants from the start time and an integer count: no drift
        Ok(EventUpdate::next_at(self.start_time + self.k as f64 * SAMPLE_PERIOD))
    }

    fn save_internal(&self, out: &mut Vec<f64>) {
        out.push(self.k as f64);
        out.push(self.start_time);
    }

    fn load_internal(&mut self, data: &[f64]) -> ModelResult {
        let [k, start_time] = data else {
            return Err(format!("test-bench internal data: 2 numbers expected, got {}", data.len()).into());
        };
        if !(*k >= 0.0 && k.fract() == 0.0 && *k <= MAX_SAMPLES as f64 + 1.0 && start_time.is_finite()) {
            return Err(format!("test-bench internal data {data:?} refused").into());
        }
        self.k = *k as u64;
        self.start_time = *start_time;
        Ok(())
    }
}

#[cfg(feature = "fmi-export")]
fmi2_export::export_fmi2!(TestBench);

/// What the test bench computes, for `documentation/index.html`.
pub const DOCUMENTATION: &str = r#"<h2>Benchmark (docs/benchmark.md)</h2>
<p>Samples k = 0, 1, ... at t_k = t_start + k 1 ms; every output is held over [t_k, t_k + 1 ms).
Steering programs (front +f, rear -f), a = <code>steer_amplitude</code> (30 deg):</p>
<p>The switches <code>maneuver</code> and <code>fidelity</code> are plain Integer parameters (not FMI
Enumerations, so that every importer can set them): <code>maneuver</code> 1 straight, 2 lane_change, 3 skidpad,
4 fishhook, 5 slalom, 6 figure_8; <code>fidelity</code> 1 paper (the sim column), 2 real.</p>
<pre>
straight     0
lane_change  [14.8, 15.0) s: +a;  [15.0, 15.2) s: -a
skidpad      [2.5, 27.5) s: +a
fishhook     [2.5, 25.0) s: a (t - 2.5)/22.5;  [25.0, 27.5) s: a
slalom       [2.5, 27.5) s: a cos(30 pi (t - 2.5)/25)
figure_8     +-a from t = 0, the sign flipping one sample after the nominal paper-fidelity car's closest
             approach to the origin once it has turned 3 pi/2 (first flips at samples 3144, 6267, 9390)
</pre>
<pre>
mu_i   = 0.35 sin(2 pi 12 theta_k - phi_i) + 0.55 + 0.1 u(seed, i, k) - 0.05,  theta_k = 2 pi t_k / 30 s,
         phi = (0, pi/2, pi, 3 pi/2)                       (0.4 with friction_variation off)
wind_y = 0.25 [t_k >= 1 s] + 0.025 u(seed, 4, k)  [N, world frame]   (0 with wind off); wind_x = 0
beta_meas     = beta     + 0.005 g(seed, 5, k)    (real fidelity with measurement_noise on; else beta)
yaw_rate_meas = yaw_rate + 0.01  g(seed, 6, k)
u(seed, s, k) = (mix(((seed &lt;&lt; 8) | s) + (k + 1) 0x9E3779B97F4A7C15) &gt;&gt; 11) 2^-53   (SplitMix64 finaliser)
g(seed, s, k) = sqrt(-2 ln(1 - u(seed, s, 2k))) cos(2 pi u(seed, s, 2k + 1))
</pre>
<p>The reference (<code>beta_ref, yaw_rate_ref, x_ref, y_ref, psi_ref</code>) is computed at the end of
initialization: the open-loop run (K = 0) of the chosen fidelity's plant (nigel-vehicle, RK4 with two 0.5 ms
sub-steps per sample) from the origin at <code>speed_target</code>, with the speed PI of the controller FMU
(kp 53.6, ki 268, |F| &lt;= 20 N), mu = 0.4, no wind, no noise, over <code>duration</code> seconds. A run may not go
past <code>duration</code>. <code>speed_ref</code> outputs <code>speed_target</code>.</p>"#;
