//! The sampled controller of maneuvers.md: steering feedback on `x = [beta, yaw_rate]`
//! around the reference plus the speed-hold PI, as one type that the benchmark loop and the
//! controller FMU both run.

use core::f64::consts::FRAC_PI_2;
use core::fmt;

use crate::gains;
use crate::scenario::{SettingError, SAMPLE_PERIOD};

/// Proportional gain of the speed hold [N s/m] (omega_n = 10 rad/s, zeta = 1 for 2.68 kg).
pub const KP_SPEED: f64 = 53.6;
/// Integral gain of the speed hold [N/m].
pub const KI_SPEED: f64 = 268.0;
/// Saturation of the total drive force [N].
pub const FORCE_MAX: f64 = 20.0;

/// Which steering feedback.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Controller {
    /// `K = 0`: the program alone.
    OpenLoop,
    /// The non-robust pole-placement baseline [`gains::POLE_PLACEMENT`].
    PolePlacement,
    /// The robust mixed H2/H-inf gain [`gains::ROBUST`].
    Robust,
    /// Any gain (rows FL, FR, RL, RR; columns beta, yaw_rate).
    Custom([[f64; 2]; 4]),
}

impl Controller {
    /// The three controllers of Table III, in its column order.
    pub const TABLE: [Controller; 3] = [Controller::OpenLoop, Controller::PolePlacement, Controller::Robust];

    /// The gain `K` (4x2).
    pub fn gain(&self) -> [[f64; 2]; 4] {
        match self {
            Controller::OpenLoop => [[0.0; 2]; 4],
            Controller::PolePlacement => gains::POLE_PLACEMENT,
            Controller::Robust => gains::ROBUST,
            Controller::Custom(k) => *k,
        }
    }

    /// `open_loop`, `pole_placement`, `robust`, `custom`.
    pub fn name(&self) -> &'static str {
        match self {
            Controller::OpenLoop => "open_loop",
            Controller::PolePlacement => "pole_placement",
            Controller::Robust => "robust",
            Controller::Custom(_) => "custom",
        }
    }
}

impl fmt::Display for Controller {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Settings of the sampled law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerSettings {
    /// Steering feedback `K`, rows FL, FR, RL, RR, columns `[beta, yaw_rate]` [rad/rad, rad/(rad/s)].
    pub gain: [[f64; 2]; 4],
    /// Speed PI proportional gain [N s/m].
    pub kp_speed: f64,
    /// Speed PI integral gain [N/m].
    pub ki_speed: f64,
    /// Largest total drive force [N].
    pub force_max: f64,
    /// Wheel radius turning force into torque [m].
    pub r_wheel: f64,
    /// Steering clamp [rad] (the plant's limit, pi/2).
    pub delta_max: f64,
    /// Sample period [s] (1 ms).
    pub sample_period: f64,
}

impl Default for ControllerSettings {
    fn default() -> Self {
        Self::with_gain(gains::ROBUST)
    }
}

impl ControllerSettings {
    /// The defaults of maneuvers.md with gain `K`.
    pub fn with_gain(gain: [[f64; 2]; 4]) -> Self {
        ControllerSettings {
            gain,
            kp_speed: KP_SPEED,
            ki_speed: KI_SPEED,
            force_max: FORCE_MAX,
            r_wheel: nigel_vehicle::VehicleParams::table2().r_wheel,
            delta_max: FRAC_PI_2,
            sample_period: SAMPLE_PERIOD,
        }
    }

