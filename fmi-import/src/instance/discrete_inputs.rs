//! The discrete inputs of a Model Exchange instance in Continuous-Time Mode. The standard
//! lets only continuous inputs change there (FMI 2.0 section 3.2.3: `fmi2SetReal` of
//! continuous inputs only; FMI 3.0 section 3.2.1: continuous `Float32`/`Float64` inputs
//! only); every other input changes in Event Mode or Initialization Mode. A set of a
//! discrete input in Continuous-Time Mode is therefore not passed on: a value the FMU
//! already holds is dropped, a new one waits ([`DiscreteInputs::defer`]) until the importer
//! brings the instance into Event Mode and applies it there
//! ([`super::Instance::apply_pending_inputs`]). Whether the instance is in Continuous-Time
//! Mode is its state machine's ([`super::InstanceState::ContinuousTime`]), told with each set.

use std::collections::{HashMap, HashSet};

use model_description::{Causality, ModelDescription, Variability};

/// Which setter a value came through (FMI 2.0 value references are per type).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Kind {
    Real,
    Integer,
    Boolean,
    String,
    Exact,
}

/// A value as the FMU was given it (a Real by its bits: a NaN equals itself).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Held {
    Real(u64),
    Integer(i32),
    Boolean(bool),
    String(String),
    Exact(i128),
}

/// The discrete inputs of one Model Exchange instance: what the FMU holds, what waits.
#[derive(Debug)]
pub(crate) struct DiscreteInputs {
    /// The value references of the continuous Real inputs (set in any mode).
    continuous: HashSet<u32>,
    /// The value last given to the FMU of every other variable set so far.
    given: HashMap<(Kind, u32), Held>,
    /// The sets waiting for Event Mode, in the order made, one per variable (the last).
    pub(crate) pending: Vec<(Kind, u32, Held)>,
}

impl DiscreteInputs {
    /// For an instance of `interface` with description `md`: Model Exchange with a
    /// discrete input only (in Co-Simulation every input may change between steps; the
    /// importer sets nothing but inputs after initialization).
    pub(crate) fn new(md: &ModelDescription, interface: crate::fmu::Interface) -> Option<Box<DiscreteInputs>> {
        if interface != crate::fmu::Interface::ModelExchange {
            return None;
        }
        let continuous = md
            .model_variables
            .iter()
            .filter(|v| v.causality == Causality::Input && v.is_real() && v.variability == Variability::Continuous)
            .map(|v| v.value_reference)
            .collect::<HashSet<u32>>();
        let inputs = md.model_variables.iter().filter(|v| v.causality == Causality::Input).count();
        if inputs == continuous.len() {
            return None;
        }
        Some(Box::new(DiscreteInputs { continuous, given: HashMap::new(), pending: Vec::new() }))
    }

    /// Whether a set of `vr` through `kind` waits (or is dropped) instead of reaching the
    /// FMU now: in Continuous-Time Mode (`continuous_time`), anything but a continuous Real
    /// input. A value that reaches the FMU is noted as what it holds.
    pub(crate) fn defer(&mut self, continuous_time: bool, kind: Kind, vr: u32, value: Held) -> bool {
        if kind == Kind::Real && self.continuous.contains(&vr) {
            return false;
        }
        if !continuous_time {
            self.given.insert((kind, vr), value);
            return false;
        }
        self.pending.retain(|(k, v, _)| (*k, *v) != (kind, vr));
        if self.given.get(&(kind, vr)) != Some(&value) {
            self.pending.push((kind, vr, value));
        }
        true
    }

    /// The FMU's values are no longer known (an FMU state was set): every later set of a
    /// discrete input in Continuous-Time Mode waits for Event Mode.
    pub(crate) fn forget_given(&mut self) {
        self.given.clear();
    }

    /// Whether any of `vrs` (set through `kind`) would wait in Continuous-Time Mode
    /// (`continuous_time`): the batch must be split.
    pub(crate) fn any_deferred(&self, continuous_time: bool, kind: Kind, vrs: &[u32]) -> bool {
        continuous_time && (kind != Kind::Real || vrs.iter().any(|vr| !self.continuous.contains(vr)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inputs() -> DiscreteInputs {
        DiscreteInputs { continuous: [1].into_iter().collect(), given: HashMap::new(), pending: Vec::new() }
    }

    /// Out of Continuous-Time Mode everything passes (and is noted); in it a continuous
    /// Real input passes, a discrete value the FMU holds is dropped, a new one waits (the
    /// last of several), and a return to the held value cancels the wait.
    #[test]
    fn discrete_sets_wait_in_continuous_time_mode_unless_the_fmu_holds_the_value() {
        let mut d = inputs();
        assert!(!d.defer(false, Kind::Integer, 7, Held::Integer(3)));
        assert!(!d.defer(true, Kind::Real, 1, Held::Real(2.0f64.to_bits())));
        assert!(d.defer(true, Kind::Integer, 7, Held::Integer(3)));
        assert!(d.pending.is_empty());
        assert!(d.defer(true, Kind::Integer, 7, Held::Integer(4)));
        assert!(d.defer(true, Kind::Integer, 7, Held::Integer(5)));
        assert_eq!(d.pending, vec![(Kind::Integer, 7, Held::Integer(5))]);
        assert!(d.defer(true, Kind::Integer, 7, Held::Integer(3)));
        assert!(d.pending.is_empty());
        // the same value reference of another type is another variable (FMI 2.0)
        assert!(d.defer(true, Kind::Boolean, 7, Held::Boolean(true)));
        assert!(d.defer(true, Kind::Real, 2, Held::Real(0.5f64.to_bits())));
        assert_eq!(d.pending.len(), 2);
        assert!(d.any_deferred(true, Kind::Real, &[1, 2]) && !d.any_deferred(true, Kind::Real, &[1]));
    }
}
