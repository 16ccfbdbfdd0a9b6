//! The Nigel plant FMU: the nonlinear 4WD4WS yaw-plane model of `nigel-vehicle` behind
//! the shared FMI 2.0 layer. This file is only the binding: the declaration of the
//! variables (the one source of the XML and the dispatch) and the [`Model`] impl.

// `!(x > 0.0)` is deliberate throughout: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use fmi_export::model_description::DefaultExperiment;
use fmi_export::{
    declared_name, Access, Capabilities, DeclarationSpec, Initial, InstantiateContext, Interfaces, Model, ModelError,
    ModelResult, Start, VarHandle, Variables,
};
use nigel_vehicle::dynamics::idx;
use nigel_vehicle::{evaluate, Dual, Evaluation, Inputs, ParamScalars, Scalar, State, VehicleParams, N_STATES, WHEELS};

/// The model identifier (file name of the shared library and of the `.fmu`).
pub const MODEL_IDENTIFIER: &str = "nigel_plant";

/// The equations and the initial state, for `documentation/index.html`.
pub const DOCUMENTATION: &str = include_str!("documentation.html");

/// Largest number of RK4 sub-steps one `fmi2DoStep` may take (about 0.5 s of computing at
/// some 0.5 us a sub-step); a longer step is refused before it starts (`fmi2Discard`)
/// instead of keeping the importer.
pub const MAX_SUBSTEPS_PER_STEP: usize = 1_000_000;

/// The declared range of a parameter: what a 1:14 to full-size car, on Earth-like gravity,
/// can have (the defaults are the 2.68 kg Nigel). The bounds also keep the tires'
/// stability step, and so the work of a step, bounded. They lie inside the vehicle model's
/// own checks ([`VehicleParams::validate`], tested), so the setters check nothing more.
fn parameter_range(p: Param) -> (f64, f64) {
    match p {
        Param::Mass => (0.1, 5000.0),
        Param::YawInertia => (1e-4, 1e4),
        Param::CgToFront | Param::CgToRear => (5e-3, 5.0),
        Param::Track => (0.01, 3.0),
        Param::WheelRadius => (5e-3, 1.0),
        Param::CorneringStiffness(_) => (0.1, 1e6),
        Param::Gravity => (1.0, 30.0),
        Param::FadeSpeed => (1e-3, 1.0),
        Param::SteerLimit => (1e-3, std::f64::consts::FRAC_PI_2),
        Param::ServoTimeConstant => (1e-3, 1.0),
        Param::ServoRateMax => (0.01, 100.0),
        Param::WheelSpeedMax => (0.01, 100.0),
        Param::MotorTaper => (1e-3, 10.0),
        Param::CsSubstepMax => (1e-6, 0.1),
    }
}

/// Default upper bound of the internal RK4 sub-step in Co-Simulation [s]. The sub-step
/// actually taken is also bounded by the tires' stability limit
/// ([`nigel_vehicle::dynamics::stable_rk4_step`]), so no accepted friction makes it unstable.
pub const DEFAULT_CS_SUBSTEP_MAX: f64 = 5e-4;

/// Largest accepted road-tire friction coefficient: above any tire on any road (racing
/// slicks on dry asphalt reach about 2).
pub const MU_MAX: f64 = 3.0;

/// Real parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Param {
    Mass,
    YawInertia,
    CgToFront,
    CgToRear,
    Track,
    WheelRadius,
    CorneringStiffness(usize),
    Gravity,
    FadeSpeed,
    SteerLimit,
    ServoTimeConstant,
    ServoRateMax,
    WheelSpeedMax,
    MotorTaper,
    CsSubstepMax,
}

/// Boolean parameters (fidelity switches).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switch {
    FrictionCircle,
    SteeringServo,
    MotorSpeedLimit,
}

/// Inputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    Steer(usize),
    Torque(usize),
    Friction(usize),
    WindHead,
    WindSide,
    /// World-frame wind, rotated into the body frame with the instantaneous heading.
    WindX,
    WindY,
}

