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
/// master sets it (an input) or reads it, the values it holds and those queued for it.
#[derive(Clone, Debug)]
pub(crate) struct Clocked {
    pub(crate) access: Access,
    clocks: Vec<u32>,
    input: bool,
    /// One of its clocks is active (set in the open event).
    active: bool,
    held: Option<Vec<f64>>,
    queued: Option<Vec<f64>>,
}

/// The clocked variables of one instance and their held and queued values. A variable is
/// found by the FMU's value reference once (its slot), then every access is by slot.
#[derive(Default)]
pub(crate) struct ClockedExchange {
    /// The slot of each clocked variable by the FMU's value reference (all elements of an
    /// array); looked up on every get and set of a running instance: a fast hash.
    slots: FxHashMap<u32, usize>,
    /// The same by index when every value reference is below [`DENSE_LIMIT`]: the slot + 1
    /// of each value reference, 0 for a variable that is not clocked (no hash at all).
    dense: Vec<u32>,
    /// By slot, in the order of the description.
    variables: Vec<Clocked>,
    /// Some value is queued.
    any_queued: bool,
    /// Some clocked variable can be set: an input or a parameter (else no set is ever queued
    /// or held, and the sets of a running instance go straight to the FMU).
    any_settable: bool,
    /// The last [`ReadPlan`] (the same clocks tick again and again).
    last_plan: Option<ReadPlan>,
}

/// Value references below this are looked up by index (64 KiB of table at most).
const DENSE_LIMIT: u32 = 1 << 14;

