//! What one benchmark run is: the maneuver, the column (plant fidelity), the steering
//! program per sample and the disturbances per sample (docs/benchmark.md).

use core::f64::consts::{FRAC_PI_2, PI, TAU};
use core::fmt;

use nigel_vehicle::VehicleParams;

use crate::noise::{g, u, STREAM_BETA, STREAM_FRICTION, STREAM_WIND, STREAM_YAW_RATE};

/// The sample period of the benchmark, 1 ms \[s\].
pub const SAMPLE_PERIOD: f64 = 1e-3;
/// Samples per run: `k = 0 .. 29999`, 30 s.
pub const N_SAMPLES: usize = 30_000;
/// Largest run accepted (10^4 s): bounds the memory of a reference (48 bytes a sample).
pub const MAX_SAMPLES: usize = 10_000_000;
/// The speed the PI holds and the start speed [m/s].
pub const DEFAULT_SPEED: f64 = 0.35;
/// Steering amplitude `a` of the programs, 30 deg \[rad\].
pub const DEFAULT_STEER_AMPLITUDE: f64 = PI / 6.0;
/// Nominal friction of the reference run (and of every wheel with the friction variation off).
pub const MU_NOMINAL: f64 = 0.4;

/// The six maneuvers of Table III.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Maneuver {
    /// No steering.
    Straight,
    /// Impulse: `[14.8, 15.0)` front +a / rear -a, `[15.0, 15.2)` front -a / rear +a.
    LaneChange,
    /// Step: `[2.5, 27.5)` front +a / rear -a.
    Skidpad,
    /// Ramp: `[2.5, 25.0)` front 0 -> +a (rear 0 -> -a), `[25.0, 27.5)` hold.
    Fishhook,
    /// Sine: `[2.5, 27.5)` front `a cos(theta)`, rear `-a cos(theta)`, theta 0 -> 30 pi.
    Slalom,
    /// Square wave from t = 0: front +a / rear -a, the sign flipping at the switching table.
    Figure8,
}

impl Maneuver {
    /// In the order of Table III (and of the FMU enumeration).
    pub const ALL: [Maneuver; 6] = [
        Maneuver::Straight,
        Maneuver::LaneChange,
        Maneuver::Skidpad,
        Maneuver::Fishhook,
        Maneuver::Slalom,
        Maneuver::Figure8,
    ];

    /// `straight`, `lane_change`, `skidpad`, `fishhook`, `slalom`, `figure_8`.
    pub fn name(&self) -> &'static str {
        match self {
            Maneuver::Straight => "straight",
            Maneuver::LaneChange => "lane_change",
            Maneuver::Skidpad => "skidpad",
            Maneuver::Fishhook => "fishhook",
            Maneuver::Slalom => "slalom",
            Maneuver::Figure8 => "figure_8",
        }
    }

    /// The inverse of [`Maneuver::name`].
    pub fn from_name(name: &str) -> Option<Maneuver> {
        Maneuver::ALL.into_iter().find(|m| m.name() == name)
    }
}

impl fmt::Display for Maneuver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The plant fidelity of a column of Table III.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Fidelity {
    /// The "sim" column: Table II, paper fidelity; the controller sees the true beta and r.
    Paper,
    /// The "real" column: Table II with friction circle, steering servo and motor limit; the
    /// controller sees beta and r with Gaussian measurement noise.
    Real,
}

impl Fidelity {
    /// Both, in the order of Table III.
    pub const ALL: [Fidelity; 2] = [Fidelity::Paper, Fidelity::Real];

    /// `paper` or `real` (the FMU enumeration's names).
    pub fn name(&self) -> &'static str {
        match self {
            Fidelity::Paper => "paper",
            Fidelity::Real => "real",
        }
    }

    /// The column heading of Table III: `sim` or `real`.
    pub fn column(&self) -> &'static str {
        match self {
            Fidelity::Paper => "sim",
            Fidelity::Real => "real",
        }
    }

    /// The plant of the column: [`VehicleParams::table2`] or [`VehicleParams::real_fidelity`].
    ///
    /// Not [`VehicleParams::paper_synthesis`]: that geometry (`l_r = 0.07924`) is the
    /// authors' design model only; the car the controllers drive is Table II.
    pub fn params(&self) -> VehicleParams {
        match self {
            Fidelity::Paper => VehicleParams::table2(),
            Fidelity::Real => VehicleParams::real_fidelity(),
        }
    }
}

/// A refused benchmark setting: which value, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct SettingError {
    /// The variable's name (as in the FMUs).
    pub name: &'static str,
    /// The value given.
    pub value: f64,
    /// What is wrong with it.
    pub reason: &'static str,
}

impl fmt::Display for SettingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {} is invalid: {}", self.name, self.value, self.reason)
    }
}

impl std::error::Error for SettingError {}

