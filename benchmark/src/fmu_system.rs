//! The benchmark's closed loop as a system of its three FMUs: the instances `plant`
//! (`nigel_plant`), `controller` (`nigel_controller`) and `maneuver` (`nigel_maneuver`,
//! the test bench), the parameters one job sets and every connection. It is data (names and
//! values), so that any co-simulation master builds its system from it: `build-fmu` writes
//! the closed-loop SSP from it through `nigel_cosim::write_ssp`, `nigel-table3` runs it.
//!
//! The switches are the FMUs' Integer parameters whose values are 1-based positions, as
//! their descriptions and documentation state: `maneuver` in [`Maneuver::ALL`], `fidelity`
//! in [`Fidelity::ALL`], `controller` in `open_loop, pole_placement, robust, custom,
//! robust_tracking` ([`CONTROLLER_SWITCH`]).

use crate::{Controller, Fidelity, Maneuver, DEFAULT_SPEED, N_SAMPLES, SAMPLE_PERIOD};
use nigel_vehicle::WHEELS;

/// The instances, `(instance name, model identifier)`, in the order a master adds them.
pub const INSTANCES: [(&str, &str); 3] =
    [("plant", "nigel_plant"), ("controller", "nigel_controller"), ("maneuver", "nigel_maneuver")];

/// The controller FMU's `controller` switch: the value of each name is its position + 1.
pub const CONTROLLER_SWITCH: [&str; 5] = ["open_loop", "pole_placement", "robust", "custom", "robust_tracking"];

/// A parameter's value, typed as the FMU declares it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StartValue {
    /// A Real.
    Real(f64),
    /// An Integer (the switches).
    Integer(i32),
    /// A Boolean.
    Boolean(bool),
}

/// One closed-loop job as FMU instances, parameters and connections.
#[derive(Clone, Debug, PartialEq)]
pub struct FmuSystem {
    /// `(instance name, model identifier)`: [`INSTANCES`].
    pub instances: Vec<(&'static str, &'static str)>,
    /// `instance.variable` and its value, set before initialization.
    pub parameters: Vec<(String, StartValue)>,
    /// `(from, to)`: an output `instance.variable` feeding an input.
    pub connections: Vec<(String, String)>,
    /// The benchmark's horizon, 30 s.
    pub stop_time: f64,
    /// The communication step, the controller's and test bench's sample period (1 ms).
    pub step: f64,
}