/// The reads of the clocked variables of some clocks when their event settles: the
/// Float64 scalars in one call, the others one call each.
#[derive(Clone, Debug, Default)]
pub(crate) struct ReadPlan {
    /// The clocks it is for.
    clocks: Vec<u32>,
    /// The Float64 scalars' value references, their slots, and a buffer for their values.
    pub(crate) scalars: Vec<u32>,
    pub(crate) scalar_slots: Vec<usize>,
    pub(crate) values: Vec<f64>,
    /// The other clocked variables the master reads, with their slots.
    pub(crate) others: Vec<(usize, Access)>,
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
            if matches!(v.value_type, T::String | T::Binary | T::Clock)
                || exchange.slots.contains_key(&v.value_reference)
            {
                continue;
            }
            let count = counts.get(&v.value_reference).copied().unwrap_or(1);
            let access = Access { vr: v.value_reference, value_type: v.value_type, element: 0, count };
            let input = v.causality == fmi3::Causality::Input;
            exchange.any_settable |=
                input || matches!(v.causality, fmi3::Causality::Parameter | fmi3::Causality::StructuralParameter);
            exchange.slots.insert(v.value_reference, exchange.variables.len());
            exchange.variables.push(Clocked {
                access,
                clocks: v.clocks.clone(),
                input,
                active: false,
                held: start_values(v.start.as_ref(), count),
                queued: None,
            });
        }
        let largest = md.model_variables.iter().map(|v| v.value_reference).max().unwrap_or(0);
        if !exchange.variables.is_empty() && largest < DENSE_LIMIT {
            exchange.dense = vec![0; largest as usize + 1];
            for (vr, slot) in exchange.slots.iter() {
                exchange.dense[*vr as usize] = *slot as u32 + 1;
            }
        }
        exchange
    }

    /// Whether the FMU has no clocked variable (every access goes to it).
    #[inline]
    pub(crate) fn is_empty(&self) -> bool {
        self.variables.is_empty()
    }

    /// The slot and element of the view's `vr` (`special` its access when it is no plain
    /// scalar) when that variable is clocked.
    #[inline]
    pub(crate) fn clocked(&self, vr: u32, special: Option<Access>) -> Option<(usize, usize)> {
        let (fmu_vr, element) = special.map_or((vr, 0), |a| (a.vr, a.element));
        if !self.dense.is_empty() {
            return match self.dense.get(fmu_vr as usize) {
                Some(&k) if k > 0 => Some((k as usize - 1, element)),
                _ => None,
            };
        }
        self.slots.get(&fmu_vr).map(|slot| (*slot, element))
    }

    /// Whether some clocked variable can be set (an input or a parameter).
    #[inline]
    pub(crate) fn has_settable(&self) -> bool {
        self.any_settable
    }

    /// Whether the clocked variable in `slot` is an input.
    #[inline]
    pub(crate) fn is_input(&self, slot: usize) -> bool {
        self.variables[slot].input
    }

    /// Whether one of the clocks of the variable in `slot` is active (set in the open
    /// event): it is read and set through the FMU.
    #[inline]
    pub(crate) fn is_active(&self, slot: usize) -> bool {
        self.variables[slot].active
    }

    /// The clocks `active` are set: their variables are active until [`ClockedExchange::deactivate`].
    pub(crate) fn activate(&mut self, active: &[u32]) {
        for c in self.variables.iter_mut() {
            c.active |= c.clocks.iter().any(|k| active.contains(k));
        }
    }

    /// The event settled: no clock is active.
    pub(crate) fn deactivate(&mut self) {
        for c in self.variables.iter_mut() {
            c.active = false;
        }
    }

    /// The value held for element `element` of the variable in `slot`.
    #[inline]
    pub(crate) fn held(&self, slot: usize, element: usize) -> Option<f64> {
        self.variables[slot].held.as_ref().and_then(|v| v.get(element)).copied()
    }

    /// Holds `value` for element `element` of the variable in `slot` (the other elements
    /// as held, NaN when none was).
    #[inline]
    pub(crate) fn hold_element(&mut self, slot: usize, element: usize, value: f64) {
        let c = &mut self.variables[slot];
        let held = c.held.get_or_insert_with(|| vec![f64::NAN; c.access.count]);
        if let Some(x) = held.get_mut(element) {
            *x = value;
        }
    }

    /// Holds all values of the variable in `slot`.
    pub(crate) fn hold(&mut self, slot: usize, values: Vec<f64>) {
        self.variables[slot].held = Some(values);
    }

    /// Queues `value` for element `element` of the clocked input in `slot`, applied at the
    /// next activation of one of its clocks (the other elements as queued or held).
    pub(crate) fn queue(&mut self, slot: usize, element: usize, value: f64) {
        let c = &mut self.variables[slot];
        let (held, count) = (&c.held, c.access.count);
        let queued = c.queued.get_or_insert_with(|| held.clone().unwrap_or_else(|| vec![f64::NAN; count]));
        if let Some(x) = queued.get_mut(element) {
            *x = value;
        }
        self.any_queued = true;
    }

    /// The queued sets of the inputs of the clocks `active`, taken (each access with its
    /// slot and all its values).
    pub(crate) fn take_queued(&mut self, active: &[u32]) -> Vec<(usize, Access, Vec<f64>)> {
        if !self.any_queued {
            return Vec::new();
        }
        let mut out = Vec::new();
        for (slot, c) in self.variables.iter_mut().enumerate() {
            if c.input && c.clocks.iter().any(|k| active.contains(k)) {
                if let Some(values) = c.queued.take() {
                    out.push((slot, c.access, values));
                }
            }
        }
        self.any_queued = self.variables.iter().any(|c| c.queued.is_some());
        // a fixed order of calls: by value reference
        out.sort_by_key(|(_, a, _)| a.vr);
        out
    }

    /// The reads of the clocked variables the master reads (outputs and every other
    /// non-input) of the clocks `active`, taken (give it back with [`ClockedExchange::put_plan`]).
    pub(crate) fn take_plan(&mut self, active: &[u32]) -> ReadPlan {
        if let Some(plan) = self.last_plan.take() {
            if plan.clocks == active {
                return plan;
            }
        }
        let mut plan = ReadPlan { clocks: active.to_vec(), ..ReadPlan::default() };
        for (slot, access) in self.of_clocks(active, false) {
            if access.count == 1 && access.value_type == fmi3::ValueType::Float64 {
                plan.scalars.push(access.vr);
                plan.scalar_slots.push(slot);
            } else {
                plan.others.push((slot, access));
            }
        }
        plan.values = vec![0.0; plan.scalars.len()];
        plan
    }

    /// The plan back, for the next event of the same clocks.
    pub(crate) fn put_plan(&mut self, plan: ReadPlan) {
        self.last_plan = Some(plan);
    }

    /// The clocked variables the master reads that hold no value (no start value, not read
    /// in Initialization Mode), with their slots.
    pub(crate) fn unheld(&self) -> Vec<(usize, Access)> {
        let mut out: Vec<(usize, Access)> = self
            .variables
            .iter()
            .enumerate()
            .filter(|(_, c)| !c.input && c.held.is_none())
            .map(|(slot, c)| (slot, c.access))
            .collect();
        out.sort_by_key(|(_, a)| a.vr);
        out
    }

    fn of_clocks(&self, active: &[u32], inputs: bool) -> Vec<(usize, Access)> {
        let mut out: Vec<(usize, Access)> = self
            .variables
            .iter()
            .enumerate()
            .filter(|(_, c)| c.input == inputs && c.clocks.iter().any(|k| active.contains(k)))
            .map(|(slot, c)| (slot, c.access))
            .collect();
        // a fixed order of calls: by value reference
        out.sort_by_key(|(_, a)| a.vr);
        out
    }

    /// A new run: the held values the start values again, nothing queued, no clock active.
    pub(crate) fn forget_run(&mut self, md: &fmi3::ModelDescription) {
        self.any_queued = false;
        for c in self.variables.iter_mut() {
            c.queued = None;
            c.held = None;
            c.active = false;
        }
        for v in md.model_variables.iter() {
            if let Some(&slot) = self.slots.get(&v.value_reference) {
                let c = &mut self.variables[slot];
                if c.held.is_none() {
                    c.held = start_values(v.start.as_ref(), c.access.count);
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
