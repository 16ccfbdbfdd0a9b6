//! The exchange of clocked variables (FMI 3.0: a variable whose `clocks` attribute names
//! clocks may be read and set only while one of them is active, in Event Mode between
//! `fmi3SetClock` and `fmi3UpdateDiscreteStates`, or in the event in which an output clock
//! ticked). The instance keeps, for each clocked variable, the value it holds between its
//! clocks' ticks (the start value before the first, or what Initialization Mode read):
//! gets of a clocked variable outside an activation return it, sets of a clocked input are
//! queued and applied at the next activation of one of its clocks. In Initialization Mode
//! every access goes to the FMU (the spec allows it), a read kept as the held value.

use std::collections::HashMap;

use crate::fmi3::Access;
// looked up on every get and set of a running instance: a fast hash of the value reference
use model_description::fmi3;
use rustc_hash::FxHashMap;

/// One clocked variable: its whole-variable access (element 0), its clocks, whether the
/// master sets it (an input) or reads it.
#[derive(Clone, Debug)]
pub(crate) struct Clocked {
    pub(crate) access: Access,
    clocks: Vec<u32>,
    input: bool,
}

/// The clocked variables of one instance and their held and queued values, by the FMU's
/// value reference (all elements of an array).
#[derive(Default)]
pub(crate) struct ClockedExchange {
    variables: FxHashMap<u32, Clocked>,
    held: FxHashMap<u32, Vec<f64>>,
    queued: FxHashMap<u32, Vec<f64>>,
    /// The last [`ReadPlan`] (the same clocks tick again and again).
    last_plan: Option<ReadPlan>,
}

/// The reads of the clocked variables of some clocks when their event settles: the
/// Float64 scalars in one call, the others one call each.
#[derive(Clone, Debug, Default)]
pub(crate) struct ReadPlan {
    /// The clocks it is for.
    clocks: Vec<u32>,
    /// The Float64 scalars' value references, and a buffer for their values.
    pub(crate) scalars: Vec<u32>,
    pub(crate) values: Vec<f64>,
    /// The other clocked variables the master reads.
    pub(crate) others: Vec<Access>,
}

impl ClockedExchange {
    /// The clocked numeric variables of `md` (Strings and Binaries are not exchanged as
    /// numbers), their held values the start values; `special` gives the element count of
    /// arrays (the view's accesses).
    pub(crate) fn new(md: &fmi3::ModelDescription, special: &HashMap<u32, Access>) -> ClockedExchange {
        use fmi3::ValueType as T;
        let counts: HashMap<u32, usize> = special.values().map(|a| (a.vr, a.count)).collect();
        let mut exchange = ClockedExchange::default();
        for v in md.model_variables.iter().filter(|v| !v.clocks.is_empty()) {
            if matches!(v.value_type, T::String | T::Binary | T::Clock) {
                continue;
            }
            let count = counts.get(&v.value_reference).copied().unwrap_or(1);
            let access = Access { vr: v.value_reference, value_type: v.value_type, element: 0, count };
            let input = v.causality == fmi3::Causality::Input;
            exchange.variables.insert(v.value_reference, Clocked { access, clocks: v.clocks.clone(), input });
            if let Some(start) = start_values(v.start.as_ref(), count) {
                exchange.held.insert(v.value_reference, start);
            }
        }
        exchange
    }

    /// Whether the FMU has no clocked variable (every access goes to it).
    #[inline]
    pub(crate) fn is_empty(&self) -> bool {
        self.variables.is_empty()
    }

    /// The FMU variable and element of the view's `vr` (`special` its access when it is no
    /// plain scalar) when that variable is clocked.
    pub(crate) fn clocked(&self, vr: u32, special: Option<Access>) -> Option<(u32, usize)> {
        let (fmu_vr, element) = special.map_or((vr, 0), |a| (a.vr, a.element));
        self.variables.contains_key(&fmu_vr).then_some((fmu_vr, element))
    }

    /// Whether the clocked variable `fmu_vr` is an input.
    pub(crate) fn is_input(&self, fmu_vr: u32) -> bool {
        self.variables.get(&fmu_vr).is_some_and(|c| c.input)
    }

    /// Whether one of the clocks of the clocked variable `fmu_vr` is among `active` (the
    /// input clocks set in the open event): it is read and set through the FMU.
    #[inline]
    pub(crate) fn is_active(&self, fmu_vr: u32, active: &[u32]) -> bool {
        !active.is_empty() && self.variables.get(&fmu_vr).is_some_and(|c| c.clocks.iter().any(|k| active.contains(k)))
    }

    /// The value held for element `element` of `fmu_vr`.
    pub(crate) fn held(&self, fmu_vr: u32, element: usize) -> Option<f64> {
        self.held.get(&fmu_vr).and_then(|v| v.get(element)).copied()
    }

