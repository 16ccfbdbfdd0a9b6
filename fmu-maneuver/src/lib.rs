//! The test-bench FMU (`nigel_maneuver`): the benchmark of docs/benchmark.md,
//! [`nigel_benchmark::Benchmark`], behind the shared FMI 2.0 layer. This file is only the
//! binding: the declaration of the variables and a small [`Model`] impl.
//!
//! At the end of initialization the FMU computes, from `nigel-vehicle`, the reference of
//! the chosen fidelity (the nominal open-loop run with the speed loop, 1 ms samples, for
//! `duration` seconds) and, for the figure-8, the switching table from the nominal
//! paper-fidelity run. Then at every sample instant `t_k = t_start + k 1 ms` (the layer's
//! sample clock, [`fmi_export::sampled`]: a time event; inside `fmi2DoStep` in
//! Co-Simulation) it latches the outputs of sample `k` and holds them until `t_(k+1)`. The
//! last sample is at `t = duration`: there the simulation ends (Model Exchange
//! `terminateSimulation`; a Co-Simulation step past it `fmi2Discard` with `fmi2Terminated`),
//! and a stop time past it is refused. `beta_meas` and `yaw_rate_meas` depend directly on the inputs
//! `beta` and `yaw_rate` (declared in the ModelStructure); everything else on `k` alone.

// `!(x > 0.0)` is deliberate: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::sync::Arc;

use core::f64::consts::{FRAC_PI_2, TAU};
use fmi_export::model_description::DefaultExperiment;
use fmi_export::{
    declared_name, Capabilities, DeclarationSpec, Field, InstantiateContext, Interfaces, Model, ModelResult, SampleEnd,
    Variables,
};
use nigel_benchmark::{
    BenchSample, BenchSampler, Benchmark, DisturbanceSettings, Fidelity, Maneuver, Scenario, DEFAULT_SPEED,
    DEFAULT_STEER_AMPLITUDE, MAX_WIND_AMPLITUDE, MU_MAX, SAMPLE_PERIOD, WHEELS,
};

/// The model identifier (file name of the shared library and of the `.fmu`).
pub const MODEL_IDENTIFIER: &str = "nigel_maneuver";

/// Longest reference the FMU computes (10 minutes: 600,000 samples, about 50 MB and 1.5 s
/// at initialization); `duration` above it is refused.
pub const MAX_DURATION: f64 = 600.0;

/// The parameter that ends the benchmark (its last sample is at `t = duration`).
const DURATION: &str = "duration";

/// Slowest `speed_target` [m/s]: the reference and its speed loop need the car moving.
pub const MIN_SPEED_TARGET: f64 = 0.01;

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

