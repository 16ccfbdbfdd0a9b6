//! The nonlinear right-hand side (`docs/vehicle-model.md`), generic over [`Scalar`].

use crate::params::VehicleParams;
use crate::scalar::Scalar;

/// The parameters as the right-hand side reads them: each continuous one as a scalar `T`,
/// so that [`evaluate`] differentiates with respect to parameters too (with
/// [`ParamScalars`] of dual numbers) while [`VehicleParams`] serves every plain evaluation
/// (its `T::constant` values are the `f64`s themselves, so the `f64` path computes the
/// same operations on the same numbers).
pub trait ParamsOf<T: Scalar> {
    fn m(&self) -> T;
    fn i_z(&self) -> T;
    fn r_wheel(&self) -> T;
    /// Cornering stiffness of wheel `i`.
    fn c(&self, i: usize) -> T;
    fn v_fade(&self) -> T;
    fn delta_max(&self) -> T;
    fn servo_time_constant(&self) -> T;
    fn servo_rate_max(&self) -> T;
    fn wheel_speed_max(&self) -> T;
    fn motor_taper(&self) -> T;
    /// Wheel positions `(x_i, y_i)` from the CG, as [`VehicleParams::wheel_positions`].
    fn wheel_positions(&self) -> [(T, T); 4];
    /// Static normal loads, as [`VehicleParams::normal_loads`].
    fn normal_loads(&self) -> [T; 4];
    /// `x_c`, as [`VehicleParams::x_c`].
    fn x_c(&self) -> T;
    /// The fidelity switches (not differentiable).
    fn switches(&self) -> (bool, bool, bool);
}

/// The accessors of [`ParamsOf`] that read one field of the same name (`c` one element
/// of it), each value passed through `$as_scalar` (a closure: `T::constant` for
/// [`VehicleParams`], the identity for [`ParamScalars`]).
macro_rules! scalar_parameters {
    ($as_scalar:expr) => {
        scalar_parameters!($as_scalar; m, i_z, r_wheel, v_fade, delta_max, servo_time_constant, servo_rate_max, wheel_speed_max, motor_taper);
        #[inline(always)]
        fn c(&self, i: usize) -> T {
            ($as_scalar)(self.c[i])
        }
    };
    ($as_scalar:expr; $($name:ident),*) => {
        $(
            #[inline(always)]
            fn $name(&self) -> T {
                ($as_scalar)(self.$name)
            }
        )*
    };
}

impl<T: Scalar> ParamsOf<T> for VehicleParams {
    scalar_parameters!(|x| T::constant(x));
    #[inline(always)]
    fn wheel_positions(&self) -> [(T, T); 4] {
        VehicleParams::wheel_positions(self).map(|(x, y)| (T::constant(x), T::constant(y)))
    }
    #[inline(always)]
    fn normal_loads(&self) -> [T; 4] {
        VehicleParams::normal_loads(self).map(T::constant)
    }
    #[inline(always)]
    fn x_c(&self) -> T {
        T::constant(VehicleParams::x_c(self))
    }
    #[inline(always)]
    fn switches(&self) -> (bool, bool, bool) {
        (self.friction_circle, self.steering_servo, self.motor_speed_limit)
    }
}

/// [`VehicleParams`] with every continuous parameter a scalar `T` (a dual number to
/// differentiate with respect to it); the derived quantities are computed with the
/// operations of [`VehicleParams`]'s methods, in the same order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamScalars<T> {
    pub m: T,
    pub i_z: T,
    pub l_f: T,
    pub l_r: T,
    pub track: T,
    pub r_wheel: T,
    pub c: [T; 4],
    pub g: T,
    pub v_fade: T,
    pub delta_max: T,
    pub servo_time_constant: T,
    pub servo_rate_max: T,
    pub wheel_speed_max: T,
    pub motor_taper: T,
    pub friction_circle: bool,
    pub steering_servo: bool,
    pub motor_speed_limit: bool,
}