/// Calculated outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    Beta,
    Speed,
    LateralAccel,
    SlipAngle(usize),
    ForceLat(usize),
    ForceDrive(usize),
    SteerApplied(usize),
}

/// What a value reference stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlantVar {
    Param(Param),
    Switch(Switch),
    Input(Input),
    /// Continuous state `i` of [`nigel_vehicle::State`].
    State(usize),
    /// Time derivative of state `i`.
    Derivative(usize),
    /// Initial value of body state `i` (`x_start .. yaw_rate_start`): a fixed parameter, the
    /// state's start (the state itself is `initial="calculated"` from it).
    StateStart(usize),
    Output(Output),
}

const STATE_NAMES: [&str; N_STATES] =
    ["x", "y", "psi", "v_x", "v_y", "yaw_rate", "servo_angle_fl", "servo_angle_fr", "servo_angle_rl", "servo_angle_rr"];
/// The body states `x .. yaw_rate`, whose initial values are the parameters `*_start`.
pub const N_BODY_STATES: usize = 6;
/// Unit, unit of the derivative, description.
const STATE_INFO: [(&str, &str, &str); N_STATES] = [
    ("m", "m/s", "global position X of the CG"),
    ("m", "m/s", "global position Y of the CG"),
    ("rad", "rad/s", "yaw angle, counter-clockwise positive"),
    ("m/s", "m/s2", "longitudinal velocity (body frame)"),
    ("m/s", "m/s2", "lateral velocity (body frame)"),
    ("rad/s", "rad/s2", "yaw rate"),
    ("rad", "rad/s", "steering servo angle FL (a state only when steering_servo is on)"),
    ("rad", "rad/s", "steering servo angle FR"),
    ("rad", "rad/s", "steering servo angle RL"),
    ("rad", "rad/s", "steering servo angle RR"),
];
/// The knowns of the dynamics (states and inputs), as the declaration returned them.
struct Knowns {
    states: Vec<VarHandle>,
    steer: Vec<VarHandle>,
    torque: Vec<VarHandle>,
    friction: Vec<VarHandle>,
    wind_head: VarHandle,
    wind_side: VarHandle,
    wind_x: VarHandle,
    wind_y: VarHandle,
}

impl Knowns {
    /// What the body dynamics depend on: all velocities, servo angles and wheel inputs, the
    /// world-frame wind through the heading psi, and of the body-frame wind the head wind
    /// for the longitudinal equation only, the side wind for the lateral and yaw equations
    /// only (it acts at the geometric centre).
    fn body(&self, longitudinal: bool) -> Vec<VarHandle> {
        let mut k = self.states[idx::V_X..].to_vec();
        for i in 0..4 {
            k.extend([self.steer[i], self.torque[i], self.friction[i]]);
        }
        k.extend([
            if longitudinal { self.wind_head } else { self.wind_side },
            self.wind_x,
            self.wind_y,
            self.states[idx::PSI],
        ]);
        k
    }

    /// What a per-wheel output depends on: the applied steering angle is the servo state
    /// (servo on) or the command (servo off); the slip angle adds the body velocities; the
    /// forces add the friction and the torque (the friction circle couples them).
    fn wheel(&self, output: fn(usize) -> Output, i: usize) -> Vec<VarHandle> {
        let s = &self.states;
        let mut k = vec![s[idx::SERVO + i], self.steer[i]];
        if output(i) != Output::SteerApplied(i) {
            k.extend([s[idx::V_X], s[idx::V_Y], s[idx::YAW_RATE]]);
        }
        if matches!(output(i), Output::ForceLat(_) | Output::ForceDrive(_)) {
            k.extend([self.torque[i], self.friction[i]]);
        }
        k
    }
}