/// A held output: name, unit ("" for none), field, description.
type Held = (&'static str, &'static str, fn(&mut TestBench, usize) -> &mut f64, &'static str);
/// A Real parameter: name, start, min, max, unit ("" for none), field, description.
type Parameter = (&'static str, f64, f64, f64, &'static str, fn(&mut TestBench, usize) -> &mut f64, &'static str);

fn build_declaration() -> DeclarationSpec<Field<TestBench>> {
    let mut v = Variables::<Field<TestBench>>::new();
    let beta =
        v.real("beta").input(0.0).unit("rad").describe("the plant's true body slip angle").field(|m, _| &mut m.beta);
    let yaw_rate =
        v.real("yaw_rate").input(0.0).unit("rad/s").describe("the plant's true yaw rate").field(|m, _| &mut m.yaw_rate);
    let steering = "the maneuver's steering program (front +f, rear -f)";
    v.family("delta_ff", &WHEELS, |d, _| d.discrete_output(vec![]).unit("rad").describe(steering))
        .field(|m, i| &mut m.held.delta_ff[i]);
    let friction = "road friction friction_amplitude sin(2 pi friction_frequency theta - friction_phase_i) + \
                    friction_mean + friction_noise (u - 1/2), theta = 2 pi t / 30 s (0.4 when off)";
    #[rustfmt::skip]
    let held: [Held; 10] = [
        ("beta_ref", "rad", |m, _| &mut m.held.beta_ref, "reference body slip angle"),
        ("yaw_rate_ref", "rad/s", |m, _| &mut m.held.yaw_rate_ref, "reference yaw rate"),
        ("speed_ref", "m/s", |m, _| &mut m.held.speed_ref, "speed to hold (the parameter speed_target)"),
        ("x_ref", "m", |m, _| &mut m.held.x_ref, "reference pose: world X"),
        ("y_ref", "m", |m, _| &mut m.held.y_ref, "reference pose: world Y"),
        ("psi_ref", "rad", |m, _| &mut m.held.psi_ref, "reference pose: heading (unwrapped)"),
        ("wind_x", "N", |m, _| &mut m.held.wind_x,
            "wind force along world X: cos(wind_direction) F_w (zero with the default direction)"),
        ("wind_y", "N", |m, _| &mut m.held.wind_y,
            "wind force along world Y: sin(wind_direction) F_w, F_w = wind_amplitude ([t >= wind_start] + wind_noise chi)"),
        ("beta_meas", "rad", |m, _| &mut m.held.beta_meas,
            "what the controller measures: beta (+ beta_noise g in the real fidelity)"),
        ("yaw_rate_meas", "rad/s", |m, _| &mut m.held.yaw_rate_meas,
            "what the controller measures: yaw rate (+ yaw_rate_noise g in the real fidelity)"),
    ];
    // beta_meas and yaw_rate_meas feed the inputs through; the others depend on the sample alone
    let feedthrough = [vec![], vec![], vec![], vec![], vec![], vec![], vec![], vec![], vec![beta], vec![yaw_rate]];
    let mut held = held.into_iter().zip(feedthrough);
    let output = |v: &mut Variables<_>, ((name, unit, field, text), on): (Held, Vec<_>)| {
        v.real(name).discrete_output(on).unit(unit).describe(text).field(field);
    };
    held.by_ref().take(6).for_each(|row| output(&mut v, row));
    v.family("mu", &WHEELS, |d, _| d.discrete_output(vec![]).describe(friction)).field(|m, i| &mut m.held.mu[i]);
    held.for_each(|row| output(&mut v, row));
    let ds = DisturbanceSettings::default();
    #[rustfmt::skip]
    let parameters: [Parameter; 13] = [
        ("steer_amplitude", DEFAULT_STEER_AMPLITUDE, 0.0, FRAC_PI_2, "rad", |m, _| &mut m.scenario.steer_amplitude,
            "amplitude a of the steering programs (30 deg)"),
        ("speed_target", DEFAULT_SPEED, MIN_SPEED_TARGET, 10.0, "m/s", |m, _| &mut m.scenario.speed_ref,
            "speed the reference holds and the output speed_ref gives (start speed of the reference)"),
        (DURATION, 30.0, SAMPLE_PERIOD, MAX_DURATION, "s", |m, _| &mut m.duration,
            "length of the reference computed at initialization (30 s); a run may not go past it"),
        // the disturbance settings: the paper's values as start values
        ("friction_mean", ds.friction_mean, 0.0, MU_MAX, "", |m, _| &mut m.settings().friction_mean,
            "friction the sinusoid oscillates around (0.55); friction_mean -+ (friction_amplitude + \
             friction_noise / 2) must stay in [0, 3]"),
        ("friction_amplitude", ds.friction_amplitude, 0.0, MU_MAX, "", |m, _| &mut m.settings().friction_amplitude,
            "amplitude of the friction sinusoid (0.35)"),
        ("friction_frequency", ds.friction_frequency, 0.0, 1000.0, "", |m, _| &mut m.settings().friction_frequency,
            "factor f of theta = 2 pi t / 30 s in the sinusoid's argument 2 pi f theta (12: about 75 periods in 30 s)"),
        ("friction_noise", ds.friction_noise, 0.0, 2.0 * MU_MAX, "", |m, _| &mut m.settings().friction_noise,
            "width of the uniform friction noise, centred on zero (0.1: -0.05 .. 0.05)"),
        ("wind_amplitude", ds.wind_amplitude, 0.0, MAX_WIND_AMPLITUDE, "N", |m, _| &mut m.settings().wind_amplitude,
            "wind step from wind_start (0.25 N)"),
        ("wind_noise", ds.wind_noise, 0.0, 10.0, "", |m, _| &mut m.settings().wind_noise,
            "uniform wind noise from t = 0, relative to wind_amplitude (0.1)"),
        ("wind_direction", ds.wind_direction, -TAU, TAU, "rad", |m, _| &mut m.settings().wind_direction,
            "direction the wind blows towards in the world frame, from +X towards +Y (pi/2: along +Y)"),
        ("wind_start", ds.wind_start, 0.0, MAX_DURATION, "s", |m, _| &mut m.settings().wind_start,
            "time the wind step starts, at the nearest 1 ms sample (1 s)"),
        ("beta_noise", ds.beta_noise, 0.0, 1.0, "rad", |m, _| &mut m.settings().beta_noise,
            "standard deviation of the Gaussian noise on beta_meas (0.005 rad; real fidelity only)"),
        ("yaw_rate_noise", ds.yaw_rate_noise, 0.0, 10.0, "rad/s", |m, _| &mut m.settings().yaw_rate_noise,
            "standard deviation of the Gaussian noise on yaw_rate_meas (0.01 rad/s; real fidelity only)"),
    ];
    let parameter = |v: &mut Variables<_>, &(name, start, min, max, unit, field, text): &Parameter| {
        v.real(name).parameter(start).min(min).max(max).unit(unit).describe(text).field(field);
    };
    let (scenario, settings) = parameters.split_at(3);
    scenario.iter().for_each(|row| parameter(&mut v, row));
    switches(&mut v);
    settings.iter().for_each(|row| parameter(&mut v, row));
    v.family("friction_phase", &WHEELS, |d, i| {
        d.parameter(ds.friction_phase[i])
            .min(-2.0 * TAU)
            .max(2.0 * TAU)
            .unit("rad")
            .describe("phase of the wheel's friction sinusoid (FL 0, FR pi/2, RL pi, RR 3 pi/2)")
    })
    .field(|m, i| &mut m.settings().friction_phase[i]);
    DeclarationSpec {
        model_name: "nigel_maneuver",
        model_identifier: MODEL_IDENTIFIER,
        description:
            "Benchmark test bench of docs/benchmark.md: steering programs, reference (nominal open-loop run), \
                      friction and wind disturbances, measurement noise (counter-based SplitMix64)",
        version: env!("CARGO_PKG_VERSION"),
        interfaces: Interfaces { model_exchange: true, co_simulation: true },
        capabilities: Capabilities { fmu_state: true, serialize_fmu_state: true, directional_derivatives: false },
        default_experiment: Some(DefaultExperiment::fixed_step(30.0, SAMPLE_PERIOD)),
        variables: v.into_vec(),
        ..Default::default()
    }
}

/// The Integer parameter `$field` of the scenario choosing one of `$choice::ALL` by its
/// 1-based position (`$value`): declared 1 .. the number of choices, starting at `$start`,
/// described by `$items`; a value outside is refused with `$refusal` (a macro: the getter
/// and setter are plain functions, one pair per field).
macro_rules! choice_parameter {
    ($v:expr, $field:ident: $choice:ident = $start:expr, $value:ident, $items:expr, $refusal:literal) => {
        $v.integer(stringify!($field))
            .parameter($value($start))
            .min(1.0)
            .max($choice::ALL.len() as f64)
            .describe($items)
            .get_set(
                |m, _| $value(m.scenario.$field),
                |m, _, x| {
                    m.scenario.$field = *$choice::ALL.get(x as usize - 1).ok_or($refusal)?;
                    Ok(())
                },
            )
    };
}

/// The Integer and Boolean parameters.
fn switches(v: &mut Variables<Field<TestBench>>) {
    // the switches: the declared ranges (1 .. the number of items, seed >= 0) make each
    // conversion exact, so the setters never refuse what the layer let through
    choice_parameter!(v, maneuver: Maneuver = Maneuver::Straight, maneuver_value, maneuver_items(), "not a maneuver");
    choice_parameter!(v, fidelity: Fidelity = Fidelity::Paper, fidelity_value, fidelity_items(), "not a fidelity");
    v.integer("seed").parameter(0).min(0.0).describe("seed of every noise stream (counter-based SplitMix64)").get_set(
        |m, _| m.scenario.seed as i32,
        |m, _, x| {
            m.scenario.seed = u64::try_from(x).map_err(|_| "a seed is >= 0")?;
            Ok(())
        },
    );
    v.boolean("friction_variation")
        .parameter(true)
        .describe("friction sinusoids plus noise (else mu = 0.4)")
        .field(|m, _| &mut m.scenario.friction_variation);
    v.boolean("wind").parameter(true).describe("wind along world +Y").field(|m, _| &mut m.scenario.wind);
    v.boolean("measurement_noise")
        .parameter(true)
        .describe("Gaussian noise on beta_meas, yaw_rate_meas (real fidelity only)")
        .field(|m, _| &mut m.scenario.measurement_noise);
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

    fn settings(&mut self) -> &mut DisturbanceSettings {
        &mut self.scenario.disturbance_settings
    }

    /// The sample at `t = duration`: the reference covers samples `0 ..= last`.
    fn last_sample(&self) -> u64 {
        (self.duration / SAMPLE_PERIOD).round() as u64
    }
}

impl Model for TestBench {
    type Binding = Field<TestBench>;

    fmi_export::declare_model!(Field<TestBench>, build_declaration());

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
        Some(SampleEnd { last: self.last_sample(), variable: DURATION })
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
fmi_export::export_fmi!(TestBench);

/// What the test bench computes, for `documentation/index.html`.
pub const DOCUMENTATION: &str = include_str!("documentation.html");