/// Everything that defines one benchmark run except the controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scenario {
    /// The maneuver.
    pub maneuver: Maneuver,
    /// The column: the plant the reference and the closed loop use, and the measurement noise.
    pub fidelity: Fidelity,
    /// Seed of every noise stream.
    pub seed: u64,
    /// Friction sinusoids plus noise on (else `mu_i = 0.4`).
    pub friction_variation: bool,
    /// Wind along `disturbance_settings.wind_direction` on (else none).
    pub wind: bool,
    /// Measurement noise on beta and r; only the real fidelity measures with noise.
    pub measurement_noise: bool,
    /// The numbers in the disturbance formulas (the paper's by default).
    pub disturbance_settings: DisturbanceSettings,
    /// Steering amplitude `a` \[rad\], in `[0, pi/2]`.
    pub steer_amplitude: f64,
    /// Speed held by the PI, and the start speed [m/s].
    pub speed_ref: f64,
    /// Samples of 1 ms to run (30,000).
    pub n_samples: usize,
}

impl Scenario {
    /// The definition of docs/benchmark.md: seed 0, every disturbance on, 30 deg, 0.35 m/s, 30 s.
    pub fn new(maneuver: Maneuver, fidelity: Fidelity) -> Self {
        Scenario {
            maneuver,
            fidelity,
            seed: 0,
            friction_variation: true,
            wind: true,
            measurement_noise: true,
            disturbance_settings: DisturbanceSettings::default(),
            steer_amplitude: DEFAULT_STEER_AMPLITUDE,
            speed_ref: DEFAULT_SPEED,
            n_samples: N_SAMPLES,
        }
    }

    /// The same maneuver and plant with every disturbance off.
    pub fn undisturbed(self) -> Self {
        Scenario { friction_variation: false, wind: false, measurement_noise: false, ..self }
    }

    /// Refuses NaN, infinite and out-of-range values, naming the variable.
    pub fn validate(&self) -> Result<(), SettingError> {
        let a = self.steer_amplitude;
        if !(a.is_finite() && (0.0..=FRAC_PI_2).contains(&a)) {
            return Err(SettingError { name: "steer_amplitude", value: a, reason: "must be in [0, pi/2] rad" });
        }
        let v = self.speed_ref;
        if !(v.is_finite() && v > 0.0 && v <= 10.0) {
            return Err(SettingError { name: "speed_ref", value: v, reason: "must be in (0, 10] m/s" });
        }
        if self.n_samples == 0 || self.n_samples > MAX_SAMPLES {
            return Err(SettingError {
                name: "n_samples",
                value: self.n_samples as f64,
                reason: "must be in [1, 10^7] (1 ms samples)",
            });
        }
        if self.seed > (u64::MAX >> 8) {
            return Err(SettingError { name: "seed", value: self.seed as f64, reason: "must be < 2^56" });
        }
        self.disturbance_settings.validate()
    }

    /// The disturbances of this scenario.
    pub fn disturbances(&self) -> Disturbances {
        Disturbances {
            seed: self.seed,
            friction_variation: self.friction_variation,
            wind: self.wind,
            measurement_noise: self.measurement_noise && self.fidelity == Fidelity::Real,
            settings: self.disturbance_settings,
        }
    }
}

/// The steering program of a maneuver, per sample (`[FL, FR, RL, RR]`, always front `+f`,
/// rear `-f`: out-of-phase all-wheel steer).
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// The maneuver.
    pub maneuver: Maneuver,
    /// Amplitude `a` \[rad\].
    pub amplitude: f64,
    /// Figure-8 only: the samples at which the sign flips (ascending); empty otherwise.
    pub switches: Vec<usize>,
}

impl Program {
    /// A program; a figure-8 needs its switching table ([`crate::figure8_switches`]).
    pub fn new(maneuver: Maneuver, amplitude: f64, switches: Vec<usize>) -> Self {
        Program { maneuver, amplitude, switches }
    }

    /// The front steering angle at sample `k` (the rear is its negative) \[rad\].
    pub fn front(&self, k: usize) -> f64 {
        let a = self.amplitude;
        // sample boundaries in integer milliseconds: no rounding at 14.8 s or 2.5 s
        match self.maneuver {
            Maneuver::Straight => 0.0,
            Maneuver::LaneChange => match k {
                14_800..=14_999 => a,
                15_000..=15_199 => -a,
                _ => 0.0,
            },
            Maneuver::Skidpad => match k {
                2_500..=27_499 => a,
                _ => 0.0,
            },
            Maneuver::Fishhook => match k {
                2_500..=24_999 => a * ((k - 2_500) as f64 * SAMPLE_PERIOD / 22.5),
                25_000..=27_499 => a,
                _ => 0.0,
            },
            Maneuver::Slalom => match k {
                2_500..=27_499 => a * (30.0 * PI * ((k - 2_500) as f64 * SAMPLE_PERIOD / 25.0)).cos(),
                _ => 0.0,
            },
            Maneuver::Figure8 => figure8_sign(&self.switches, k) * a,
        }
    }

    /// `[FL, FR, RL, RR]` at sample `k` \[rad\].
    pub fn steering(&self, k: usize) -> [f64; 4] {
        let f = self.front(k);
        [f, f, -f, -f]
    }
}

/// `+1` before the first switch, flipping at every switch sample (a switch at `k` applies from `k` on).
pub fn figure8_sign(switches: &[usize], k: usize) -> f64 {
    if switches.partition_point(|&s| s <= k) % 2 == 0 {
        1.0
    } else {
        -1.0
    }
}