fn build_declaration() -> DeclarationSpec<PlantVar> {
    let d = VehicleParams::table2();
    let mut v = Variables::<PlantVar>::new();
    let input = PlantVar::Input;

    // inputs
    let steer = v
        .family("delta", &WHEELS, |d, _| {
            d.input(0.0).unit("rad").describe("steering command, clamped to [-delta_max, delta_max]")
        })
        .bind(|i| input(Input::Steer(i)));
    let torque = v
        .family("tau", &WHEELS, |d, _| d.input(0.0).unit("N.m").describe("drive torque at the wheel"))
        .bind(|i| input(Input::Torque(i)));
    let friction = v
        .family("mu", &WHEELS, |d, _| {
            d.input(0.4).min(0.0).max(MU_MAX).describe("road-tire friction coefficient, 0 .. 3")
        })
        .bind(|i| input(Input::Friction(i)));
    let winds = [
        ("wind_head", Input::WindHead, "head wind force, positive opposes forward motion"),
        ("wind_side", Input::WindSide, "side wind force toward body +y, at the geometric centre"),
        (
            "wind_x",
            Input::WindX,
            "wind force along world +X at the geometric centre, rotated with the instantaneous psi",
        ),
        (
            "wind_y",
            Input::WindY,
            "wind force along world +Y at the geometric centre, rotated with the instantaneous psi",
        ),
    ];
    let [wind_head, wind_side, wind_x, wind_y] =
        winds.map(|(name, which, text)| v.real(name).input(0.0).unit("N").describe(text).bind(input(which)));

    // initial state of the body: parameters, declared before the states so that restoring
    // a serialized FMU state sets them first and the saved states after them
    for (i, name) in STATE_NAMES.iter().take(N_BODY_STATES).enumerate() {
        let (unit, _, text) = STATE_INFO[i];
        v.real(declared_name(format!("{name}_start")))
            .parameter(0.0)
            .unit(unit)
            .describe(declared_name(format!("initial value of {name} ({text})")))
            .bind(PlantVar::StateStart(i));
    }

    // states (the first six are outputs too, their start values calculated from the
    // parameters *_start) and their derivatives
    let states: Vec<VarHandle> = (0..N_STATES)
        .map(|i| {
            let (unit, _, text) = STATE_INFO[i];
            let mut state = v.real(STATE_NAMES[i]).state(0.0, i < idx::SERVO);
            if i < N_BODY_STATES {
                state = state.start_value(Start::None, Initial::Calculated);
            }
            state.unit(unit).describe(text).bind(PlantVar::State(i))
        })
        .collect();
    let k = Knowns { states, steer, torque, friction, wind_head, wind_side, wind_x, wind_y };

    // outputs
    let s = &k.states;
    let output = PlantVar::Output;
    v.real("beta")
        .output([s[idx::V_X], s[idx::V_Y]])
        .unit("rad")
        .describe("body slip angle atan2(v_y, v_x)")
        .bind(output(Output::Beta));
    v.real("speed")
        .output([s[idx::V_X], s[idx::V_Y]])
        .unit("m/s")
        .describe("hypot(v_x, v_y)")
        .bind(output(Output::Speed));
    v.real("lateral_accel")
        .output(k.body(false))
        .unit("m/s2")
        .describe("body-frame lateral acceleration dv_y/dt + r v_x")
        .bind(output(Output::LateralAccel));
    type Per = (fn(usize) -> Output, &'static str, &'static str, &'static str);
    let per_wheel_outputs: [Per; 4] = [
        (Output::SlipAngle, "slip_angle", "rad", "tire slip angle"),
        (Output::ForceLat, "force_lat", "N", "lateral tire force (wheel frame)"),
        (Output::ForceDrive, "force_drive", "N", "drive force (wheel frame), capped by friction"),
        (Output::SteerApplied, "delta_applied", "rad", "steering angle actually applied"),
    ];
    for (make, stem, unit, text) in per_wheel_outputs {
        v.family(stem, &WHEELS, |d, i| d.output(k.wheel(make, i)).unit(unit).describe(text)).bind(|i| output(make(i)));
    }

    for i in 0..N_STATES {
        let deps = match i {
            idx::X | idx::Y => vec![s[idx::PSI], s[idx::V_X], s[idx::V_Y]],
            idx::PSI => vec![s[idx::YAW_RATE]],
            idx::V_X => k.body(true),
            idx::V_Y | idx::YAW_RATE => k.body(false),
            servo => vec![s[servo], k.steer[servo - idx::SERVO]],
        };
        v.real(declared_name(format!("der({})", STATE_NAMES[i])))
            .derivative(s[i], deps)
            .unit(STATE_INFO[i].1)
            .bind(PlantVar::Derivative(i));
    }

    // parameters
    let params: [(&'static str, Param, f64, &'static str, &'static str); 18] = [
        ("m", Param::Mass, d.m, "kg", "vehicle mass"),
        ("I_z", Param::YawInertia, d.i_z, "kg.m2", "yaw moment of inertia"),
        ("l_f", Param::CgToFront, d.l_f, "m", "CG to front axle"),
        ("l_r", Param::CgToRear, d.l_r, "m", "CG to rear axle"),
        ("track", Param::Track, d.track, "m", "track width (full)"),
        ("r_wheel", Param::WheelRadius, d.r_wheel, "m", "wheel radius"),
        ("c_fl", Param::CorneringStiffness(0), d.c[0], "N/rad", "cornering stiffness FL"),
        ("c_fr", Param::CorneringStiffness(1), d.c[1], "N/rad", "cornering stiffness FR"),
        ("c_rl", Param::CorneringStiffness(2), d.c[2], "N/rad", "cornering stiffness RL"),
        ("c_rr", Param::CorneringStiffness(3), d.c[3], "N/rad", "cornering stiffness RR"),
        ("g", Param::Gravity, d.g, "m/s2", "gravity"),
        ("v_fade", Param::FadeSpeed, d.v_fade, "m/s", "speed below which tire forces fade to zero"),
        ("delta_max", Param::SteerLimit, d.delta_max, "rad", "steering limit"),
        (
            "servo_time_constant",
            Param::ServoTimeConstant,
            d.servo_time_constant,
            "s",
            "steering servo time constant (real fidelity)",
        ),
        ("servo_rate_max", Param::ServoRateMax, d.servo_rate_max, "rad/s", "steering servo rate limit (real fidelity)"),
        (
            "wheel_speed_max",
            Param::WheelSpeedMax,
            d.wheel_speed_max,
            "m/s",
            "motor speed limit as wheel rolling speed (real fidelity)",
        ),
        (
            "motor_taper",
            Param::MotorTaper,
            d.motor_taper,
            "m/s",
            "width of the linear drive-force taper below wheel_speed_max",
        ),
        (
            "cs_substep_max",
            Param::CsSubstepMax,
            DEFAULT_CS_SUBSTEP_MAX,
            "s",
            "Co-Simulation: largest internal RK4 sub-step",
        ),
    ];
    for (name, p, start, unit, text) in params {
        let (min, max) = parameter_range(p);
        v.real(name).parameter(start).unit(unit).describe(text).min(min).max(max).bind(PlantVar::Param(p));
    }
    let switches = [
        (Switch::FrictionCircle, "friction_circle", "real fidelity: friction-circle tire, hypot(F_d, F_y) <= mu N"),
        (Switch::SteeringServo, "steering_servo", "real fidelity: first-order rate-limited steering servo"),
        (Switch::MotorSpeedLimit, "motor_speed_limit", "real fidelity: drive motor speed limit"),
    ];
    for (s, name, text) in switches {
        v.boolean(name).parameter(false).describe(text).bind(PlantVar::Switch(s));
    }

    DeclarationSpec {
        model_name: "Nigel 4WD4WS plant",
        model_identifier: MODEL_IDENTIFIER,
        description: "Nonlinear yaw-plane dynamics of the over-actuated 1:14 vehicle Nigel \
                      (independent four-wheel drive and steer), paper Section III",
        version: env!("CARGO_PKG_VERSION"),
        interfaces: Interfaces { model_exchange: true, co_simulation: true },
        capabilities: Capabilities { directional_derivatives: true, fmu_state: true, serialize_fmu_state: true },
        default_experiment: Some(DefaultExperiment {
            start_time: Some(0.0),
            stop_time: Some(10.0),
            tolerance: Some(1e-8),
            step_size: Some(1e-3),
        }),
        variables: v.into_vec(),
        ..Default::default()
    }
}

/// The plant instance: parameters, inputs, state, and a lazily computed evaluation.
#[derive(Clone, Debug)]
pub struct Plant {
    pub params: VehicleParams,
    pub inputs: Inputs<f64>,
    pub state: State<f64>,
    /// The parameters `x_start .. yaw_rate_start`: the initial body state.
    pub state_start: [f64; N_BODY_STATES],
    pub cs_substep_max: f64,
    cache: Option<Evaluation<f64>>,
}

impl Default for Plant {
    fn default() -> Self {
        Plant {
            params: VehicleParams::table2(),
            inputs: Inputs::coasting(0.4),
            state: [0.0; N_STATES],
            state_start: [0.0; N_BODY_STATES],
            cs_substep_max: DEFAULT_CS_SUBSTEP_MAX,
            cache: None,
        }
    }
}

/// The field of parameter `which` in `$params` (a [`VehicleParams`] or [`ParamScalars`]:
/// the same field names), `None` for `cs_substep_max`, which is the FMU's own.
macro_rules! param_field {
    ($params:expr, $which:expr) => {
        Some(match $which {
            Param::Mass => &mut $params.m,
            Param::YawInertia => &mut $params.i_z,
            Param::CgToFront => &mut $params.l_f,
            Param::CgToRear => &mut $params.l_r,
            Param::Track => &mut $params.track,
            Param::WheelRadius => &mut $params.r_wheel,
            Param::CorneringStiffness(i) => &mut $params.c[i],
            Param::Gravity => &mut $params.g,
            Param::FadeSpeed => &mut $params.v_fade,
            Param::SteerLimit => &mut $params.delta_max,
            Param::ServoTimeConstant => &mut $params.servo_time_constant,
            Param::ServoRateMax => &mut $params.servo_rate_max,
            Param::WheelSpeedMax => &mut $params.wheel_speed_max,
            Param::MotorTaper => &mut $params.motor_taper,
            Param::CsSubstepMax => return None,
        })
    };
}

fn param_slot(p: &mut VehicleParams, which: Param) -> Option<&mut f64> {
    param_field!(p, which)
}

/// [`param_slot`] of the parameters as scalars of the right-hand side.
fn param_scalar_slot<T>(p: &mut ParamScalars<T>, which: Param) -> Option<&mut T> {
    param_field!(p, which)
}

fn switch_slot(p: &mut VehicleParams, which: Switch) -> &mut bool {
    match which {
        Switch::FrictionCircle => &mut p.friction_circle,
        Switch::SteeringServo => &mut p.steering_servo,
        Switch::MotorSpeedLimit => &mut p.motor_speed_limit,
    }
}

fn input_slot<T>(u: &mut Inputs<T>, which: Input) -> &mut T {
    match which {
        Input::Steer(i) => &mut u.delta[i],
        Input::Torque(i) => &mut u.tau[i],
        Input::Friction(i) => &mut u.mu[i],
        Input::WindHead => &mut u.wind_head,
        Input::WindSide => &mut u.wind_side,
        Input::WindX => &mut u.wind_x,
        Input::WindY => &mut u.wind_y,
    }
}

fn output_of<T: Copy>(e: &Evaluation<T>, which: Output) -> T {
    match which {
        Output::Beta => e.beta,
        Output::Speed => e.speed,
        Output::LateralAccel => e.lateral_accel,
        Output::SlipAngle(i) => e.slip_angle[i],
        Output::ForceLat(i) => e.force_lat[i],
        Output::ForceDrive(i) => e.force_drive[i],
        Output::SteerApplied(i) => e.delta_applied[i],
    }
}

/// The parameter checks of `nigel-vehicle` with every fidelity switch on: a parameter of a
/// switched-off feature must be possible too (it is refused even while its switch is off,
/// so that switching it on later cannot make an accepted instance impossible).
fn validate_all(p: &VehicleParams) -> Result<(), String> {
    let strict = VehicleParams { friction_circle: true, steering_servo: true, motor_speed_limit: true, ..*p };
    strict.validate().map_err(|e| e.to_string())
}

impl Plant {
    /// The RK4 sub-step of Co-Simulation: `cs_substep_max`, or shorter where the tire
    /// forces' stability limit at the current friction and torques requires it.
    pub fn substep(&self) -> f64 {
        self.cs_substep_max.min(nigel_vehicle::dynamics::stable_rk4_step(&self.params, &self.inputs))
    }

    /// The evaluation at the current state and inputs (computed once per change).
    pub fn evaluation(&mut self) -> &Evaluation<f64> {
        let (p, s, u) = (&self.params, &self.state, &self.inputs);
        self.cache.get_or_insert_with(|| evaluate(p, s, u))
    }

    fn changed(&mut self) {
        self.cache = None;
    }
}

/// The plant dispatches on its own binding (states, derivatives, outputs from one cached
/// evaluation, directional derivatives by dual numbers).
impl Access<Plant> for PlantVar {}

impl Model for Plant {
    type Binding = PlantVar;

    fmi_export::declare_model!(PlantVar, build_declaration());

    fn instantiate(_context: &InstantiateContext) -> ModelResult<Self> {
        Ok(Plant::default())
    }

    fn get_real(&mut self, b: PlantVar) -> ModelResult<f64> {
        Ok(match b {
            PlantVar::Param(Param::CsSubstepMax) => self.cs_substep_max,
            PlantVar::Param(p) => *param_slot(&mut self.params, p).ok_or("no such parameter")?,
            PlantVar::Input(i) => *input_slot(&mut self.inputs, i),
            PlantVar::State(i) => self.state[i],
            PlantVar::StateStart(i) => self.state_start[i],
            PlantVar::Derivative(i) => self.evaluation().derivatives[i],
            // the body outputs depend on the state alone: computed as `evaluate` does, without
            // the whole right-hand side (a master reads them at every communication point)
            PlantVar::Output(Output::Beta) => nigel_vehicle::dynamics::body_slip_angle(&self.state),
            PlantVar::Output(Output::Speed) => nigel_vehicle::dynamics::speed_of(&self.state),
            PlantVar::Output(o) => output_of(self.evaluation(), o),
            PlantVar::Switch(_) => return Err("a Boolean, not a Real".into()),
        })
    }

    fn set_real(&mut self, b: PlantVar, value: f64) -> ModelResult {
        match b {
            // its range is declared; nothing else depends on it
            PlantVar::Param(Param::CsSubstepMax) => self.cs_substep_max = value,
            // the declared ranges lie inside what the vehicle model accepts
            PlantVar::Param(p) => *param_slot(&mut self.params, p).ok_or("no such parameter")? = value,
            PlantVar::Input(i) => *input_slot(&mut self.inputs, i) = value,
            PlantVar::State(i) => self.state[i] = value,
            // a fixed parameter: set only before initialization ends (and when an FMU state is
            // restored, before the saved states), so the calculated state follows it
            PlantVar::StateStart(i) => {
                self.state_start[i] = value;
                self.state[i] = value;
            }
            PlantVar::Derivative(_) | PlantVar::Output(_) => return Err("a calculated variable cannot be set".into()),
            PlantVar::Switch(_) => return Err("a Boolean, not a Real".into()),
        }
        self.changed();
        Ok(())
    }

    /// Only the calculated variables refuse (the layer refuses to set them first): the
    /// declaration's ranges are the only checks of the others.
    fn setter_may_refuse(b: PlantVar) -> bool {
        matches!(b, PlantVar::Derivative(_) | PlantVar::Output(_))
    }

    fn get_boolean(&mut self, b: PlantVar) -> ModelResult<bool> {
        match b {
            PlantVar::Switch(s) => Ok(*switch_slot(&mut self.params, s)),
            _ => Err("not a Boolean variable".into()),
        }
    }

    fn set_boolean(&mut self, b: PlantVar, value: bool) -> ModelResult {
        let PlantVar::Switch(s) = b else { return Err("not a Boolean variable".into()) };
        *switch_slot(&mut self.params, s) = value;
        self.changed();
        Ok(())
    }

    /// The vehicle model's own parameter checks, behind the declared ranges (which lie
    /// inside them, so this refuses nothing the layer let through).
    fn exit_initialization(&mut self) -> ModelResult {
        Ok(validate_all(&self.params)?)
    }

    fn do_step(&mut self, _time: f64, step: f64) -> ModelResult {
        let substep = self.substep();
        let substeps = nigel_vehicle::dynamics::substeps(step, substep);
        if substeps > MAX_SUBSTEPS_PER_STEP {
            return Err(ModelError::Discard(format!(
                "a step of {step} s would take {substeps} RK4 sub-steps of {substep} s (the smaller of \
                 cs_substep_max = {} s and the tires' stability limit; limit {MAX_SUBSTEPS_PER_STEP}); \
                 take shorter communication steps",
                self.cs_substep_max
            )));
        }
        let next = nigel_vehicle::integrate(&self.params, &self.state, &self.inputs, step, substep);
        if let Some(i) = next.iter().position(|x| !x.is_finite()) {
            return Err(format!("state {} became {} (step {step} s)", STATE_NAMES[i], next[i]).into());
        }
        self.state = next;
        self.changed();
        Ok(())
    }

    /// The inputs and states; in Initialization Mode also the states' start values (the
    /// states are their start values there), not the parameters.
    fn provides_derivative_with_respect_to(known: PlantVar, initialization: bool) -> bool {
        match known {
            PlantVar::Input(_) | PlantVar::State(_) => true,
            // in Initialization Mode the knowns with initial="exact": the start values and the
            // parameters (dual numbers through the right-hand side: the states are their start
            // values, which no parameter changes)
            PlantVar::StateStart(_) | PlantVar::Param(_) => initialization,
            _ => false,
        }
    }

    fn directional_derivative(
        &mut self,
        unknowns: &[PlantVar],
        knowns: &[PlantVar],
        dv_known: &[f64],
        out: &mut [f64],
    ) -> ModelResult {
        let mut s: State<Dual> = self.state.map(Dual::constant);
        let u = &self.inputs;
        let mut ud = Inputs {
            delta: u.delta.map(Dual::constant),
            tau: u.tau.map(Dual::constant),
            mu: u.mu.map(Dual::constant),
            wind_head: Dual::constant(u.wind_head),
            wind_side: Dual::constant(u.wind_side),
            wind_x: Dual::constant(u.wind_x),
            wind_y: Dual::constant(u.wind_y),
        };
        // the parameters as dual numbers only when one is a known (else as constants, the
        // cheaper evaluation of the Jacobians an ME importer asks for at every step)
        let mut pd =
            knowns.iter().any(|k| matches!(k, PlantVar::Param(_))).then(|| ParamScalars::<Dual>::of(&self.params));
        for (&k, &dv) in knowns.iter().zip(dv_known) {
            match (k, pd.as_mut()) {
                // in Initialization Mode a state is its start value
                (PlantVar::State(i) | PlantVar::StateStart(i), _) => s[i].d += dv,
                (PlantVar::Input(i), _) => input_slot(&mut ud, i).d += dv,
                // cs_substep_max changes no value, only the Co-Simulation step's sub-steps
                (PlantVar::Param(Param::CsSubstepMax), _) => {}
                (PlantVar::Param(p), Some(pd)) => {
                    param_scalar_slot(pd, p).ok_or("a parameter of the right-hand side expected")?.d += dv
                }
                _ => return Err("a known the layer let through is not a state, an input or a parameter".into()),
            }
        }
        let e = match &pd {
            Some(pd) => evaluate(pd, &s, &ud),
            None => evaluate(&self.params, &s, &ud),
        };
        for (o, &unknown) in out.iter_mut().zip(unknowns) {
            *o = match unknown {
                PlantVar::Derivative(i) => e.derivatives[i].d,
                PlantVar::Output(w) => output_of(&e, w).d,
                PlantVar::State(i) => s[i].d,
                _ => return Err("an unknown the layer let through is not a derivative, output or state".into()),
            };
        }
        Ok(())
    }
}

#[cfg(feature = "fmi-export")]
fmi_export::export_fmi!(Plant);

#[cfg(test)]
mod tests {
    use super::*;
    use fmi_export::BaseType;

    /// The wheel names (the suffixes of every per-wheel variable) are the vehicle model's
    /// wheel order: `mu_rl` is the friction the physics applies to wheel 2.
    #[test]
    fn per_wheel_variables_follow_the_vehicle_wheel_order() {
        let d = Plant::declaration();
        let named = |name: &str| d.spec.variables.iter().find(|v| v.name == name).unwrap_or_else(|| panic!("{name}"));
        for (i, w) in ["fl", "fr", "rl", "rr"].iter().enumerate() {
            let families: [(&str, PlantVar); 7] = [
                ("delta", PlantVar::Input(Input::Steer(i))),
                ("tau", PlantVar::Input(Input::Torque(i))),
                ("mu", PlantVar::Input(Input::Friction(i))),
                ("slip_angle", PlantVar::Output(Output::SlipAngle(i))),
                ("force_lat", PlantVar::Output(Output::ForceLat(i))),
                ("force_drive", PlantVar::Output(Output::ForceDrive(i))),
                ("delta_applied", PlantVar::Output(Output::SteerApplied(i))),
            ];
            for (stem, binding) in families {
                let v = named(&format!("{stem}_{w}"));
                assert_eq!(v.binding, binding, "{}", v.name);
                assert_eq!(d.row(BaseType::Real, v.value_reference).map(|row| d.variable(row).name), Some(v.name));
            }
            // the servo state of wheel i is named after the same wheel
            assert_eq!(named(&format!("servo_angle_{w}")).binding, PlantVar::State(idx::SERVO + i));
        }
    }

    /// Every declared parameter range lies inside what the vehicle model accepts: each
    /// bound, with the other parameters at their defaults and every feature switched on,
    /// passes `VehicleParams::validate` (so the setters need no check of their own).
    #[test]
    fn declared_parameter_ranges_lie_inside_the_vehicle_checks() {
        let d = Plant::declaration();
        let mut checked = 0;
        for v in &d.spec.variables {
            let PlantVar::Param(p) = v.binding else { continue };
            let Some(defaults) = param_slot(&mut VehicleParams::table2(), p).map(|x| *x) else { continue };
            assert_eq!((v.min, v.max), (Some(parameter_range(p).0), Some(parameter_range(p).1)), "{}", v.name);
            for bound in [v.min.unwrap(), v.max.unwrap(), defaults] {
                let mut params = VehicleParams::table2();
                *param_slot(&mut params, p).unwrap() = bound;
                assert_eq!(validate_all(&params), Ok(()), "{} = {bound}", v.name);
                checked += 1;
            }
        }
        assert_eq!(checked, 3 * 17);
    }

    /// The value references the layer assigned, pinned: a change shows in review.
    #[test]
    fn value_references_are_the_pinned_ones() {
        let pinned = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("value_references.txt");
        Plant::declaration().check_pinned_value_references(&pinned).unwrap_or_else(|e| panic!("{e}"));
    }
}
