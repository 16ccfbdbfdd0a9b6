//! The sampled controller of docs/benchmark.md: steering feedback on `x = [beta, yaw_rate]`
//! around the reference plus the speed-hold PI, as one type that the benchmark loop and the
//! controller FMU both run; and, beyond the paper, the robust path-tracking law
//! with pose feedback and the along-track speed correction.
//!
//! # Robust tracking (`Controller::RobustTracking`)
//!
//! The steering law feeds back the tracking errors of `nigel_vehicle::tracking` (the car
//! relative to the reference car, in the reference car's frame):
//!
//! ```text
//! (e_x, e_y, e_psi) = pose_errors(x, y, psi, x_ref, y_ref, psi_ref)   e_psi wrapped to (-pi, pi]
//! delta_i = clamp(delta_ff_i + K_track,i [e_y, e_psi, beta - beta_ref, yaw_rate - yaw_rate_ref], +-delta_max)
//! ```
//!
//! with `K_track` = [`gains::ROBUST_TRACKING`] (synthesized with exactly this sign
//! convention: `u = delta - delta_ff = K_track e`). The headings may be unwrapped (the plant
//! and the test bench integrate them); only their difference is wrapped.
//!
//! # Along-track correction
//!
//! The lateral law cannot remove the along-track error `e_x` (positive: the car is *ahead*
//! of the reference car, along the reference heading). A loop on top of the speed PI does:
//!
//! ```text
//! speed_command = speed_ref - clamp(k_along_track e_x, -along_track_speed_max, +along_track_speed_max)
//! e = speed_command - speed,   F = kp_speed e + ki_speed I        (the PI of docs/benchmark.md otherwise unchanged)
//! ```
//!
//! A car behind (`e_x < 0`) is asked to go faster, one ahead slower. Gain from a linear
//! argument (not from a maneuver or a seed): with the car's mass `m` alone against the
//! drive force, the PI loop is `v/v_cmd = (kp s + ki) / (m s^2 + kp s + ki)`, poles at
//! `omega_n = sqrt(ki/m) = 10 rad/s`, `zeta = 1`. The along-track error integrates the
//! speed difference, `de_x/dt = v - v_ref`, so the outer loop is
//! `L(s) = k_along_track (kp s + ki) / (s (m s^2 + kp s + ki))`; [`K_ALONG_TRACK`] `= 1 /s`
//! puts its crossover a decade below the inner loop, where the inner loop is unity
//! (phase lag 0.1 deg): `e_x` decays like a first-order lag of time constant about
//! `1 / k_along_track = 1 s` (the exact dominant pole of
//! `s^3 + (kp/m) s^2 + (ki/m + k kp/m) s + k ki/m` is -0.988 /s), without overshoot. The
//! clamp [`ALONG_TRACK_SPEED_MAX`] `= 0.1 m/s` (29 % of 0.35 m/s) keeps the commanded speed
//! inside `0.25 .. 0.45 m/s`, near the speed the tracking gain was designed for, however
//! far behind the car starts. The paper's three controllers run with `k_along_track = 0`,
//! i.e. exactly the speed PI of docs/benchmark.md.

use core::f64::consts::FRAC_PI_2;
use core::fmt;

use nigel_vehicle::tracking::pose_errors;

use crate::gains;
use crate::scenario::{SettingError, SAMPLE_PERIOD};

/// Proportional gain of the speed hold [N s/m] (omega_n = 10 rad/s, zeta = 1 for 2.68 kg).
pub const KP_SPEED: f64 = 53.6;
/// Integral gain of the speed hold [N/m].
pub const KI_SPEED: f64 = 268.0;
/// Saturation of the total drive force \[N\].
pub const FORCE_MAX: f64 = 20.0;
/// Gain of the along-track correction of the robust tracking controller [1/s] (module docs).
pub const K_ALONG_TRACK: f64 = 1.0;
/// Largest speed correction of the along-track loop [m/s] (module docs).
pub const ALONG_TRACK_SPEED_MAX: f64 = 0.1;

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
    /// Beyond the paper: the robust tracking gain [`gains::ROBUST_TRACKING`] on
    /// `[e_y, e_psi, beta - beta_ref, r - r_ref]` with the along-track speed correction.
    RobustTracking,
}