/// Largest friction coefficient a disturbance may give (the plant's declared range of `mu`).
pub const MU_MAX: f64 = 3.0;
/// Largest wind amplitude accepted \[N\] (some 10 g of the 2.68 kg car).
pub const MAX_WIND_AMPLITUDE: f64 = 250.0;

/// The numbers in the disturbance formulas of docs/benchmark.md; [`Default`] is the paper's
/// values (Table III), which give exactly the sequences of those formulas.
///
/// Friction of wheel `i`: `mu_i = A_mu sin(2 pi f theta_k - phi_i) + mu_mean + w_mu (u - 1/2)`,
/// `theta_k = 2 pi t_k / 30 s`. Wind: `F_w = A_w [k >= k_w] + r_w A_w chi_k` along the world
/// direction `dir` (`wind_x = cos(dir) F_w`, `wind_y = sin(dir) F_w`), `k_w` the sample
/// nearest `wind_start`. Measurement noise: `beta + s_beta g`, `r + s_r g`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisturbanceSettings {
    /// `mu_mean`, the friction the sinusoid oscillates around (0.55).
    pub friction_mean: f64,
    /// `A_mu`, the amplitude of the friction sinusoid (0.35).
    pub friction_amplitude: f64,
    /// `f`, the factor of `theta` in the sinusoid's argument `2 pi f theta` (12: about 75
    /// periods per 30 s run) \[1\].
    pub friction_frequency: f64,
    /// `w_mu`, the width of the uniform friction noise, centred on zero (0.1).
    pub friction_noise: f64,
    /// `phi_i`, the phase of the sinusoid per wheel FL, FR, RL, RR \[rad\] (0, pi/2, pi, 3 pi/2).
    pub friction_phase: [f64; 4],
    /// `A_w`, the wind step \[N\] (0.25).
    pub wind_amplitude: f64,
    /// `r_w`, the uniform wind noise relative to `A_w`, on from t = 0 (0.1).
    pub wind_noise: f64,
    /// `dir`, the direction the wind blows towards in the world frame, from +X towards +Y \[rad\]
    /// (pi/2: along +Y).
    pub wind_direction: f64,
    /// When the wind step starts \[s\] (1 s).
    pub wind_start: f64,
    /// `s_beta`, the standard deviation of the noise on the measured beta \[rad\] (0.005).
    pub beta_noise: f64,
    /// `s_r`, the standard deviation of the noise on the measured yaw rate [rad/s] (0.01).
    pub yaw_rate_noise: f64,
}

impl Default for DisturbanceSettings {
    fn default() -> Self {
        DisturbanceSettings {
            friction_mean: 0.55,
            friction_amplitude: 0.35,
            friction_frequency: 12.0,
            friction_noise: 0.1,
            friction_phase: FRICTION_PHASE,
            wind_amplitude: 0.25,
            wind_noise: 0.1,
            wind_direction: FRAC_PI_2,
            wind_start: 1.0,
            beta_noise: 0.005,
            yaw_rate_noise: 0.01,
        }
    }
}

/// The FMU names of the per-wheel friction phases.
const FRICTION_PHASE_NAMES: [&str; 4] =
    ["friction_phase_fl", "friction_phase_fr", "friction_phase_rl", "friction_phase_rr"];