impl<T: Scalar> ParamScalars<T> {
    /// The parameters `p` as constants (derivative parts zero).
    pub fn of(p: &VehicleParams) -> Self {
        let k = T::constant;
        ParamScalars {
            m: k(p.m),
            i_z: k(p.i_z),
            l_f: k(p.l_f),
            l_r: k(p.l_r),
            track: k(p.track),
            r_wheel: k(p.r_wheel),
            c: p.c.map(k),
            g: k(p.g),
            v_fade: k(p.v_fade),
            delta_max: k(p.delta_max),
            servo_time_constant: k(p.servo_time_constant),
            servo_rate_max: k(p.servo_rate_max),
            wheel_speed_max: k(p.wheel_speed_max),
            motor_taper: k(p.motor_taper),
            friction_circle: p.friction_circle,
            steering_servo: p.steering_servo,
            motor_speed_limit: p.motor_speed_limit,
        }
    }
}

impl<T: Scalar> ParamsOf<T> for ParamScalars<T> {
    scalar_parameters!(|x| x);
    fn wheel_positions(&self) -> [(T, T); 4] {
        let h = self.track * 0.5;
        [(self.l_f, h), (self.l_f, -h), (-self.l_r, h), (-self.l_r, -h)]
    }
    fn normal_loads(&self) -> [T; 4] {
        let l = self.l_f + self.l_r;
        let front = self.m * self.g * self.l_r / (l * 2.0);
        let rear = self.m * self.g * self.l_f / (l * 2.0);
        [front, front, rear, rear]
    }
    fn x_c(&self) -> T {
        (self.l_f - self.l_r) * 0.5
    }
    fn switches(&self) -> (bool, bool, bool) {
        (self.friction_circle, self.steering_servo, self.motor_speed_limit)
    }
}

/// Number of continuous states: `x, y, psi, v_x, v_y, yaw_rate` and the four servo angles.
///
/// The servo angles are always states (an FMU has a fixed state vector); with the steering
/// servo off their derivative is zero and the applied steer is the clamped command.
pub const N_STATES: usize = 10;

/// Indices into the state vector.
pub mod idx {
    pub const X: usize = 0;
    pub const Y: usize = 1;
    pub const PSI: usize = 2;
    pub const V_X: usize = 3;
    pub const V_Y: usize = 4;
    pub const YAW_RATE: usize = 5;
    /// First servo angle (FL); FR, RL, RR follow.
    pub const SERVO: usize = 6;
}

/// Continuous state vector.
pub type State<T> = [T; N_STATES];

/// Inputs of the plant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs<T> {
    /// Steering commands \[rad\], FL, FR, RL, RR.
    pub delta: [T; 4],
    /// Drive torques [N.m].
    pub tau: [T; 4],
    /// Road friction coefficients [-].
    pub mu: [T; 4],
    /// Head wind force \[N\], positive opposes forward motion.
    pub wind_head: T,
    /// Side wind force \[N\], positive toward body +y, at the geometric centre.
    pub wind_side: T,
    /// Wind force along world +X \[N\], at the geometric centre. Rotated into the body frame
    /// with the instantaneous heading inside the right-hand side (every RK4 stage), and
    /// added to `wind_head` / `wind_side`.
    pub wind_x: T,
    /// Wind force along world +Y \[N\], at the geometric centre (see `wind_x`).
    pub wind_y: T,
}

impl<T: Scalar> Inputs<T> {
    /// Zero steer, zero torque, no wind, `mu_i = mu`.
    pub fn coasting(mu: f64) -> Self {
        let z = T::constant(0.0);
        Inputs {
            delta: [z; 4],
            tau: [z; 4],
            mu: [T::constant(mu); 4],
            wind_head: z,
            wind_side: z,
            wind_x: z,
            wind_y: z,
        }
    }
}

/// Everything the model computes at one point: derivatives and outputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluation<T> {
    pub derivatives: State<T>,
    /// Body slip angle `atan2(v_y, v_x)` \[rad\].
    pub beta: T,
    /// `hypot(v_x, v_y)` [m/s].
    pub speed: T,
    /// Body-frame lateral acceleration `dv_y/dt + r v_x` [m/s2].
    pub lateral_accel: T,
    /// Tire slip angles alpha_i \[rad\].
    pub slip_angle: [T; 4],
    /// Lateral tire forces F_y,i in the wheel frame \[N\].
    pub force_lat: [T; 4],
    /// Drive forces F_d,i in the wheel frame \[N\].
    pub force_drive: [T; 4],
    /// Steering angles actually applied \[rad\].
    pub delta_applied: [T; 4],
}