impl Controller {
    /// The three controllers of Table III, in its column order.
    pub const TABLE: [Controller; 3] = [Controller::OpenLoop, Controller::PolePlacement, Controller::Robust];

    /// The paper's three and the robust tracking controller (our Table III's four columns).
    pub const WITH_TRACKING: [Controller; 4] =
        [Controller::OpenLoop, Controller::PolePlacement, Controller::Robust, Controller::RobustTracking];

    /// The gain on `[beta - beta_ref, yaw_rate - yaw_rate_ref]` (4x2); for
    /// [`Controller::RobustTracking`] the last two columns of `K_track`.
    pub fn gain(&self) -> [[f64; 2]; 4] {
        match self {
            Controller::OpenLoop => [[0.0; 2]; 4],
            Controller::PolePlacement => gains::POLE_PLACEMENT,
            Controller::Robust => gains::ROBUST,
            Controller::Custom(k) => *k,
            Controller::RobustTracking => gains::ROBUST_TRACKING.map(|row| [row[2], row[3]]),
        }
    }

    /// The gain on the pose errors `[e_y, e_psi]` (4x2): zero but for
    /// [`Controller::RobustTracking`] (the first two columns of `K_track`).
    pub fn pose_gain(&self) -> [[f64; 2]; 4] {
        match self {
            Controller::RobustTracking => gains::ROBUST_TRACKING.map(|row| [row[0], row[1]]),
            _ => [[0.0; 2]; 4],
        }
    }

    /// The whole feedback gain on `[e_y, e_psi, beta - beta_ref, yaw_rate - yaw_rate_ref]` (4x4).
    pub fn feedback_gain(&self) -> [[f64; 4]; 4] {
        let (p, k) = (self.pose_gain(), self.gain());
        core::array::from_fn(|i| [p[i][0], p[i][1], k[i][0], k[i][1]])
    }

    /// Whether the law reads the pose (the tracking controller).
    pub fn uses_pose(&self) -> bool {
        matches!(self, Controller::RobustTracking)
    }

    /// The settings of docs/benchmark.md with this controller's gains (and, for the tracking
    /// controller, the along-track correction [`K_ALONG_TRACK`]).
    pub fn settings(&self) -> ControllerSettings {
        match self {
            Controller::RobustTracking => ControllerSettings::tracking(gains::ROBUST_TRACKING),
            c => ControllerSettings::with_gain(c.gain()),
        }
    }

    /// `open_loop`, `pole_placement`, `robust`, `custom`, `robust_tracking`.
    pub fn name(&self) -> &'static str {
        match self {
            Controller::OpenLoop => "open_loop",
            Controller::PolePlacement => "pole_placement",
            Controller::Robust => "robust",
            Controller::Custom(_) => "custom",
            Controller::RobustTracking => "robust_tracking",
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
    /// Steering feedback on the pose errors, rows FL, FR, RL, RR, columns `[e_y, e_psi]`
    /// [rad/m, rad/rad] (zero for the paper's controllers).
    pub pose_gain: [[f64; 2]; 4],
    /// Along-track correction of the speed command [1/s] (0: the speed PI of docs/benchmark.md).
    pub k_along_track: f64,
    /// Largest along-track speed correction [m/s].
    pub along_track_speed_max: f64,
    /// Speed PI proportional gain [N s/m].
    pub kp_speed: f64,
    /// Speed PI integral gain [N/m].
    pub ki_speed: f64,
    /// Largest total drive force \[N\].
    pub force_max: f64,
    /// Wheel radius turning force into torque \[m\].
    pub r_wheel: f64,
    /// Steering clamp \[rad\] (the plant's limit, pi/2).
    pub delta_max: f64,
    /// Sample period \[s\] (1 ms).
    pub sample_period: f64,
}

impl Default for ControllerSettings {
    fn default() -> Self {
        Self::with_gain(gains::ROBUST)
    }
}

impl ControllerSettings {
    /// The defaults of docs/benchmark.md with gain `K`.
    pub fn with_gain(gain: [[f64; 2]; 4]) -> Self {
        ControllerSettings {
            gain,
            pose_gain: [[0.0; 2]; 4],
            k_along_track: 0.0,
            along_track_speed_max: ALONG_TRACK_SPEED_MAX,
            kp_speed: KP_SPEED,
            ki_speed: KI_SPEED,
            force_max: FORCE_MAX,
            r_wheel: nigel_vehicle::VehicleParams::table2().r_wheel,
            delta_max: FRAC_PI_2,
            sample_period: SAMPLE_PERIOD,
        }
    }