impl DisturbanceSettings {
    /// Refuses NaN, infinite and out-of-range values, naming the variable (as in the FMU).
    pub fn validate(&self) -> Result<(), SettingError> {
        let check = |name: &'static str, value: f64, ok: bool, reason: &'static str| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(SettingError { name, value, reason })
            }
        };
        let s = self;
        check("friction_amplitude", s.friction_amplitude, s.friction_amplitude >= 0.0, "must be >= 0")?;
        check("friction_noise", s.friction_noise, s.friction_noise >= 0.0, "must be >= 0")?;
        check(
            "friction_frequency",
            s.friction_frequency,
            (0.0..=1000.0).contains(&s.friction_frequency),
            "must be in [0, 1000]",
        )?;
        for (name, phase) in FRICTION_PHASE_NAMES.into_iter().zip(s.friction_phase) {
            check(name, phase, phase.abs() <= 2.0 * TAU, "must be in [-4 pi, 4 pi] rad")?;
        }
        let swing = s.friction_amplitude + 0.5 * s.friction_noise;
        check(
            "friction_mean",
            s.friction_mean,
            s.friction_mean - swing >= 0.0,
            "friction_mean - friction_amplitude - friction_noise / 2 must be >= 0 (the lowest friction)",
        )?;
        check(
            "friction_mean",
            s.friction_mean,
            s.friction_mean + swing <= MU_MAX,
            "friction_mean + friction_amplitude + friction_noise / 2 must be <= 3 (the plant's largest mu)",
        )?;
        check(
            "wind_amplitude",
            s.wind_amplitude,
            (0.0..=MAX_WIND_AMPLITUDE).contains(&s.wind_amplitude),
            "must be in [0, 250] N",
        )?;
        check(
            "wind_noise",
            s.wind_noise,
            (0.0..=10.0).contains(&s.wind_noise),
            "must be in [0, 10] (relative to wind_amplitude)",
        )?;
        check("wind_direction", s.wind_direction, s.wind_direction.abs() <= TAU, "must be in [-2 pi, 2 pi] rad")?;
        check("wind_start", s.wind_start, s.wind_start >= 0.0, "must be >= 0 s")?;
        check("beta_noise", s.beta_noise, (0.0..=1.0).contains(&s.beta_noise), "must be in [0, 1] rad")?;
        check(
            "yaw_rate_noise",
            s.yaw_rate_noise,
            (0.0..=10.0).contains(&s.yaw_rate_noise),
            "must be in [0, 10] rad/s",
        )?;
        Ok(())
    }

    /// The bits of every number: the key of the disturbance-table cache (two settings share a
    /// table only if every formula gives the same bits).
    fn key(&self) -> [u64; 14] {
        let s = self;
        let p = s.friction_phase;
        [
            s.friction_mean,
            s.friction_amplitude,
            s.friction_frequency,
            s.friction_noise,
            p[0],
            p[1],
            p[2],
            p[3],
            s.wind_amplitude,
            s.wind_noise,
            s.wind_direction,
            s.wind_start,
            s.beta_noise,
            s.yaw_rate_noise,
        ]
        .map(f64::to_bits)
    }

    /// `(cos dir, sin dir)`, exact at the quarter turns: `cos(pi/2)` of the f64 nearest pi/2 is
    /// 6e-17, not 0, and the wind along +Y (the default) has no X component.
    fn wind_unit(&self) -> (f64, f64) {
        let d = self.wind_direction;
        let quarter = d / FRAC_PI_2;
        let q = quarter.round();
        if d == q * FRAC_PI_2 {
            // 0, pi/2, pi, 3 pi/2 (and their negatives, and 2 pi) as f64
            match (q as i64).rem_euclid(4) {
                0 => (1.0, 0.0),
                1 => (0.0, 1.0),
                2 => (-1.0, 0.0),
                _ => (0.0, -1.0),
            }
        } else {
            let (s, c) = d.sin_cos();
            (c, s)
        }
    }

    /// The first sample of the wind step: the one nearest `wind_start`.
    fn wind_start_sample(&self) -> u64 {
        // validated finite and >= 0; `as` saturates a huge start to "never"
        (self.wind_start / SAMPLE_PERIOD).round() as u64
    }
}

/// The disturbances of a run, per sample (pure functions of the sample index).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disturbances {
    /// Seed of every stream.
    pub seed: u64,
    /// Friction sinusoids plus noise (else 0.4).
    pub friction_variation: bool,
    /// Wind along `settings.wind_direction` (else zero).
    pub wind: bool,
    /// Gaussian noise on the measured beta and r.
    pub measurement_noise: bool,
    /// The numbers in the formulas.
    pub settings: DisturbanceSettings,
}

/// Phase of the friction sinusoid per wheel, FL, FR, RL, RR.
pub const FRICTION_PHASE: [f64; 4] = [0.0, FRAC_PI_2, PI, 1.5 * PI];

impl Disturbances {
    /// Nothing: `mu = 0.4`, no wind, true measurements (the reference run).
    pub fn none() -> Self {
        Disturbances {
            seed: 0,
            friction_variation: false,
            wind: false,
            measurement_noise: false,
            settings: DisturbanceSettings::default(),
        }
    }

    /// Road friction per wheel at sample `k`:
    /// `mu_i = A_mu sin(2 pi f theta_k - phi_i) + mu_mean + (w_mu u - w_mu / 2)`, `theta_k = 2 pi t_k / 30 s`
    /// (by default `0.35 sin(2 pi 12 theta_k - phi_i) + 0.55 + (0.1 u - 0.05)`).
    pub fn friction(&self, k: usize) -> [f64; 4] {
        if !self.friction_variation {
            return [MU_NOMINAL; 4];
        }
        let s = &self.settings;
        let t = k as f64 * SAMPLE_PERIOD;
        let theta = 2.0 * PI * t / 30.0;
        // 0.5 w is exact, so the default 0.1 gives the 0.05 of the paper's formula bit for bit
        let half_width = 0.5 * s.friction_noise;
        let mut mu = [0.0; 4];
        for i in 0..4 {
            let noise = s.friction_noise * u(self.seed, STREAM_FRICTION[i], k as u64) - half_width;
            mu[i] = s.friction_amplitude * (2.0 * PI * s.friction_frequency * theta - s.friction_phase[i]).sin()
                + s.friction_mean
                + noise;
        }
        mu
    }

    /// The wind's size at sample `k` [N]: `F_w = A_w [k >= k_w] + r_w A_w chi_k` (by default
    /// `0.25 [t_k >= 1 s] + 0.025 chi_k`), whatever the switch.
    fn wind_force(&self, k: usize) -> f64 {
        let s = &self.settings;
        let gust = if k as u64 >= s.wind_start_sample() { s.wind_amplitude } else { 0.0 };
        gust + s.wind_noise * s.wind_amplitude * u(self.seed, STREAM_WIND, k as u64)
    }