/// Applied steering angles with their sines and cosines, and the servo derivatives.
///
/// With the servo off these depend on the inputs only, so an integrator holding the
/// inputs over a step computes them once per step instead of once per stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Steering<T> {
    pub delta: [T; 4],
    pub sin: [T; 4],
    pub cos: [T; 4],
    /// `d servo_angle_i / dt` (zero with the servo off).
    pub servo_rate: [T; 4],
}

/// The steering actually applied at this state and input.
pub fn steering<T: Scalar>(p: &impl ParamsOf<T>, s: &State<T>, u: &Inputs<T>) -> Steering<T> {
    steering_commanded(p, s, &clamped_commands(p, u))
}

/// The steering commands clamped to `+-delta_max` (inputs only: once per held step).
#[inline(always)]
fn clamped_commands<T: Scalar>(p: &impl ParamsOf<T>, u: &Inputs<T>) -> [T; 4] {
    let dmax = p.delta_max();
    u.delta.map(|d| d.clamp_s(-dmax, dmax))
}

/// [`steering`] from the clamped commands.
#[inline(always)]
fn steering_commanded<T: Scalar>(p: &impl ParamsOf<T>, s: &State<T>, cmd: &[T; 4]) -> Steering<T> {
    let zero = T::constant(0.0);
    let mut st = Steering { delta: *cmd, sin: [zero; 4], cos: [zero; 4], servo_rate: [zero; 4] };
    if p.switches().1 {
        let rate = p.servo_rate_max();
        for i in 0..4 {
            let sv = s[idx::SERVO + i];
            st.servo_rate[i] = ((cmd[i] - sv) / p.servo_time_constant()).clamp_s(-rate, rate);
            st.delta[i] = sv;
        }
    }
    (st.sin, st.cos) = T::sin_cos4(st.delta);
    st
}

/// Whether `hypot(f_drive, f_lat) <= cap` certainly holds, decided without the square
/// root: `f_drive^2 + f_lat^2 < cap^2 (1 - 1e-12)`. The squares carry a relative error of a
/// few units in the last place, far inside the 1e-12 margin, so `true` implies that the
/// computed `hypot` is not above `cap` either and the friction circle would change nothing;
/// `false` (near the circle, outside it, NaN, or magnitudes below 1e-100 or above 1e150
/// where the squares could underflow or overflow) leaves the decision to the exact `hypot`
/// test. Only the cost changes: the results are bit for bit those of the `hypot` test alone.
#[inline(always)]
fn inside_friction_circle(f_drive: f64, f_lat: f64, cap: f64) -> bool {
    const LOWEST: f64 = 1e-100;
    const HIGHEST: f64 = 1e150;
    (LOWEST..HIGHEST).contains(&cap)
        && f_drive.abs() < HIGHEST
        && f_lat.abs() < HIGHEST
        && f_drive * f_drive + f_lat * f_lat < cap * cap * (1.0 - 1e-12)
}

/// Body slip angle `atan2(v_y, v_x)` \[rad\] of a state (an output of [`evaluate`]).
#[inline]
pub fn body_slip_angle<T: Scalar>(s: &State<T>) -> T {
    s[idx::V_Y].atan2(s[idx::V_X])
}

/// Speed `hypot(v_x, v_y)` [m/s] of a state (an output of [`evaluate`]).
#[inline]
pub fn speed_of<T: Scalar>(s: &State<T>) -> T {
    s[idx::V_X].hypot(s[idx::V_Y])
}

/// The tire force limit `cap_i = mu_i N_i` and the drive force `clamp(tau_i / r_wheel, +-cap_i)`
/// before the motor taper and the friction circle: functions of the parameters and inputs
/// only, so an integrator holding the inputs over a step computes them once per step.
#[derive(Clone, Copy, Debug, PartialEq)]
struct WheelDrive<T> {
    cap: [T; 4],
    drive: [T; 4],
}

#[inline(always)]
fn wheel_drive<T: Scalar>(p: &impl ParamsOf<T>, u: &Inputs<T>) -> WheelDrive<T> {
    let loads = p.normal_loads();
    let cap: [T; 4] = core::array::from_fn(|i| u.mu[i] * loads[i]);
    let r_wheel = p.r_wheel();
    WheelDrive { cap, drive: core::array::from_fn(|i| (u.tau[i] / r_wheel).clamp_s(-cap[i], cap[i])) }
}

