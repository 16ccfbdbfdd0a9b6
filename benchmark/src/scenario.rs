//! What one benchmark run is: the maneuver, the column (plant fidelity), the steering
//! program per sample and the disturbances per sample (maneuvers.md).

use core::f64::consts::{FRAC_PI_2, PI};
use core::fmt;

use nigel_vehicle::VehicleParams;

use crate::noise::{g, u, STREAM_BETA, STREAM_FRICTION, STREAM_WIND, STREAM_YAW_RATE};

/// The sample period of the benchmark, 1 ms [s].
pub const SAMPLE_PERIOD: f64 = 1e-3;
/// Samples per run: `k = 0 .. 29999`, 30 s.
pub const N_SAMPLES: usize = 30_000;
/// Largest run accepted (10^4 s): bounds the memory of a reference (48 bytes a sample).
pub const MAX_SAMPLES: usize = 10_000_000;
/// The speed the PI holds and the start speed [m/s].
pub const DEFAULT_SPEED: f64 = 0.35;
/// Steering amplitude `a` of the programs, 30 deg [rad].
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
    /// Wind along world +Y on (else none).
    pub wind: bool,
    /// Measurement noise on beta and r; only the real fidelity measures with noise.
    pub measurement_noise: bool,
    /// Steering amplitude `a` [rad], in `[0, pi/2]`.
    pub steer_amplitude: f64,
    /// Speed held by the PI, and the start speed [m/s].
    pub speed_ref: f64,
    /// Samples of 1 ms to run (30,000).
    pub n_samples: usize,
}

impl Scenario {
    /// The definition of maneuvers.md: seed 0, every disturbance on, 30 deg, 0.35 m/s, 30 s.
    pub fn new(maneuver: Maneuver, fidelity: Fidelity) -> Self {
        Scenario {
            maneuver,
            fidelity,
            seed: 0,
            friction_variation: true,
            wind: true,
            measurement_noise: true,
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
        Ok(())
    }

    /// The disturbances of this scenario.
    pub fn disturbances(&self) -> Disturbances {
        Disturbances {
            seed: self.seed,
            friction_variation: self.friction_variation,
            wind: self.wind,
            measurement_noise: self.measurement_noise && self.fidelity == Fidelity::Real,
        }
    }
}

/// The steering program of a maneuver, per sample (`[FL, FR, RL, RR]`, always front `+f`,
/// rear `-f`: out-of-phase all-wheel steer).
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// The maneuver.
    pub maneuver: Maneuver,
    /// Amplitude `a` [rad].
    pub amplitude: f64,
    /// Figure-8 only: the samples at which the sign flips (ascending); empty otherwise.
    pub switches: Vec<usize>,
}

impl Program {
    /// A program; a figure-8 needs its switching table ([`crate::figure8_switches`]).
    pub fn new(maneuver: Maneuver, amplitude: f64, switches: Vec<usize>) -> Self {
        Program { maneuver, amplitude, switches }
    }

    /// The front steering angle at sample `k` (the rear is its negative) [rad].
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

    /// `[FL, FR, RL, RR]` at sample `k` [rad].
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

/// The disturbances of a run, per sample (pure functions of the sample index).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Disturbances {
    /// Seed of every stream.
    pub seed: u64,
    /// Friction sinusoids plus noise (else 0.4).
    pub friction_variation: bool,
    /// Wind along world +Y (else zero).
    pub wind: bool,
    /// Gaussian noise on the measured beta and r.
    pub measurement_noise: bool,
}

/// Phase of the friction sinusoid per wheel, FL, FR, RL, RR.
pub const FRICTION_PHASE: [f64; 4] = [0.0, FRAC_PI_2, PI, 1.5 * PI];

impl Disturbances {
    /// Nothing: `mu = 0.4`, no wind, true measurements (the reference run).
    pub fn none() -> Self {
        Disturbances { seed: 0, friction_variation: false, wind: false, measurement_noise: false }
    }

    /// Road friction per wheel at sample `k`:
    /// `mu_i = 0.35 sin(2 pi f theta_k - phi_i) + 0.55 + (0.1 u - 0.05)`, `theta_k = 2 pi t_k / 30 s`, `f = 12`.
    pub fn friction(&self, k: usize) -> [f64; 4] {
        if !self.friction_variation {
            return [MU_NOMINAL; 4];
        }
        let t = k as f64 * SAMPLE_PERIOD;
        let theta = 2.0 * PI * t / 30.0;
        let mut mu = [0.0; 4];
        for i in 0..4 {
            let noise = 0.1 * u(self.seed, STREAM_FRICTION[i], k as u64) - 0.05;
            mu[i] = 0.35 * (2.0 * PI * 12.0 * theta - FRICTION_PHASE[i]).sin() + 0.55 + noise;
        }
        mu
    }

    /// Wind force along world +Y at sample `k` [N]: `0.25 [t_k >= 1 s] + 0.025 chi_k`.
    pub fn wind_y(&self, k: usize) -> f64 {
        if !self.wind {
            return 0.0;
        }
        let gust = if k >= 1_000 { 0.25 } else { 0.0 };
        gust + 0.1 * 0.25 * u(self.seed, STREAM_WIND, k as u64)
    }

    /// What the controller measures at sample `k`: `(beta + 0.005 g, r + 0.01 g)` with the
    /// noise on, else the true values.
    pub fn measure(&self, k: usize, beta: f64, yaw_rate: f64) -> (f64, f64) {
        if !self.measurement_noise {
            return (beta, yaw_rate);
        }
        (beta + 0.005 * g(self.seed, STREAM_BETA, k as u64), yaw_rate + 0.01 * g(self.seed, STREAM_YAW_RATE, k as u64))
    }
}