/// The system of one job: `fidelity` (the column), `maneuver` (the row), `controller`,
/// the noise `seed`, and `disturbed` (friction variation, wind, measurement noise as in the
/// benchmark; `false` turns all three off).
///
/// [`Controller::Custom`] runs as the controller FMU's `custom` with its gain in the
/// tunable parameters `k_beta_<wheel>`, `k_yaw_rate_<wheel>`. Fails for a seed beyond the
/// test bench's Integer range.
pub fn closed_loop(
    fidelity: Fidelity,
    maneuver: Maneuver,
    controller: Controller,
    seed: u64,
    disturbed: bool,
) -> Result<FmuSystem, String> {
    let seed = i32::try_from(seed)
        .map_err(|_| format!("seed {seed} does not fit the test bench's Integer seed (0 ..= {})", i32::MAX))?;
    let position = |names: &[&str], name: &str| names.iter().position(|n| *n == name).map_or(0, |k| k as i32 + 1);
    let maneuvers = Maneuver::ALL.map(|m| m.name());
    let fidelities = Fidelity::ALL.map(|f| f.name());
    let mut parameters = vec![
        ("maneuver.maneuver".to_string(), StartValue::Integer(position(&maneuvers, maneuver.name()))),
        ("maneuver.fidelity".to_string(), StartValue::Integer(position(&fidelities, fidelity.name()))),
        ("maneuver.seed".to_string(), StartValue::Integer(seed)),
    ];
    if !disturbed {
        for switch in ["friction_variation", "wind", "measurement_noise"] {
            parameters.push((format!("maneuver.{switch}"), StartValue::Boolean(false)));
        }
    }
    parameters
        .push(("controller.controller".into(), StartValue::Integer(position(&CONTROLLER_SWITCH, controller.name()))));
    if let Controller::Custom(k) = controller {
        for (row, w) in k.iter().zip(WHEELS) {
            parameters.push((format!("controller.k_beta_{w}"), StartValue::Real(row[0])));
            parameters.push((format!("controller.k_yaw_rate_{w}"), StartValue::Real(row[1])));
        }
    }
    let real = fidelity == Fidelity::Real;
    for switch in ["friction_circle", "steering_servo", "motor_speed_limit"] {
        parameters.push((format!("plant.{switch}"), StartValue::Boolean(real)));
    }
    // the initial speed is a parameter (the state v_x is calculated from it), so that
    // every importer applies it from an SSP's parameter bindings
    parameters.push(("plant.v_x_start".into(), StartValue::Real(DEFAULT_SPEED)));

    let mut connections = Vec::new();
    let mut connect = |from: &str, to: &str| connections.push((from.to_string(), to.to_string()));
    for w in WHEELS {
        connect(&format!("controller.delta_{w}"), &format!("plant.delta_{w}"));
        connect(&format!("controller.tau_{w}"), &format!("plant.tau_{w}"));
        connect(&format!("maneuver.mu_{w}"), &format!("plant.mu_{w}"));
        connect(&format!("maneuver.delta_ff_{w}"), &format!("controller.delta_ff_{w}"));
    }
    connect("maneuver.wind_x", "plant.wind_x");
    connect("maneuver.wind_y", "plant.wind_y");
    connect("maneuver.beta_meas", "controller.beta");
    connect("maneuver.yaw_rate_meas", "controller.yaw_rate");
    connect("plant.speed", "controller.speed");
    connect("maneuver.beta_ref", "controller.beta_ref");
    connect("maneuver.yaw_rate_ref", "controller.yaw_rate_ref");
    connect("maneuver.speed_ref", "controller.speed_ref");
    connect("plant.beta", "maneuver.beta");
    connect("plant.yaw_rate", "maneuver.yaw_rate");
    for pose in ["x", "y", "psi"] {
        connect(&format!("plant.{pose}"), &format!("controller.{pose}"));
        connect(&format!("maneuver.{pose}_ref"), &format!("controller.{pose}_ref"));
    }
    Ok(FmuSystem {
        instances: INSTANCES.to_vec(),
        parameters,
        connections,
        stop_time: N_SAMPLES as f64 * SAMPLE_PERIOD,
        step: SAMPLE_PERIOD,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The start value the system sets for the parameter `name`.
    fn parameter(s: &FmuSystem, name: &str) -> Option<StartValue> {
        s.parameters.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }

    #[test]
    fn lane_change_robust_sets_the_switch_positions_and_wires_every_input_once() {
        let s = closed_loop(Fidelity::Paper, Maneuver::LaneChange, Controller::Robust, 0, true).unwrap();
        let get = |name: &str| parameter(&s, name);
        assert_eq!(get("maneuver.maneuver"), Some(StartValue::Integer(2)));
        assert_eq!(get("maneuver.fidelity"), Some(StartValue::Integer(1)));
        assert_eq!(get("controller.controller"), Some(StartValue::Integer(3)));
        assert_eq!(get("plant.steering_servo"), Some(StartValue::Boolean(false)));
        assert_eq!(get("maneuver.wind"), None);
        assert_eq!(get("plant.v_x_start"), Some(StartValue::Real(0.35)));
        // plant: 4 x (delta, tau, mu) + wind_x, wind_y; controller: 4 delta_ff, beta,
        // yaw_rate, speed, 3 references, 6 pose; test bench: beta, yaw_rate
        assert_eq!(s.connections.len(), 14 + 16 + 2);
        let mut inputs: Vec<&String> = s.connections.iter().map(|(_, to)| to).collect();
        inputs.sort();
        inputs.dedup();
        assert_eq!(inputs.len(), s.connections.len(), "an input fed twice");
        assert_eq!((s.stop_time, s.step), (30.0, 1e-3));
    }

    #[test]
    fn tracking_real_undisturbed_and_refusals() {
        let s = closed_loop(Fidelity::Real, Maneuver::Figure8, Controller::RobustTracking, 7, false).unwrap();
        let get = |name: &str| parameter(&s, name);
        assert_eq!(get("controller.controller"), Some(StartValue::Integer(5)));
        assert_eq!(get("maneuver.maneuver"), Some(StartValue::Integer(6)));
        assert_eq!(get("maneuver.fidelity"), Some(StartValue::Integer(2)));
        assert_eq!(get("maneuver.seed"), Some(StartValue::Integer(7)));
        assert_eq!(get("maneuver.measurement_noise"), Some(StartValue::Boolean(false)));
        assert_eq!(get("plant.friction_circle"), Some(StartValue::Boolean(true)));
        let k = [[0.1, 0.2], [0.3, 0.4], [0.5, 0.6], [0.7, 0.8]];
        let c = closed_loop(Fidelity::Paper, Maneuver::Straight, Controller::Custom(k), 0, true).unwrap();
        let get = |name: &str| parameter(&c, name);
        assert_eq!(get("controller.controller"), Some(StartValue::Integer(4)));
        assert_eq!(get("controller.k_beta_rl"), Some(StartValue::Real(0.5)));
        assert_eq!(get("controller.k_yaw_rate_rr"), Some(StartValue::Real(0.8)));
        let e = closed_loop(Fidelity::Paper, Maneuver::Straight, Controller::Robust, 1 << 31, true).unwrap_err();
        assert!(e.contains("2147483648"), "{e}");
    }
}