/// Derivatives and per-wheel quantities, without the body outputs (the hot path).
struct Core<T> {
    derivatives: State<T>,
    lateral_force: T,
    slip_angle: [T; 4],
    force_lat: [T; 4],
    force_drive: [T; 4],
}

#[inline(always)]
fn core<T: Scalar>(p: &impl ParamsOf<T>, s: &State<T>, u: &Inputs<T>, st: &Steering<T>, wd: &WheelDrive<T>) -> Core<T> {
    let (friction_circle, _, motor_speed_limit) = p.switches();
    let zero = T::constant(0.0);
    let one = T::constant(1.0);
    let v_x = s[idx::V_X];
    let v_y = s[idx::V_Y];
    let r = s[idx::YAW_RATE];
    let psi = s[idx::PSI];
    let pos = p.wheel_positions();
    let v_fade = p.v_fade();
    let v_fade_sq = (v_fade * v_fade).value();

    let mut der = [zero; N_STATES];
    der[idx::SERVO..].copy_from_slice(&st.servo_rate);

    // wheel-centre velocities, body frame (u, w) and wheel frame (v_lon, v_lat); the four
    // wheels go through each stage together (straight-line code the compiler vectorizes)
    let mut v_lon = [zero; 4];
    let mut v_lat = [zero; 4];
    let mut speed_sq = [zero; 4];
    for i in 0..4 {
        let (xi, yi) = pos[i];
        let (sd, cd) = (st.sin[i], st.cos[i]);
        let ui = v_x - r * yi;
        let wi = v_y + r * xi;
        v_lon[i] = ui * cd + wi * sd;
        v_lat[i] = wi * cd - ui * sd;
        speed_sq[i] = ui * ui + wi * wi;
    }
    let slip_angle = T::atan2x4(v_lat, v_lon.map(T::abs)).map(|a| -a);
    // lateral force mu alpha C min(1, |(u, w)| / v_fade), the square root only inside the fade zone
    let mut force_lat: [T; 4] = core::array::from_fn(|i| {
        let fade = if speed_sq[i].value() < v_fade_sq { speed_sq[i].sqrt() / v_fade } else { one };
        u.mu[i] * slip_angle[i] * p.c(i) * fade
    });
    let mut force_drive = wd.drive;
    if motor_speed_limit {
        for i in 0..4 {
            if force_drive[i].value() > 0.0 {
                let scale = ((p.wheel_speed_max() - v_lon[i]) / p.motor_taper()).clamp_s(zero, one);
                force_drive[i] = force_drive[i] * scale;
            }
        }
    }
    if friction_circle {
        for i in 0..4 {
            let (f_drive, f_lat, cap) = (force_drive[i], force_lat[i], wd.cap[i]);
            if !inside_friction_circle(f_drive.value(), f_lat.value(), cap.value()) {
                let h = f_drive.hypot(f_lat);
                if h.value() > cap.value() && h.value() > 0.0 {
                    let k = cap / h;
                    force_drive[i] = f_drive * k;
                    force_lat[i] = f_lat * k;
                }
            }
        }
    }
    // wheel-frame forces into body axes, summed in wheel order
    let fx: [T; 4] = core::array::from_fn(|i| force_drive[i] * st.cos[i] - force_lat[i] * st.sin[i]);
    let fy: [T; 4] = core::array::from_fn(|i| force_drive[i] * st.sin[i] + force_lat[i] * st.cos[i]);
    let (mut fx_sum, mut fy_sum, mut mz) = (zero, zero, zero);
    for i in 0..4 {
        let (xi, yi) = pos[i];
        fx_sum = fx_sum + fx[i];
        fy_sum = fy_sum + fy[i];
        mz = mz + fy[i] * xi - fx[i] * yi;
    }
    let (sp, cp) = psi.sin_cos();
    // world-frame wind (wind_x, wind_y) in body axes: forward = x cos + y sin, left = -x sin + y cos
    let wind_head = u.wind_head - (u.wind_x * cp + u.wind_y * sp);
    let wind_side = u.wind_side + (u.wind_y * cp - u.wind_x * sp);
    mz = mz + wind_side * p.x_c();
    let lateral_force = fy_sum + wind_side;
    der[idx::X] = v_x * cp - v_y * sp;
    der[idx::Y] = v_x * sp + v_y * cp;
    der[idx::PSI] = r;
    let m = p.m();
    der[idx::V_X] = (fx_sum - wind_head) / m + r * v_y;
    der[idx::V_Y] = lateral_force / m - r * v_x;
    der[idx::YAW_RATE] = mz / p.i_z();
    Core { derivatives: der, lateral_force, slip_angle, force_lat, force_drive }
}

