//! Vehicle parameters (Table II of the paper) and their validation.

use core::fmt;

/// Wheel order used everywhere: front-left, front-right, rear-left, rear-right.
pub const WHEELS: [&str; 4] = ["fl", "fr", "rl", "rr"];

/// Physical parameters of the vehicle and the "real"-fidelity options.
///
/// Field names follow the physics notation of the paper (and the FMU variable names);
/// all values are SI (kg, m, s, rad, N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VehicleParams {
    /// Mass m \[kg\].
    pub m: f64,
    /// Yaw moment of inertia I_z [kg.m2].
    pub i_z: f64,
    /// CG to front axle l_f \[m\].
    pub l_f: f64,
    /// CG to rear axle l_r \[m\].
    pub l_r: f64,
    /// Full track width t \[m\].
    pub track: f64,
    /// Wheel radius r \[m\].
    pub r_wheel: f64,
    /// Cornering stiffness per wheel C_i [N/rad], order FL, FR, RL, RR.
    pub c: [f64; 4],
    /// Gravity g [m/s2].
    pub g: f64,
    /// Speed below which tire forces fade to zero [m/s].
    pub v_fade: f64,
    /// Steering limit \[rad\].
    pub delta_max: f64,
    /// "Real" fidelity: friction-circle tire (`hypot(F_d, F_y) <= mu N`).
    pub friction_circle: bool,
    /// "Real" fidelity: first-order steering servo with a rate limit.
    pub steering_servo: bool,
    /// Servo time constant T_s \[s\].
    pub servo_time_constant: f64,
    /// Servo rate limit [rad/s].
    pub servo_rate_max: f64,
    /// "Real" fidelity: drive motor speed limit.
    pub motor_speed_limit: bool,
    /// Wheel rolling speed at which the motor runs out of speed [m/s].
    pub wheel_speed_max: f64,
    /// Width of the linear taper below `wheel_speed_max` [m/s].
    pub motor_taper: f64,
}

impl Default for VehicleParams {
    fn default() -> Self {
        Self::table2()
    }
}

/// Why a parameter set was refused.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    pub name: &'static str,
    pub value: f64,
    pub reason: &'static str,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "parameter {} = {} is invalid: {}", self.name, self.value, self.reason)
    }
}

impl std::error::Error for ParamError {}

/// `Ok` when `valid`, else the refusal of parameter `name` = `value` for `reason`.
fn refuse_unless(valid: bool, name: &'static str, value: f64, reason: &'static str) -> Result<(), ParamError> {
    if valid {
        Ok(())
    } else {
        Err(ParamError { name, value, reason })
    }
}

impl VehicleParams {
    /// Table II of the paper, paper fidelity (all "real" options off).
    pub fn table2() -> Self {
        VehicleParams {
            m: 2.68,
            i_z: 0.01944,
            l_f: 0.06226,
            l_r: 0.07929,
            track: 0.14724,
            r_wheel: 0.0325,
            c: [22.4768; 4],
            g: 9.81,
            v_fade: 0.02,
            delta_max: core::f64::consts::FRAC_PI_2,
            friction_circle: false,
            steering_servo: false,
            servo_time_constant: 0.03,
            servo_rate_max: 5.51,
            motor_speed_limit: false,
            wheel_speed_max: 0.442,
            motor_taper: 0.05,
        }
    }

    /// The geometry the authors' synthesis script used: `l = 0.1415`, `l_f = 0.44 l`,
    /// `l_r = l - l_f = 0.07924` (Table II prints 0.07929). Used to reproduce the
    /// published synthesis numbers; everything else as Table II.
    pub fn paper_synthesis() -> Self {
        let l = 0.1415;
        let l_f = 0.44 * l;
        VehicleParams { l_f, l_r: l - l_f, ..Self::table2() }
    }

    /// Table II with every "real"-fidelity option switched on (friction circle,
    /// steering servo T_s = 0.03 s / 5.51 rad/s, motor limit 0.442 m/s).
    pub fn real_fidelity() -> Self {
        VehicleParams { friction_circle: true, steering_servo: true, motor_speed_limit: true, ..Self::table2() }
    }

    /// Refuses physically impossible values with the reason.
    pub fn validate(&self) -> Result<(), ParamError> {
        let positive: [(&'static str, f64); 8] = [
            ("m", self.m),
            ("I_z", self.i_z),
            ("l_f", self.l_f),
            ("l_r", self.l_r),
            ("track", self.track),
            ("r_wheel", self.r_wheel),
            ("g", self.g),
            ("v_fade", self.v_fade),
        ];
        for (name, value) in positive {
            if !value.is_finite() {
                return Err(ParamError { name, value, reason: "must be finite" });
            }
            if value <= 0.0 {
                return Err(ParamError { name, value, reason: "must be > 0" });
            }
        }
        const C_NAMES: [&str; 4] = ["c_fl", "c_fr", "c_rl", "c_rr"];
        for (name, value) in C_NAMES.into_iter().zip(self.c) {
            if !value.is_finite() {
                return Err(ParamError { name, value, reason: "must be finite" });
            }
            if value < 0.0 {
                return Err(ParamError { name, value, reason: "cornering stiffness must be >= 0" });
            }
        }
        let delta_max = self.delta_max;
        let in_range = delta_max.is_finite() && delta_max > 0.0 && delta_max <= core::f64::consts::FRAC_PI_2;
        refuse_unless(in_range, "delta_max", delta_max, "must be in (0, pi/2]")?;
        if self.steering_servo {
            const WHY: &str = "must be > 0 when the steering servo is on";
            let time_constant = self.servo_time_constant;
            refuse_unless(time_constant.is_finite() && time_constant > 0.0, "servo_time_constant", time_constant, WHY)?;
            // An infinite rate limit is no limit: only values <= 0 and NaN (never > 0) are refused.
            let rate = self.servo_rate_max;
            refuse_unless(rate > 0.0, "servo_rate_max", rate, WHY)?;
        }
        if self.motor_speed_limit {
            const WHY: &str = "must be > 0 when the motor speed limit is on";
            let speed = self.wheel_speed_max;
            refuse_unless(speed.is_finite() && speed > 0.0, "wheel_speed_max", speed, WHY)?;
            let taper = self.motor_taper;
            refuse_unless(taper.is_finite() && taper > 0.0, "motor_taper", taper, WHY)?;
        }
        Ok(())
    }

    /// Wheel positions `(x_i, y_i)` relative to the CG, order FL, FR, RL, RR.
    pub fn wheel_positions(&self) -> [(f64, f64); 4] {
        let h = 0.5 * self.track;
        [(self.l_f, h), (self.l_f, -h), (-self.l_r, h), (-self.l_r, -h)]
    }

    /// Static normal loads N_i \[N\].
    pub fn normal_loads(&self) -> [f64; 4] {
        let l = self.l_f + self.l_r;
        let front = self.m * self.g * self.l_r / (2.0 * l);
        let rear = self.m * self.g * self.l_f / (2.0 * l);
        [front, front, rear, rear]
    }

    /// Offset of the geometric centre ahead of the CG, `x_c = (l_f - l_r)/2` \[m\].
    pub fn x_c(&self) -> f64 {
        0.5 * (self.l_f - self.l_r)
    }
}