    /// Holds `value` for element `element` of `fmu_vr` (the other elements as held, NaN
    /// when none was).
    pub(crate) fn hold_element(&mut self, fmu_vr: u32, element: usize, value: f64) {
        let count = self.variables.get(&fmu_vr).map_or(1, |c| c.access.count);
        let held = self.held.entry(fmu_vr).or_insert_with(|| vec![f64::NAN; count]);
        if let Some(x) = held.get_mut(element) {
            *x = value;
        }
    }

    /// Holds all values of `fmu_vr`.
    pub(crate) fn hold(&mut self, fmu_vr: u32, values: Vec<f64>) {
        self.held.insert(fmu_vr, values);
    }

    /// Queues `value` for element `element` of the clocked input `fmu_vr`, applied at the
    /// next activation of one of its clocks (the other elements as queued or held).
    pub(crate) fn queue(&mut self, fmu_vr: u32, element: usize, value: f64) {
        let count = self.variables.get(&fmu_vr).map_or(1, |c| c.access.count);
        let held = self.held.get(&fmu_vr).cloned();
        let queued = self.queued.entry(fmu_vr).or_insert_with(|| held.unwrap_or_else(|| vec![f64::NAN; count]));
        if let Some(x) = queued.get_mut(element) {
            *x = value;
        }
    }

    /// The queued sets of the inputs of the clocks `active`, taken (each access with all
    /// its values).
    pub(crate) fn take_queued(&mut self, active: &[u32]) -> Vec<(Access, Vec<f64>)> {
        if self.queued.is_empty() {
            return Vec::new();
        }
        let due: Vec<Access> = self.of_clocks(active, true);
        due.into_iter().filter_map(|a| self.queued.remove(&a.vr).map(|values| (a, values))).collect()
    }

    /// The reads of the clocked variables the master reads (outputs and every other
    /// non-input) of the clocks `active`, taken (give it back with [`ClockedExchange::put_plan`]).
    pub(crate) fn take_plan(&mut self, active: &[u32]) -> ReadPlan {
        if let Some(plan) = self.last_plan.take() {
            if plan.clocks == active {
                return plan;
            }
        }
        let (scalars, others): (Vec<Access>, Vec<Access>) = self
            .of_clocks(active, false)
            .into_iter()
            .partition(|a| a.count == 1 && a.value_type == fmi3::ValueType::Float64);
        let scalars: Vec<u32> = scalars.iter().map(|a| a.vr).collect();
        ReadPlan { clocks: active.to_vec(), values: vec![0.0; scalars.len()], scalars, others }
    }

    /// The plan back, for the next event of the same clocks.
    pub(crate) fn put_plan(&mut self, plan: ReadPlan) {
        self.last_plan = Some(plan);
    }

    /// The clocked variables the master reads that hold no value (no start value, not read
    /// in Initialization Mode).
    pub(crate) fn unheld(&self) -> Vec<Access> {
        let mut out: Vec<Access> = self
            .variables
            .values()
            .filter(|c| !c.input && !self.held.contains_key(&c.access.vr))
            .map(|c| c.access)
            .collect();
        out.sort_by_key(|a| a.vr);
        out
    }

    fn of_clocks(&self, active: &[u32], inputs: bool) -> Vec<Access> {
        let mut out: Vec<Access> = self
            .variables
            .values()
            .filter(|c| c.input == inputs && c.clocks.iter().any(|k| active.contains(k)))
            .map(|c| c.access)
            .collect();
        // a fixed order of calls (the map's is not)
        out.sort_by_key(|a| a.vr);
        out
    }

    /// A new run: the held values the start values again, nothing queued.
    pub(crate) fn forget_run(&mut self, md: &fmi3::ModelDescription) {
        self.queued.clear();
        self.held.clear();
        for v in md.model_variables.iter() {
            if let Some(c) = self.variables.get(&v.value_reference) {
                if let Some(start) = start_values(v.start.as_ref(), c.access.count) {
                    self.held.insert(v.value_reference, start);
                }
            }
        }
    }
}

/// A variable's `count` start values as numbers (one start value spread over an array).
fn start_values(start: Option<&fmi3::Values>, count: usize) -> Option<Vec<f64>> {
    use fmi3::Values;
    let values: Vec<f64> = match start? {
        Values::Float(v) => v.clone(),
        Values::Int(v) => v.iter().map(|x| *x as f64).collect(),
        Values::Boolean(v) => v.iter().map(|x| *x as i32 as f64).collect(),
        _ => return None,
    };
    match values.len() {
        1 => Some(vec![values[0]; count]),
        n if n == count => Some(values),
        _ => None,
    }
}

/// A value type of the view's getters and setters, held as f64 (an Int32 and a Boolean
/// exactly).
pub(crate) trait HeldNumber: Copy {
    fn from_held(x: f64) -> Self;
    fn to_held(self) -> f64;
}

impl HeldNumber for f64 {
    fn from_held(x: f64) -> f64 {
        x
    }
    fn to_held(self) -> f64 {
        self
    }
}

impl HeldNumber for i32 {
    fn from_held(x: f64) -> i32 {
        x as i32
    }
    fn to_held(self) -> f64 {
        self as f64
    }
}