    /// The tracking law with `K_track` (rows FL, FR, RL, RR, columns `[e_y, e_psi, beta -
    /// beta_ref, yaw_rate - yaw_rate_ref]`) and the along-track correction [`K_ALONG_TRACK`].
    pub fn tracking(k_track: [[f64; 4]; 4]) -> Self {
        ControllerSettings {
            pose_gain: k_track.map(|row| [row[0], row[1]]),
            k_along_track: K_ALONG_TRACK,
            ..Self::with_gain(k_track.map(|row| [row[2], row[3]]))
        }
    }

    /// Whether the law reads the pose inputs (a pose gain or the along-track loop is on).
    pub fn uses_pose(&self) -> bool {
        self.k_along_track != 0.0 || self.pose_gain.iter().flatten().any(|&k| k != 0.0)
    }

    /// Refuses NaN, infinite or out-of-range values, naming the variable.
    pub fn validate(&self) -> Result<(), SettingError> {
        const GAIN_NAMES: [[&str; 2]; 4] = [
            ["k_beta_fl", "k_yaw_rate_fl"],
            ["k_beta_fr", "k_yaw_rate_fr"],
            ["k_beta_rl", "k_yaw_rate_rl"],
            ["k_beta_rr", "k_yaw_rate_rr"],
        ];
        const POSE_GAIN_NAMES: [[&str; 2]; 4] = [
            ["gain_e_y_fl", "gain_e_psi_fl"],
            ["gain_e_y_fr", "gain_e_psi_fr"],
            ["gain_e_y_rl", "gain_e_psi_rl"],
            ["gain_e_y_rr", "gain_e_psi_rr"],
        ];
        for (gain, all_names) in [(&self.gain, GAIN_NAMES), (&self.pose_gain, POSE_GAIN_NAMES)] {
            for (row, names) in gain.iter().zip(all_names) {
                for (&value, name) in row.iter().zip(names) {
                    if !value.is_finite() {
                        return Err(SettingError { name, value, reason: "gain must be finite" });
                    }
                }
            }
        }
        let checks: [(&'static str, f64, bool, &'static str); 8] = [
            ("k_along_track", self.k_along_track, self.k_along_track >= 0.0, "must be finite and >= 0"),
            (
                "along_track_speed_max",
                self.along_track_speed_max,
                self.along_track_speed_max >= 0.0,
                "must be finite and >= 0",
            ),
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
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ControllerInputs {
    /// Measured body slip angle \[rad\].
    pub beta: f64,
    /// Measured yaw rate [rad/s].
    pub yaw_rate: f64,
    /// Measured speed `hypot(v_x, v_y)` [m/s].
    pub speed: f64,
    /// Reference body slip angle \[rad\].
    pub beta_ref: f64,
    /// Reference yaw rate [rad/s].
    pub yaw_rate_ref: f64,
    /// Speed to hold [m/s].
    pub speed_ref: f64,
    /// Feed-forward steering (the program) \[rad\], FL, FR, RL, RR.
    pub delta_ff: [f64; 4],
    /// Measured pose: world X \[m\] (read only by the tracking law).
    pub x: f64,
    /// Measured pose: world Y \[m\].
    pub y: f64,
    /// Measured heading, unwrapped or not \[rad\].
    pub psi: f64,
    /// Reference pose: world X \[m\].
    pub x_ref: f64,
    /// Reference pose: world Y \[m\].
    pub y_ref: f64,
    /// Reference heading \[rad\].
    pub psi_ref: f64,
}

impl ControllerInputs {
    /// The pose errors `(e_x, e_y, e_psi)` of the measured pose relative to the reference
    /// pose ([`nigel_vehicle::tracking::pose_errors`]).
    pub fn pose_errors(&self) -> (f64, f64, f64) {
        pose_errors(self.x, self.y, self.psi, self.x_ref, self.y_ref, self.psi_ref)
    }
}

/// What the law puts out, held until the next sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerOutputs {
    /// Steering commands \[rad\], clamped to `+-delta_max`.
    pub delta: [f64; 4],
    /// Drive torques `F r_wheel / 4` [N.m].
    pub tau: [f64; 4],
    /// Total drive force `F` after the clip \[N\].
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

    /// The speed integrator `I` \[m\].
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
        if s.uses_pose() {
            let (_, e_y, e_psi) = x.pose_errors();
            let p = &s.pose_gain;
            for i in 0..4 {
                let u = p[i][0] * e_y + p[i][1] * e_psi + s.gain[i][0] * d_beta + s.gain[i][1] * d_yaw_rate;
                delta[i] = (x.delta_ff[i] + u).clamp(-s.delta_max, s.delta_max);
            }
        } else {
            // the paper's law, exactly as docs/benchmark.md writes it
            for i in 0..4 {
                let cmd = x.delta_ff[i] + (s.gain[i][0] * d_beta + s.gain[i][1] * d_yaw_rate);
                delta[i] = cmd.clamp(-s.delta_max, s.delta_max);
            }
        }
        let (force, saturated) = self.force(x);
        let torque = force * s.r_wheel / 4.0;
        ControllerOutputs { delta, tau: [torque; 4], force, saturated }
    }

    /// The speed the PI holds: `speed_ref`, corrected by the along-track loop when it is on
    /// (module docs).
    pub fn speed_command(&self, x: &ControllerInputs) -> f64 {
        let s = &self.settings;
        if s.k_along_track == 0.0 {
            return x.speed_ref;
        }
        let (e_x, _, _) = x.pose_errors();
        x.speed_ref - (s.k_along_track * e_x).clamp(-s.along_track_speed_max, s.along_track_speed_max)
    }

    fn force(&self, x: &ControllerInputs) -> (f64, bool) {
        let s = &self.settings;
        let e = self.speed_command(x) - x.speed;
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
            (self.speed_command(x) - x.speed) * self.settings.sample_period
        }
    }