/// The model at one point: derivatives and all outputs.
///
/// `p` is a [`VehicleParams`] (the parameters as constants), or [`ParamScalars`] of dual
/// numbers for derivatives with respect to the parameters.
pub fn evaluate<T: Scalar>(p: &impl ParamsOf<T>, s: &State<T>, u: &Inputs<T>) -> Evaluation<T> {
    let st = steering(p, s, u);
    let c = core(p, s, u, &st, &wheel_drive(p, u));
    Evaluation {
        derivatives: c.derivatives,
        beta: body_slip_angle(s),
        speed: speed_of(s),
        lateral_accel: c.lateral_force / p.m(),
        slip_angle: c.slip_angle,
        force_lat: c.force_lat,
        force_drive: c.force_drive,
        delta_applied: st.delta,
    }
}

/// Only the derivatives (the hot path of integrators).
#[inline]
pub fn derivatives_of(p: &VehicleParams, s: &State<f64>, u: &Inputs<f64>) -> State<f64> {
    core(p, s, u, &steering(p, s, u), &wheel_drive(p, u)).derivatives
}

/// The derivatives with the steering given (valid while it does not depend on the state,
/// i.e. with the servo off) and the wheel drive given (always valid with the inputs held).
#[inline]
fn derivatives_steered(
    p: &VehicleParams,
    s: &State<f64>,
    u: &Inputs<f64>,
    st: &Steering<f64>,
    wd: &WheelDrive<f64>,
) -> State<f64> {
    core(p, s, u, st, wd).derivatives
}

/// One classical Runge-Kutta step of size `h` with inputs held constant.
pub fn rk4_step(p: &VehicleParams, s: &State<f64>, u: &Inputs<f64>, h: f64) -> State<f64> {
    rk4(p, s, u, h, &HeldSteering::new(p, s, u), &wheel_drive(p, u))
}

/// What of the steering is constant while the inputs are held: all of it with the servo
/// off (it depends on the inputs only), the clamped commands with the servo on.
enum HeldSteering {
    Fixed(Steering<f64>),
    Servo([f64; 4]),
}

impl HeldSteering {
    #[inline(always)]
    fn new(p: &VehicleParams, s: &State<f64>, u: &Inputs<f64>) -> Self {
        let cmd = clamped_commands(p, u);
        if p.steering_servo {
            HeldSteering::Servo(cmd)
        } else {
            HeldSteering::Fixed(steering_commanded(p, s, &cmd))
        }
    }
}

/// One classical RK4 step with the inputs held, for the held steering: one monomorphic
/// [`rk4_with`] per case, so each inlines its right-hand side.
#[inline]
fn rk4(
    p: &VehicleParams,
    s: &State<f64>,
    u: &Inputs<f64>,
    h: f64,
    held: &HeldSteering,
    wd: &WheelDrive<f64>,
) -> State<f64> {
    match held {
        HeldSteering::Fixed(st) => rk4_with(s, h, |x| derivatives_steered(p, x, u, st, wd)),
        HeldSteering::Servo(cmd) => {
            rk4_with(s, h, |x| derivatives_steered(p, x, u, &steering_commanded(p, x, cmd), wd))
        }
    }
}