    /// Wind force `[along world X, along world Y]` at sample `k` \[N\]:
    /// `F_w (cos dir, sin dir)` (by default `(0, F_w)`, exactly).
    pub fn wind(&self, k: usize) -> [f64; 2] {
        if !self.wind {
            return [0.0; 2];
        }
        along(self.settings.wind_unit(), self.wind_force(k))
    }

    /// What the controller measures at sample `k`: `(beta + s_beta g, r + s_r g)` (by default
    /// `(beta + 0.005 g, r + 0.01 g)`) with the noise on, else the true values.
    pub fn measure(&self, k: usize, beta: f64, yaw_rate: f64) -> (f64, f64) {
        if !self.measurement_noise {
            return (beta, yaw_rate);
        }
        with_noise(&self.settings, beta, yaw_rate, measurement_noise(self.seed, k))
    }
}

/// The wind `force` along the unit vector `(c, s)`.
#[inline]
fn along((c, s): (f64, f64), force: f64) -> [f64; 2] {
    [c * force, s * force]
}

/// The unscaled measurement noise of sample `k`: `g(seed, 5, k)`, `g(seed, 6, k)`.
#[inline]
fn measurement_noise(seed: u64, k: usize) -> [f64; 2] {
    [g(seed, STREAM_BETA, k as u64), g(seed, STREAM_YAW_RATE, k as u64)]
}

/// `(beta + s_beta noise_0, r + s_r noise_1)`: what the controller measures.
#[inline]
fn with_noise(settings: &DisturbanceSettings, beta: f64, yaw_rate: f64, noise: [f64; 2]) -> (f64, f64) {
    (beta + settings.beta_noise * noise[0], yaw_rate + settings.yaw_rate_noise * noise[1])
}

/// How many (seed, settings) disturbance tables [`DisturbanceSequence::new`] keeps for the process.
pub const DISTURBANCE_CACHE_SIZE: usize = 4;

/// Samples a disturbance table covers at most (60 s): about 3.4 MB a seed, so the cache
/// stays below some 14 MB. Samples beyond it come from the formulas.
pub const DISTURBANCE_TABLE_MAX_SAMPLES: usize = 60_001;

/// One sample of the disturbance streams of a seed and settings, every switch on.
#[derive(Clone, Copy, Debug, PartialEq)]
struct DisturbanceRow {
    /// [`Disturbances::friction`] with the variation on.
    mu: [f64; 4],
    /// The wind's size `F_w` (its direction is applied on reading, as the formula does).
    wind_force: f64,
    /// `g(seed, 5, k)` and `g(seed, 6, k)`, the measurement noise before its scale.
    noise: [f64; 2],
}

/// Every disturbance of one seed and settings for the samples `0 .. rows.len()`, every switch on.
#[derive(Debug, PartialEq)]
struct DisturbanceTable {
    seed: u64,
    settings: DisturbanceSettings,
    rows: Vec<DisturbanceRow>,
}

impl DisturbanceTable {
    fn compute(seed: u64, settings: DisturbanceSettings, len: usize) -> Self {
        let on = Disturbances { seed, friction_variation: true, wind: true, measurement_noise: true, settings };
        let rows = (0..len)
            .map(|k| DisturbanceRow {
                mu: on.friction(k),
                wind_force: on.wind_force(k),
                noise: measurement_noise(seed, k),
            })
            .collect();
        DisturbanceTable { seed, settings, rows }
    }
}

/// What a cached table is for: the seed, the bits of the settings, the length.
type DisturbanceKey = (u64, [u64; 14], usize);

/// One table of the cache: empty while (or if) it is being computed; its own lock makes a
/// second thread asking for the same seed wait for the first one's table.
type DisturbanceSlot = std::sync::Arc<std::sync::Mutex<Option<std::sync::Arc<DisturbanceTable>>>>;

/// The most recently used tables, newest last, keyed by seed, settings and length.
type DisturbanceCache = std::sync::Mutex<Vec<(DisturbanceKey, DisturbanceSlot)>>;

fn disturbance_cache() -> &'static DisturbanceCache {
    static CACHE: std::sync::OnceLock<DisturbanceCache> = std::sync::OnceLock::new();
    CACHE.get_or_init(|| std::sync::Mutex::new(Vec::new()))
}

/// The table of `seed` and `settings` over `len` samples, from the cache or computed (and kept).
fn disturbance_table(seed: u64, settings: DisturbanceSettings, len: usize) -> std::sync::Arc<DisturbanceTable> {
    let key = (seed, settings.key(), len);
    let slot = {
        let mut entries = disturbance_cache().lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        match entries.iter().position(|(k, _)| *k == key) {
            Some(i) => {
                // most recently used last
                let entry = entries.remove(i);
                let slot = entry.1.clone();
                entries.push(entry);
                slot
            }
            None => {
                if entries.len() >= DISTURBANCE_CACHE_SIZE {
                    entries.remove(0);
                }
                let slot = DisturbanceSlot::default();
                entries.push((key, slot.clone()));
                slot
            }
        }
    };
    // held while computing: a concurrent request for the same table waits for it
    let mut cached = slot.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    cached.get_or_insert_with(|| std::sync::Arc::new(DisturbanceTable::compute(seed, settings, len))).clone()
}