    /// [`SampledController::outputs`] and [`SampledController::increment`] in one pass
    /// (the speed error and the force once).
    pub fn outputs_and_increment(&self, x: &ControllerInputs) -> (ControllerOutputs, f64) {
        let out = self.outputs(x);
        let increment =
            if out.saturated { 0.0 } else { (self.speed_command(x) - x.speed) * self.settings.sample_period };
        (out, increment)
    }

    /// Moves the integrator past the current sample: `I += e T` unless the force saturates.
    pub fn advance(&mut self, x: &ControllerInputs) {
        self.integral += self.increment(x);
    }

    /// [`SampledController::outputs`] then [`SampledController::advance`].
    pub fn step(&mut self, x: &ControllerInputs) -> ControllerOutputs {
        let out = self.outputs(x);
        if !out.saturated {
            self.integral += (self.speed_command(x) - x.speed) * self.settings.sample_period;
        }
        out
    }
}

/// The inputs the tests start from, shared with the integration tests.
#[cfg(test)]
#[path = "../tests/common/inputs.rs"]
mod test_inputs;

#[cfg(test)]
mod tests {
    use super::*;

    fn inputs() -> ControllerInputs {
        super::test_inputs::off_reference()
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
    fn tracking_law_by_hand() {
        // K_track with distinct entries; the reference car at (1, 2) heading 30 deg, the car
        // 0.1 m to its left and 0.2 m ahead, turned 0.05 rad, with the heading a full turn up
        let k = [[1.0, 2.0, 3.0, 4.0], [-1.0, 0.5, 0.0, 0.0], [0.0, -3.0, 0.25, 1.0], [4.0, 0.0, -2.0, 0.5]];
        let c = SampledController::new(ControllerSettings::tracking(k)).unwrap();
        let psi_ref: f64 = 30f64.to_radians();
        let (c30, s30) = (psi_ref.cos(), psi_ref.sin());
        let x = ControllerInputs {
            x: 1.0 + 0.2 * c30 - 0.1 * s30,
            y: 2.0 + 0.2 * s30 + 0.1 * c30,
            psi: psi_ref + 0.05 + core::f64::consts::TAU,
            x_ref: 1.0,
            y_ref: 2.0,
            psi_ref,
            ..inputs()
        };
        let out = c.outputs(&x);
        // e = [e_y, e_psi, d_beta, d_r] = [0.1, 0.05, 0.01, -0.15]
        let e = [0.1, 0.05, 0.01, -0.15];
        for i in 0..4 {
            let expect = x.delta_ff[i] + (0..4).map(|j| k[i][j] * e[j]).sum::<f64>();
            assert!((out.delta[i] - expect).abs() < 1e-12, "{i}: {} vs {expect}", out.delta[i]);
        }
        // 0.2 m ahead: the speed command is 0.35 - 1.0 * 0.2 = 0.15 m/s, clamped to 0.25
        assert!((c.speed_command(&x) - 0.25).abs() < 1e-15, "{}", c.speed_command(&x));
        // e = 0.25 - 0.3: F = 53.6 * -0.05
        assert!((out.force + 2.68).abs() < 1e-12, "{}", out.force);
        let x = ControllerInputs { x: x.x - 0.25 * c30, y: x.y - 0.25 * s30, ..x }; // 0.05 m behind
        assert!((c.speed_command(&x) - 0.4).abs() < 1e-12, "{}", c.speed_command(&x));
        // the robust tracking controller's settings are K_track split in pose and state columns
        let s = Controller::RobustTracking.settings();
        assert_eq!(Controller::RobustTracking.feedback_gain(), gains::ROBUST_TRACKING);
        assert_eq!(s.gain[3], [gains::ROBUST_TRACKING[3][2], gains::ROBUST_TRACKING[3][3]]);
        assert_eq!(s.pose_gain[0], [gains::ROBUST_TRACKING[0][0], gains::ROBUST_TRACKING[0][1]]);
        assert_eq!(s.k_along_track, K_ALONG_TRACK);
        assert_eq!(Controller::Robust.feedback_gain()[0], [0.0, 0.0, gains::ROBUST[0][0], gains::ROBUST[0][1]]);
    }

    #[test]
    fn outputs_and_increment_in_one_pass() {
        let c = SampledController::new(ControllerSettings::tracking(gains::ROBUST_TRACKING)).unwrap();
        let mut x = ControllerInputs { x: 0.3, y: -0.1, psi: 0.2, ..inputs() };
        // e = 0.35 - 0.3 (+ the along-track correction): not saturated, I += e T
        let (out, inc) = c.outputs_and_increment(&x);
        assert_eq!((out, inc), (c.outputs(&x), c.increment(&x)));
        assert!(!out.saturated && inc != 0.0);
        x.speed = -5.0; // F far beyond 20 N: saturated, the integrator frozen
        let (out, inc) = c.outputs_and_increment(&x);
        assert!(out.saturated && inc == 0.0 && c.increment(&x) == 0.0);
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
        let mut s = ControllerSettings::tracking(gains::ROBUST_TRACKING);
        s.pose_gain[1][1] = f64::INFINITY;
        assert_eq!(s.validate().unwrap_err().name, "gain_e_psi_fr");
        let s = ControllerSettings { k_along_track: -1.0, ..Default::default() };
        assert_eq!(s.validate().unwrap_err().name, "k_along_track");
        let s = ControllerSettings { along_track_speed_max: f64::NAN, ..Default::default() };
        assert_eq!(s.validate().unwrap_err().name, "along_track_speed_max");
    }
}