/// Classical RK4 of `f` over `h`: `s + h/6 (k1 + 2 k2 + 2 k3 + k4)`, the sum accumulated
/// in that order as the stages come (the same operations as the textbook form, so the same
/// bits), the stages in a loop so that `f` has one call site.
#[inline(always)]
fn rk4_with(s: &State<f64>, h: f64, f: impl Fn(&State<f64>) -> State<f64>) -> State<f64> {
    let mut sum = [0.0; N_STATES];
    let mut x = *s;
    for stage in 0..4 {
        let k = f(&x);
        if stage == 0 {
            sum = k;
        } else {
            let weight = if stage == 3 { 1.0 } else { 2.0 };
            for j in 0..N_STATES {
                sum[j] += weight * k[j];
            }
        }
        if stage < 3 {
            let c = if stage < 2 { 0.5 * h } else { h };
            x = *s;
            for j in 0..N_STATES {
                x[j] += c * k[j];
            }
        }
    }
    let mut o = *s;
    for j in 0..N_STATES {
        o[j] += h / 6.0 * sum[j];
    }
    o
}

/// Number of RK4 sub-steps [`integrate`] takes for a step `h` (at least 1).
///
/// The slack keeps a step a few rounding units above a multiple of `max_step` (as masters
/// that accumulate time produce) from costing one more sub-step. Callers facing untrusted
/// `h` and `max_step` check this count before integrating (it can be astronomically large).
pub fn substeps(h: f64, max_step: f64) -> usize {
    let q = h / max_step - 1e-9;
    // ceil(q) without a call: baseline x86-64 has no rounding instruction, and `f64::ceil`
    // costs a libm call per step. Exact for 0 <= q < 2^52 (the truncation is exact there);
    // anything else (negative, huge, infinite, NaN) takes `ceil` itself.
    if (0.0..4503599627370496.0).contains(&q) {
        let truncated = q as u64;
        let up = truncated + u64::from((truncated as f64) < q);
        up.max(1) as usize
    } else {
        q.ceil().max(1.0) as usize
    }
}

/// Real-axis stability limit of classical RK4: `|h lambda| <= 2.785` for a real negative
/// eigenvalue `lambda`.
pub const RK4_REAL_STABILITY_LIMIT: f64 = 2.785;

/// An upper bound [1/s] of the fastest decay rate of the velocity dynamics at these
/// parameters and inputs, from the tires' velocity stiffness.
///
/// A tire's lateral force changes with the contact-point velocity by at most
/// `k_i = (pi/2) mu_i C_i / v_fade`: above `v_fade` the slip-angle slope is
/// `mu C / |v| <= mu C / v_fade`, and inside the fade zone the force grows like
/// `mu C |alpha| |v| / v_fade` with `|alpha| <= pi/2`, largest at standstill. A unit force
/// at wheel `i` accelerates the body velocity `(v_x, v_y, r)` by at most
/// `1/m + (x_i^2 + y_i^2)/I_z` in the mass metric, so the spectral radius of the velocity
/// Jacobian is at most `sum_i k_i (1/m + (x_i^2 + y_i^2)/I_z)` (a sum of rank-one
/// positive terms). The drive-motor taper adds `|tau_i| / (r_wheel motor_taper)` per
/// wheel when the speed limit is on, and the steering servo its rate `1/servo_time_constant`.
pub fn stiffness_rate_bound(p: &VehicleParams, u: &Inputs<f64>) -> f64 {
    let half_track = 0.5 * p.track;
    let lever_sq = [p.l_f * p.l_f, p.l_f * p.l_f, p.l_r * p.l_r, p.l_r * p.l_r].map(|x2| x2 + half_track * half_track);
    let mut rate = 0.0;
    for i in 0..4 {
        let mut stiffness = core::f64::consts::FRAC_PI_2 * u.mu[i].abs() * p.c[i] / p.v_fade;
        if p.motor_speed_limit {
            stiffness += u.tau[i].abs() / (p.r_wheel * p.motor_taper);
        }
        rate += stiffness * (1.0 / p.m + lever_sq[i] / p.i_z);
    }
    if p.steering_servo {
        rate = rate.max(1.0 / p.servo_time_constant);
    }
    rate
}

/// The longest RK4 step that keeps the linearised tire dynamics stable at these
/// parameters and inputs, with a 10 % margin on [`RK4_REAL_STABILITY_LIMIT`]
/// (`f64::INFINITY` when nothing is stiff, e.g. zero friction).
pub fn stable_rk4_step(p: &VehicleParams, u: &Inputs<f64>) -> f64 {
    let rate = stiffness_rate_bound(p, u);
    if rate > 0.0 {
        0.9 * RK4_REAL_STABILITY_LIMIT / rate
    } else {
        f64::INFINITY
    }
}