    /// Refuses NaN, infinite or out-of-range values, naming the variable.
    pub fn validate(&self) -> Result<(), SettingError> {
        const GAIN_NAMES: [[&str; 2]; 4] = [
            ["k_beta_fl", "k_yaw_rate_fl"],
            ["k_beta_fr", "k_yaw_rate_fr"],
            ["k_beta_rl", "k_yaw_rate_rl"],
            ["k_beta_rr", "k_yaw_rate_rr"],
        ];
        for (row, names) in self.gain.iter().zip(GAIN_NAMES) {
            for (&value, name) in row.iter().zip(names) {
                if !value.is_finite() {
                    return Err(SettingError { name, value, reason: "gain must be finite" });
                }
            }
        }
        let checks: [(&'static str, f64, bool, &'static str); 6] = [
            ("kp_speed", self.kp_speed, self.kp_speed >= 0.0, "must be finite and >= 0"),
            ("ki_speed", self.ki_speed, self.ki_speed >= 0.0, "must be finite and >= 0"),
            ("force_max", self.force_max, self.force_max > 0.0, "must be finite and > 0"),
            ("r_wheel", self.r_wheel, self.r_wheel > 0.0, "must be finite and > 0"),
            ("delta_max", self.delta_max, self.delta_max > 0.0 && self.delta_max <= FRAC_PI_2, "must be in (0, pi/2]"),
            ("sample_period", self.sample_period, self.sample_period > 0.0, "must be finite and > 0"),
        ];
        for (name, value, ok, reason) in checks {
            if !(value.is_finite() && ok) {
                return Err(SettingError { name, value, reason });
            }
        }
        Ok(())
    }
}

/// What the law reads at a sample instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerInputs {
    /// Measured body slip angle [rad].
    pub beta: f64,
    /// Measured yaw rate [rad/s].
    pub yaw_rate: f64,
    /// Measured speed `hypot(v_x, v_y)` [m/s].
    pub speed: f64,
    /// Reference body slip angle [rad].
    pub beta_ref: f64,
    /// Reference yaw rate [rad/s].
    pub yaw_rate_ref: f64,
    /// Speed to hold [m/s].
    pub speed_ref: f64,
    /// Feed-forward steering (the program) [rad], FL, FR, RL, RR.
    pub delta_ff: [f64; 4],
}

/// What the law puts out, held until the next sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerOutputs {
    /// Steering commands [rad], clamped to `+-delta_max`.
    pub delta: [f64; 4],
    /// Drive torques `F r_wheel / 4` [N.m].
    pub tau: [f64; 4],
    /// Total drive force `F` after the clip [N].
    pub force: f64,
    /// Whether `|kp e + ki I| > force_max` (the integrator is then frozen).
    pub saturated: bool,
}

/// The sampled law with its one discrete state, the speed integrator `I`.
///
/// At a sample: [`SampledController::outputs`] is the law on the inputs of that instant
/// (direct feedthrough, the integrator unchanged), [`SampledController::advance`] moves the
/// integrator to the next sample (`I += e T` unless saturated). [`SampledController::step`] does both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledController {
    settings: ControllerSettings,
    integral: f64,
}

impl SampledController {
    /// A controller at `I = 0`; refuses invalid settings.
    pub fn new(settings: ControllerSettings) -> Result<Self, SettingError> {
        settings.validate()?;
        Ok(SampledController { settings, integral: 0.0 })
    }

    /// The settings in use.
    pub fn settings(&self) -> &ControllerSettings {
        &self.settings
    }

    /// Replaces the settings (validated; the integrator is kept).
    pub fn set_settings(&mut self, settings: ControllerSettings) -> Result<(), SettingError> {
        settings.validate()?;
        self.settings = settings;
        Ok(())
    }

    /// The speed integrator `I` [m].
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// Sets the integrator (e.g. restoring a saved state).
    pub fn set_integral(&mut self, integral: f64) {
        self.integral = integral;
    }

    /// Back to `I = 0`.
    pub fn reset(&mut self) {
        self.integral = 0.0;
    }

    /// The law at the current sample; does not change the state.
    pub fn outputs(&self, x: &ControllerInputs) -> ControllerOutputs {
        let s = &self.settings;
        let d_beta = x.beta - x.beta_ref;
        let d_yaw_rate = x.yaw_rate - x.yaw_rate_ref;
        let mut delta = [0.0; 4];
        for i in 0..4 {
            let cmd = x.delta_ff[i] + (s.gain[i][0] * d_beta + s.gain[i][1] * d_yaw_rate);
            delta[i] = cmd.clamp(-s.delta_max, s.delta_max);
        }
        let (force, saturated) = self.force(x);
        let torque = force * s.r_wheel / 4.0;
        ControllerOutputs { delta, tau: [torque; 4], force, saturated }
    }

    fn force(&self, x: &ControllerInputs) -> (f64, bool) {
        let s = &self.settings;
        let e = x.speed_ref - x.speed;
        let f = s.kp_speed * e + s.ki_speed * self.integral;
        if f.abs() > s.force_max {
            (f.clamp(-s.force_max, s.force_max), true)
        } else {
            (f, false)
        }
    }