/// The disturbances of a run read from a table computed once per seed, settings and process
/// (Table III runs 3 or 4 controllers on 6 maneuvers and 2 columns with the same seed, and
/// every sample draws 4 sines, 2 logarithms, 2 cosines and 9 hashes). Every value is
/// exactly (bit for bit) what the per-sample formulas of [`Disturbances`] give: the table
/// holds those formulas' own results, and samples beyond it are computed by them.
#[derive(Clone, Debug, PartialEq)]
pub struct DisturbanceSequence {
    disturbances: Disturbances,
    /// `None` with every switch off (nothing to look up).
    table: Option<std::sync::Arc<DisturbanceTable>>,
}

impl DisturbanceSequence {
    /// The disturbances `d` of a run of `n_samples` samples: the table covers the samples
    /// `0 ..= n_samples` (the last one is what a test bench holds at the end), at most
    /// [`DISTURBANCE_TABLE_MAX_SAMPLES`]; any other sample comes from the formulas.
    pub fn new(d: Disturbances, n_samples: usize) -> Self {
        let any = d.friction_variation || d.wind || d.measurement_noise;
        let len = n_samples.saturating_add(1).min(DISTURBANCE_TABLE_MAX_SAMPLES);
        let table = any.then(|| disturbance_table(d.seed, d.settings, len));
        DisturbanceSequence { disturbances: d, table }
    }

    /// The switches, the seed and the settings.
    pub fn disturbances(&self) -> &Disturbances {
        &self.disturbances
    }

    #[inline]
    fn row(&self, k: usize) -> Option<&DisturbanceRow> {
        self.table.as_ref()?.rows.get(k)
    }

    /// [`Disturbances::friction`] at sample `k`.
    #[inline]
    pub fn friction(&self, k: usize) -> [f64; 4] {
        if !self.disturbances.friction_variation {
            return [MU_NOMINAL; 4];
        }
        match self.row(k) {
            Some(row) => row.mu,
            None => self.disturbances.friction(k),
        }
    }

    /// [`Disturbances::wind`] at sample `k` \[N\].
    #[inline]
    pub fn wind(&self, k: usize) -> [f64; 2] {
        if !self.disturbances.wind {
            return [0.0; 2];
        }
        match self.row(k) {
            Some(row) => along(self.disturbances.settings.wind_unit(), row.wind_force),
            None => self.disturbances.wind(k),
        }
    }