/// Integrates over `[0, h]` with RK4 sub-steps no longer than `max_step`, inputs held.
/// With the servo off the steering trigonometry is computed once for the whole interval;
/// the tire force limits and drive forces always are (they depend on the inputs only).
pub fn integrate(p: &VehicleParams, s: &State<f64>, u: &Inputs<f64>, h: f64, max_step: f64) -> State<f64> {
    let n = substeps(h, max_step);
    let dt = h / n as f64;
    let held = HeldSteering::new(p, s, u);
    let wd = wheel_drive(p, u);
    let mut x = *s;
    for _ in 0..n {
        x = rk4(p, &x, u, dt, &held, &wd);
        flush_negligible(&mut x);
    }
    x
}

/// States smaller in magnitude than this are set to exactly zero after each sub-step.
///
/// A car coasting to rest decays exponentially (the faded tire forces are proportional to
/// the speed), so within about a second its velocities reach the subnormal range, where
/// x86 arithmetic is some 30 times slower. 1e-150 (m, m/s, rad, rad/s) is physically
/// nothing, and squares of it stay normal.
pub const NEGLIGIBLE: f64 = 1e-150;

#[inline]
fn flush_negligible(x: &mut State<f64>) {
    for v in x.iter_mut() {
        if v.abs() < NEGLIGIBLE {
            *v = 0.0;
        }
    }
}