    /// What [`SampledController::advance`] adds to the integrator: `e T`, or 0 while the
    /// force saturates.
    pub fn increment(&self, x: &ControllerInputs) -> f64 {
        let (_, saturated) = self.force(x);
        if saturated {
            0.0
        } else {
            (x.speed_ref - x.speed) * self.settings.sample_period
        }
    }

    /// Moves the integrator past the current sample: `I += e T` unless the force saturates.
    pub fn advance(&mut self, x: &ControllerInputs) {
        self.integral += self.increment(x);
    }

    /// [`SampledController::outputs`] then [`SampledController::advance`].
    pub fn step(&mut self, x: &ControllerInputs) -> ControllerOutputs {
        let out = self.outputs(x);
        if !out.saturated {
            self.integral += (x.speed_ref - x.speed) * self.settings.sample_period;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inputs() -> ControllerInputs {
        ControllerInputs {
            beta: 0.02,
            yaw_rate: -0.1,
            speed: 0.3,
            beta_ref: 0.01,
            yaw_rate_ref: 0.05,
            speed_ref: 0.35,
            delta_ff: [0.1, 0.1, -0.1, -0.1],
        }
    }

    #[test]
    fn law_by_hand() {
        let k = [[1.0, 2.0], [-1.0, 0.5], [0.0, -3.0], [4.0, 0.0]];
        let mut c = SampledController::new(ControllerSettings::with_gain(k)).unwrap();
        let out = c.step(&inputs());
        // d_beta = 0.01, d_r = -0.15
        let expect = [0.1 + 0.01 - 0.3, 0.1 - 0.01 - 0.075, -0.1 + 0.45, -0.1 + 0.04];
        for i in 0..4 {
            assert!((out.delta[i] - expect[i]).abs() < 1e-15, "{i}: {}", out.delta[i]);
        }
        // e = 0.05: F = 53.6 * 0.05 = 2.68, tau = 2.68 * 0.0325 / 4
        assert!((out.force - 2.68).abs() < 1e-14 && !out.saturated);
        assert!((out.tau[0] - 2.68 * 0.0325 / 4.0).abs() < 1e-15);
        assert!((c.integral() - 0.05e-3).abs() < 1e-18);
        // next sample: F = 2.68 + 268 * 5e-5 = 2.6934
        let out = c.outputs(&inputs());
        assert!((out.force - 2.6934).abs() < 1e-13, "{}", out.force);
    }

    #[test]
    fn steering_clamps_and_force_saturates_with_frozen_integrator() {
        let k = [[100.0, 0.0]; 4];
        let mut c = SampledController::new(ControllerSettings::with_gain(k)).unwrap();
        let mut x = inputs();
        x.beta = 1.0; // 100 * 0.99 far beyond pi/2
        x.speed = 0.0; // F = 53.6 * 0.35 = 18.76, below 20
        let out = c.step(&x);
        assert_eq!(out.delta, [FRAC_PI_2; 4]);
        assert!(!out.saturated);
        assert!((c.integral() - 0.35e-3).abs() < 1e-18);
        x.speed_ref = 1.0; // F = 53.6 + ... > 20
        let before = c.integral();
        let out = c.step(&x);
        assert!(out.saturated && out.force == 20.0);
        assert_eq!(out.tau, [20.0 * 0.0325 / 4.0; 4]);
        assert_eq!(c.integral(), before, "frozen while saturated");
        x.speed_ref = -1.0;
        let out = c.step(&x);
        assert!(out.saturated && out.force == -20.0);
        assert_eq!(c.integral(), before);
    }

    #[test]
    fn refuses_bad_settings_naming_the_variable() {
        let mut s = ControllerSettings::default();
        s.gain[2][1] = f64::NAN;
        assert_eq!(s.validate().unwrap_err().name, "k_yaw_rate_rl");
        let s = ControllerSettings { sample_period: -1e-3, ..Default::default() };
        assert_eq!(SampledController::new(s).unwrap_err().name, "sample_period");
        let s = ControllerSettings { delta_max: 2.0, ..Default::default() };
        assert_eq!(s.validate().unwrap_err().name, "delta_max");
        let s = ControllerSettings { force_max: f64::INFINITY, ..Default::default() };
        assert_eq!(s.validate().unwrap_err().name, "force_max");
    }
}