    /// [`Disturbances::measure`] at sample `k`.
    #[inline]
    pub fn measure(&self, k: usize, beta: f64, yaw_rate: f64) -> (f64, f64) {
        if !self.disturbances.measurement_noise {
            return (beta, yaw_rate);
        }
        match self.row(k) {
            Some(row) => with_noise(&self.disturbances.settings, beta, yaw_rate, row.noise),
            None => self.disturbances.measure(k, beta, yaw_rate),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bits(x: [f64; 4]) -> [u64; 4] {
        x.map(f64::to_bits)
    }

    /// The table holds the formulas' own numbers: every sample, every switch combination,
    /// bit for bit, and past the table's end the formulas themselves.
    #[test]
    fn disturbance_sequence_is_the_formulas_bit_for_bit() {
        for seed in [0, 7, (1 << 40) + 3] {
            for switches in 0..8u8 {
                let d = Disturbances {
                    seed,
                    friction_variation: switches & 1 != 0,
                    wind: switches & 2 != 0,
                    measurement_noise: switches & 4 != 0,
                    settings: DisturbanceSettings::default(),
                };
                let n = 2_000;
                let seq = DisturbanceSequence::new(d, n);
                assert_eq!(seq.disturbances(), &d);
                // beyond the table (n + 1 samples) too
                for k in (0..=n + 50).chain([N_SAMPLES, 10 * N_SAMPLES]) {
                    assert_eq!(bits(seq.friction(k)), bits(d.friction(k)), "seed {seed} switches {switches} k {k}");
                    assert_eq!(seq.wind(k).map(f64::to_bits), d.wind(k).map(f64::to_bits), "k {k}");
                    let (beta, yaw_rate) = (0.01 * k as f64 - 3.0, -0.2);
                    let (a, b) = (seq.measure(k, beta, yaw_rate), d.measure(k, beta, yaw_rate));
                    assert_eq!((a.0.to_bits(), a.1.to_bits()), (b.0.to_bits(), b.1.to_bits()), "k {k}");
                }
            }
        }
    }

    /// A whole 30 s run of the default scenario: the table against the formulas (and the
    /// friction against an independent writing of docs/benchmark.md's formula).
    #[test]
    fn disturbance_table_of_a_whole_run() {
        let d = Scenario::new(Maneuver::Slalom, Fidelity::Real).disturbances();
        let seq = DisturbanceSequence::new(d, N_SAMPLES);
        for k in 0..=N_SAMPLES {
            assert_eq!(bits(seq.friction(k)), bits(d.friction(k)), "k {k}");
            assert_eq!(seq.wind(k).map(f64::to_bits), d.wind(k).map(f64::to_bits), "k {k}");
            assert_eq!(seq.measure(k, 0.1, 0.2), d.measure(k, 0.1, 0.2), "k {k}");
        }
        // docs/benchmark.md at t = 12.345 s, wheel RL (phase pi): 0.35 sin(2 pi 12 theta - pi) + 0.55 + 0.1 u - 0.05
        let k = 12_345;
        let theta = 2.0 * PI * 12.345 / 30.0;
        let by_hand = 0.35 * (24.0 * PI * theta - PI).sin() + 0.5 + 0.1 * u(0, 2, k as u64);
        assert!((seq.friction(k)[2] - by_hand).abs() < 1e-12, "{} vs {by_hand}", seq.friction(k)[2]);
    }

    /// The paper's formulas with their numbers written in, as docs/benchmark.md prints them:
    /// friction, wind along +Y, measured `(beta, r)`.
    fn paper_formulas(seed: u64, k: usize) -> ([f64; 4], [f64; 2], (f64, f64)) {
        let t = k as f64 * SAMPLE_PERIOD;
        let theta = 2.0 * PI * t / 30.0;
        let phase = [0.0, FRAC_PI_2, PI, 1.5 * PI];
        let mut mu = [0.0; 4];
        for i in 0..4 {
            let noise = 0.1 * u(seed, i as u8, k as u64) - 0.05;
            mu[i] = 0.35 * (2.0 * PI * 12.0 * theta - phase[i]).sin() + 0.55 + noise;
        }
        let gust = if k >= 1_000 { 0.25 } else { 0.0 };
        let wind_y = gust + 0.1 * 0.25 * u(seed, 4, k as u64);
        let (beta, yaw_rate) = (0.02, -0.3);
        let measured = (beta + 0.005 * g(seed, 5, k as u64), yaw_rate + 0.01 * g(seed, 6, k as u64));
        (mu, [0.0, wind_y], measured)
    }

    /// The default settings are the paper's formulas bit for bit over a whole run (and one
    /// sample), for the formulas and for the cached table, for several seeds.
    #[test]
    fn default_settings_are_the_paper_formulas_bit_for_bit() {
        assert_eq!(
            Scenario::new(Maneuver::Skidpad, Fidelity::Real).disturbance_settings,
            DisturbanceSettings::default()
        );
        for seed in [0, 1, 7, 123_456, (1 << 40) + 3] {
            let d = Scenario { seed, ..Scenario::new(Maneuver::Slalom, Fidelity::Real) }.disturbances();
            let seq = DisturbanceSequence::new(d, N_SAMPLES);
            for k in 0..=N_SAMPLES {
                let (mu, wind, measured) = paper_formulas(seed, k);
                for (got_mu, got_wind, got_measured) in [
                    (d.friction(k), d.wind(k), d.measure(k, 0.02, -0.3)),
                    (seq.friction(k), seq.wind(k), seq.measure(k, 0.02, -0.3)),
                ] {
                    assert_eq!(bits(got_mu), bits(mu), "seed {seed} k {k}");
                    assert_eq!(got_wind.map(f64::to_bits), wind.map(f64::to_bits), "seed {seed} k {k}");
                    assert_eq!(
                        (got_measured.0.to_bits(), got_measured.1.to_bits()),
                        (measured.0.to_bits(), measured.1.to_bits())
                    );
                }
            }
        }
    }

    /// Other settings give what the formula says, and a table is never shared between settings.
    #[test]
    fn settings_change_the_disturbances_as_the_formulas_say() {
        let base = Scenario { seed: 4, ..Scenario::new(Maneuver::Straight, Fidelity::Real) };
        let settings = DisturbanceSettings {
            friction_mean: 0.8,
            friction_amplitude: 0.1,
            friction_frequency: 3.0,
            friction_noise: 0.02,
            friction_phase: [0.1, 0.2, 0.3, 0.4],
            wind_amplitude: 0.5,
            wind_noise: 0.2,
            wind_direction: 0.0,
            wind_start: 2.5,
            beta_noise: 0.0,
            yaw_rate_noise: 0.03,
        };
        let d = Scenario { disturbance_settings: settings, ..base }.disturbances();
        let seq = DisturbanceSequence::new(d, 5_000);
        let default_seq = DisturbanceSequence::new(base.disturbances(), 5_000);
        assert!(!std::sync::Arc::ptr_eq(seq.table.as_ref().unwrap(), default_seq.table.as_ref().unwrap()));
        for k in [0, 1, 2_499, 2_500, 4_321, 5_000, 7_000] {
            let t = k as f64 * 1e-3;
            let theta = 2.0 * PI * t / 30.0;
            for i in 0..4 {
                let by_hand = 0.1 * (6.0 * PI * theta - 0.1 * (i + 1) as f64).sin()
                    + 0.8
                    + 0.02 * (u(4, i as u8, k as u64) - 0.5);
                // w u - w/2 against w (u - 1/2): a few ulp of 1
                assert!((seq.friction(k)[i] - by_hand).abs() < 1e-15, "k {k} wheel {i}");
                assert!((0.69..=0.91).contains(&seq.friction(k)[i]));
            }
            let force = if t >= 2.5 { 0.5 } else { 0.0 } + 0.1 * u(4, 4, k as u64);
            // direction 0: along +X exactly, nothing along Y
            assert_eq!(seq.wind(k), [force, 0.0], "k {k}");
            assert_eq!(d.wind(k), [force, 0.0], "k {k}");
            let (beta, r) = seq.measure(k, 0.1, 0.2);
            assert_eq!(beta, 0.1, "beta_noise 0 measures beta as it is");
            assert_eq!(r, 0.2 + 0.03 * g(4, 6, k as u64));
        }
        // an oblique direction splits the force by cos and sin (to the rounding of a product)
        let oblique = Disturbances { settings: DisturbanceSettings { wind_direction: 2.0, ..settings }, ..d };
        let [x, y] = DisturbanceSequence::new(oblique, 3_000).wind(2_600);
        let force = 0.5 + 0.1 * u(4, 4, 2_600);
        assert_eq!((x, y), (2.0f64.cos() * force, 2.0f64.sin() * force));
        // the quarter turns are exact: pi/2, pi, -pi/2
        for (dir, unit) in [(FRAC_PI_2, (0.0, 1.0)), (PI, (-1.0, 0.0)), (-FRAC_PI_2, (0.0, -1.0)), (TAU, (1.0, 0.0))] {
            assert_eq!(DisturbanceSettings { wind_direction: dir, ..settings }.wind_unit(), unit, "{dir}");
        }
    }

    /// Out-of-range settings are refused with the FMU variable's name.
    #[test]
    fn settings_out_of_range_are_refused_by_name() {
        let ok = DisturbanceSettings::default();
        assert_eq!(ok.validate(), Ok(()));
        let cases: [(DisturbanceSettings, &str); 10] = [
            (DisturbanceSettings { friction_mean: 0.3, ..ok }, "friction_mean"),
            (DisturbanceSettings { friction_mean: 2.9, ..ok }, "friction_mean"),
            (DisturbanceSettings { friction_amplitude: -0.1, ..ok }, "friction_amplitude"),
            (DisturbanceSettings { friction_noise: f64::NAN, ..ok }, "friction_noise"),
            (DisturbanceSettings { friction_frequency: f64::INFINITY, ..ok }, "friction_frequency"),
            (DisturbanceSettings { friction_phase: [0.0, 0.0, 100.0, 0.0], ..ok }, "friction_phase_rl"),
            (DisturbanceSettings { wind_amplitude: -0.5, ..ok }, "wind_amplitude"),
            (DisturbanceSettings { wind_direction: 7.0, ..ok }, "wind_direction"),
            (DisturbanceSettings { wind_start: -1.0, ..ok }, "wind_start"),
            (DisturbanceSettings { yaw_rate_noise: -0.01, ..ok }, "yaw_rate_noise"),
        ];
        for (settings, name) in cases {
            let e = settings.validate().unwrap_err();
            assert_eq!(e.name, name, "{e}");
            let scenario =
                Scenario { disturbance_settings: settings, ..Scenario::new(Maneuver::Straight, Fidelity::Real) };
            assert!(scenario.validate().unwrap_err().to_string().starts_with(name));
        }
        // the lowest friction exactly 0 is accepted
        assert_eq!(DisturbanceSettings { friction_mean: 0.4, ..ok }.validate(), Ok(()));
    }

    /// The process keeps at most `DISTURBANCE_CACHE_SIZE` tables, hands out the same one
    /// to every run of a seed, and two threads asking at once get one table.
    #[test]
    fn disturbance_cache_is_shared_and_bounded() {
        let d = |seed| Disturbances {
            seed: 1_000 + seed,
            ..Scenario::new(Maneuver::Straight, Fidelity::Real).disturbances()
        };
        let (a, b) = std::thread::scope(|s| {
            let a = s.spawn(|| DisturbanceSequence::new(d(0), 500));
            let b = s.spawn(|| DisturbanceSequence::new(d(0), 500));
            (a.join().unwrap(), b.join().unwrap())
        });
        let (ta, tb) = (a.table.unwrap(), b.table.unwrap());
        assert!(std::sync::Arc::ptr_eq(&ta, &tb), "one table for one seed");
        assert_eq!((ta.seed, ta.rows.len()), (1_000, 501));
        for seed in 1..=2 * DISTURBANCE_CACHE_SIZE as u64 {
            DisturbanceSequence::new(d(seed), 500);
        }
        assert!(disturbance_cache().lock().unwrap().len() <= DISTURBANCE_CACHE_SIZE);
        // nothing to look up with every switch off; a long run keeps a bounded table
        assert!(DisturbanceSequence::new(Disturbances::none(), N_SAMPLES).table.is_none());
        let long = DisturbanceSequence::new(d(99), 100 * N_SAMPLES);
        assert_eq!(long.table.as_ref().unwrap().rows.len(), DISTURBANCE_TABLE_MAX_SAMPLES);
        let k = 3 * DISTURBANCE_TABLE_MAX_SAMPLES;
        assert_eq!(bits(long.friction(k)), bits(d(99).friction(k)));
    }
}