/// A state at straight running with speed `v` (everything else zero).
pub fn straight_running(v: f64) -> State<f64> {
    let mut s = [0.0; N_STATES];
    s[idx::V_X] = v;
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::test_rng::next_unit as next;

    /// `rk4_step` (held steering, stages in a loop, the sum accumulated as they come) is bit
    /// for bit the textbook RK4 of `derivatives_of`, in both fidelities.
    #[test]
    fn rk4_step_is_the_textbook_rk4_bit_for_bit() {
        let seed = core::cell::Cell::new(23u64);
        let uniform = || {
            let mut v = seed.get();
            let x = next(&mut v);
            seed.set(v);
            x
        };
        let r = |scale: f64| scale * (2.0 * uniform() - 1.0);
        for p in [VehicleParams::table2(), VehicleParams::real_fidelity()] {
            for _ in 0..2_000 {
                let mut s = [0.0; N_STATES];
                s[idx::X] = r(5.0);
                s[idx::Y] = r(5.0);
                s[idx::PSI] = r(20.0);
                s[idx::V_X] = r(1.0);
                s[idx::V_Y] = r(0.3);
                s[idx::YAW_RATE] = r(3.0);
                for i in 0..4 {
                    s[idx::SERVO + i] = r(1.6);
                }
                let mut u = Inputs::coasting(0.2 + uniform());
                u.delta = [r(2.0), r(2.0), r(2.0), r(2.0)];
                u.tau = [r(0.05), r(0.05), r(0.05), r(0.05)];
                u.wind_x = r(0.5);
                u.wind_side = r(0.5);
                let h = 1e-4 + 1e-3 * uniform();
                let f = |x: &State<f64>| derivatives_of(&p, x, &u);
                let add = |k: &State<f64>, c: f64| core::array::from_fn::<f64, N_STATES, _>(|j| s[j] + c * k[j]);
                let k1 = f(&s);
                let k2 = f(&add(&k1, 0.5 * h));
                let k3 = f(&add(&k2, 0.5 * h));
                let k4 = f(&add(&k3, h));
                let want: State<f64> =
                    core::array::from_fn(|j| s[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
                let got = rk4_step(&p, &s, &u, h);
                assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{s:?} {u:?}");
            }
        }
    }

    /// The call-free `ceil` of [`substeps`] is `ceil` exactly: at and around integers, on
    /// both sides of 2^52, for tiny, negative and non-finite ratios.
    #[test]
    fn substeps_equals_the_ceil_formula() {
        let reference = |h: f64, max_step: f64| (h / max_step - 1e-9).ceil().max(1.0) as usize;
        let mut seed = 17u64;
        let mut cases: Vec<(f64, f64)> = vec![
            (1e-3, 5e-4),
            (1e-3 + 1e-18, 5e-4),
            (1e-3 * (1.0 + 1e-12), 5e-4),
            (1e-3, 1e-3),
            (0.0, 1e-3),
            (-1.0, 1e-3),
            (1e-300, 1.0),
            (1.0, 1e-300),
            (f64::INFINITY, 1.0),
            (f64::NAN, 1.0),
            (4503599627370496.0, 1.0),
            (4503599627370495.5, 1.0),
            (9007199254740993.0, 1.0),
            (1e20, 1.0),
        ];
        for _ in 0..200_000 {
            let max_step = 10f64.powf(-6.0 * next(&mut seed)) * 1e-3;
            let k = (next(&mut seed) * 1e4).floor();
            // multiples of max_step, a few ulps either side, and arbitrary ratios
            let h = match (next(&mut seed) * 3.0) as u32 {
                0 => k * max_step,
                1 => k * max_step * (1.0 + (next(&mut seed) - 0.5) * 1e-12),
                _ => next(&mut seed) * 1e4 * max_step,
            };
            cases.push((h, max_step));
        }
        for (h, max_step) in cases {
            assert_eq!(substeps(h, max_step), reference(h, max_step), "h = {h:e}, max_step = {max_step:e}");
        }
    }

    /// The shortcut decides "inside" only where the exact test (`hypot > cap`) would not
    /// scale the forces: so the right-hand side is bit for bit the one without it. Points
    /// on, just inside and just outside the circle at every scale, signs, zeros, subnormal,
    /// huge and non-finite values.
    #[test]
    fn friction_circle_shortcut_only_skips_what_the_hypot_test_would_skip() {
        let mut seed = 7u64;
        let (mut shortcut, mut near_and_inside) = (0usize, 0usize);
        let mut check = |a: f64, b: f64, cap: f64| {
            if inside_friction_circle(a, b, cap) {
                assert!(a.hypot(b) <= cap, "a = {a:e}, b = {b:e}, cap = {cap:e}");
                shortcut += 1;
            }
        };
        for scale in [1e-300, 1e-160, 1e-100, 1e-20, 1e-3, 1.0, 9.81, 1e3, 1e20, 1e149, 1e151, 1e300] {
            for _ in 0..20_000 {
                let cap = scale * (0.5 + next(&mut seed));
                let angle = 2.0 * core::f64::consts::PI * next(&mut seed);
                // radius from 0.9 to 1.1 of the cap, denser within 1e-9 of the circle
                let rel = if next(&mut seed) < 0.5 {
                    0.9 + 0.2 * next(&mut seed)
                } else {
                    1.0 + 1e-9 * (2.0 * next(&mut seed) - 1.0) * 10f64.powi(-(next(&mut seed) * 7.0) as i32)
                };
                let (a, b) = (cap * rel * angle.cos(), cap * rel * angle.sin());
                check(a, b, cap);
                check(-a, b, cap);
                check(a, -b, cap);
                check(b, a, cap);
                if rel < 1.0 - 1e-11 && (1e-100..1e149).contains(&cap) && inside_friction_circle(a, b, cap) {
                    near_and_inside += 1;
                }
            }
        }
        for (a, b, cap) in [
            (1.0, 0.0, 1.0),
            (0.0, 1.0, 1.0),
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 1.0),
            (f64::MIN_POSITIVE / 4.0, 0.0, f64::MIN_POSITIVE / 8.0),
            (f64::NAN, 0.0, 1.0),
            (0.0, f64::INFINITY, 1.0),
            (1e200, 1e200, 1e201),
            (1.0, 1.0, f64::INFINITY),
            (1.0, 1.0, f64::NAN),
            (-3.0, 4.0, 5.0),
            (-3.0, 4.0, 5.0 * (1.0 + 1e-13)),
        ] {
            check(a, b, cap);
        }
        // it does take the shortcut where the forces are well inside the circle
        assert!(shortcut > 200_000, "{shortcut}");
        assert!(near_and_inside > 30_000, "{near_and_inside}");
        assert!(!inside_friction_circle(3.0, 4.0, 5.0), "on the circle: the exact test decides");
        assert!(!inside_friction_circle(f64::NAN, 0.0, 1.0));
        assert!(inside_friction_circle(3.0, 4.0, 5.0 * (1.0 + 1e-11)));
    }
}
