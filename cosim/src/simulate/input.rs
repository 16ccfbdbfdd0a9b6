//! Input signals over time, as fmpy's `simulate_fmu(input=...)` takes them: a table with
//! a time column and one column per input variable. Applied by the master before each
//! communication step at the step's start time: Real variables that are not discrete
//! interpolated linearly between rows, the others (discrete Reals, Integers, Booleans)
//! held from the last row at or before the time; before the first row the first values,
//! after the last row the last values. Two rows at the same time are a jump: at that time
//! the later row holds (fmpy's `after_event`), in initialization the earlier one.
//! Model Exchange instances get the value at the start of each communication step, held
//! over it (as the master holds connections); a discrete input of theirs only when it
//! changes, in an event of its own (Event Mode, the value set, the event iteration, as
//! fmpy does): the standard allows no discrete input to change in Continuous-Time Mode.
//!
//! A jump (two rows at one time) and a change of a discrete column are input events.
//! fmpy's `simulate_fmu` makes one a communication point of its own in Co-Simulation
//! (when the FMU can vary its step) and a time event in Model Exchange. Here an event on a
//! communication point applies the later row from that point on, as there; an event
//! between two points splits the communication step there (the instances step to the
//! event, the inputs take their values after it, the step goes on to the next point),
//! which is fmpy's extra communication point, and for a Model Exchange FMU without
//! discrete states its time event; no row is recorded at the event (fmpy records one
//! there in Co-Simulation). Splitting needs every Co-Simulation instance to vary its
//! step (`canHandleVariableCommunicationStepSize`); otherwise an event between points
//! takes effect at the next communication point, as fmpy applies it there (the value at
//! the step's start time), and the run's summary says so in a note naming the event, the
//! point and the FMU.

use crate::error::{Error, Result};
use crate::simulate::algorithm::{Communication, Core};
use crate::simulate::clock::{Clock, Point};
use crate::simulate::input_table::{isclose, InputTable};
use crate::simulate::profiler::Profiler;
use crate::system::{BaseType, System, VariableRef};
use model_description::{Causality, Variability};

/// The input events of a table, as fmpy's `Input.findEvents` finds them: the time of two
/// rows at one time, and of each row where a discrete column changes; with what it is.
fn input_events(table: &InputTable, columns: &[Column]) -> Vec<(String, f64)> {
    let t = &table.time;
    let mut out = Vec::new();
    for k in 1..t.len() {
        if t[k] == t[k - 1] {
            out.push((format!("the jump (rows {} and {} both at t = {} s)", k + 1, k + 2, t[k]), t[k]));
        }
        for (j, c) in columns.iter().enumerate() {
            if c.discrete && table.columns[j][k] != table.columns[j][k - 1] {
                out.push((
                    format!("the change of the discrete input {} at t = {} s (row {})", table.names[j], t[k], k + 2),
                    t[k],
                ));
            }
        }
    }
    out
}

/// Whether an input event at `t` needs no split: outside the run, or on a communication
/// point (to fmpy's `isclose`).
fn on_grid(t: f64, clock: &Clock) -> bool {
    let end = clock.t0 + clock.steps as f64 * clock.h;
    if !(t > clock.t0 && t < end) || isclose(t, clock.t0) || isclose(t, end) {
        return true;
    }
    let n = ((t - clock.t0) / clock.h).floor();
    isclose(t, clock.t0 + n * clock.h) || isclose(t, clock.t0 + (n + 1.0) * clock.h)
}

/// The note for an input event between communication points that cannot split a step
/// (instance `fixed` cannot vary its step): it takes effect at the next point.
fn off_grid(what: &str, t: f64, clock: &Clock, fixed: &str) -> String {
    let n = ((t - clock.t0) / clock.h).floor();
    let (before, after) = (clock.t0 + n * clock.h, clock.t0 + (n + 1.0) * clock.h);
    format!(
        "input: {what} falls between the communication points {before} and {after} s (step {} s), and \
         {fixed} cannot vary its communication step (canHandleVariableCommunicationStepSize) to stop \
         there: it takes effect at {after} s, as fmpy applies it (move the event onto a communication \
         point, or choose a step that has it, to apply it at its time)",
        clock.h
    )
}

/// One column resolved to a variable.
struct Column {
    variable: VariableRef,
    discrete: bool,
}

/// The inputs of a run, resolved, wrapped around the algorithm.
pub(crate) struct WithInput<'s> {
    pub(crate) inner: Box<dyn Communication + Send + 's>,
    table: InputTable,
    columns: Vec<Column>,
    /// The input events between communication points, ascending: a step is split at each.
    splits: Vec<f64>,
    /// The first of `splits` not yet passed.
    next_split: usize,
    /// What the run does with the table that a reader of it may not expect (an event
    /// between points that takes effect at the next point), for [`crate::Summary::notes`].
    pub(crate) notes: Vec<String>,
    /// The value each column last set ([`Cell::key`]; `None`: not yet set).
    held: Vec<Option<i128>>,
}

impl<'s> WithInput<'s> {
    /// Resolves the table's names in `system` (a bare name in a one-instance system is
    /// that instance's variable); refuses names that are not inputs (or tunable
    /// parameters) and inputs a connection already feeds.
    pub(crate) fn new(
        inner: Box<dyn Communication + Send + 's>,
        system: &System,
        table: &InputTable,
        clock: &Clock,
    ) -> Result<WithInput<'s>> {
        let mut columns = Vec::new();
        for name in &table.names {
            let r = match system.resolve(name) {
                Ok(r) => r,
                Err(_) if system.instances.len() == 1 => {
                    system.resolve(&format!("{}.{name}", system.instances[0].name))?
                }
                Err(e) => return Err(e),
            };
            let v = system.variable(&r);
            let bad = |reason: String| {
                Error::Import(crate::ImportError::InvalidValue {
                    variable: name.clone(),
                    value: "(input column)".into(),
                    reason,
                })
            };
            if !(v.causality == Causality::Input || v.variability == Variability::Tunable) {
                return Err(bad(format!(
                    "a {} variable cannot be driven over time (only inputs and tunable parameters)",
                    v.causality.as_str()
                )));
            }
            if system.connections.iter().any(|c| c.to == r) {
                return Err(bad("the input is fed by a connection".into()));
            }
            if r.base_type == BaseType::String {
                return Err(bad("String inputs cannot be read from a table".into()));
            }
            let discrete = r.base_type != BaseType::Real
                || v.variability == Variability::Discrete
                || v.variability == Variability::Tunable;
            columns.push(Column { variable: r, discrete });
        }
        let fixed_step = system
            .instances
            .iter()
            .find(|i| i.fmu.interface() == crate::fmu::Interface::CoSimulation && !i.fmu.can_handle_variable_step());
        let mut splits = Vec::new();
        let mut notes = Vec::new();
        for (what, t) in input_events(table, &columns) {
            if !on_grid(t, clock) {
                match fixed_step {
                    Some(i) => notes.push(off_grid(&what, t, clock, &i.name)),
                    None => splits.push(t),
                }
            }
        }
        splits.sort_by(f64::total_cmp);
        splits.dedup();
        let held = vec![None; columns.len()];
        Ok(WithInput { inner, table: table.clone(), columns, splits, next_split: 0, notes, held })
    }

    /// The table's values at `t` set: continuous inputs at every call; a discrete one when
    /// its value changes, and in a Model Exchange instance out of Initialization Mode
    /// through an event (Event Mode, the new values, the event iteration, back to
    /// Continuous-Time Mode), as the standard allows discrete inputs to change only there
    /// (FMI 2.0 section 3.2.3, FMI 3.0 section 3.2.1) and as fmpy applies them.
    fn apply(&mut self, core: &mut Core, t: f64, after_event: bool) -> Result<()> {
        // (column, value) of the changed discrete inputs of Model Exchange instances
        let mut events: Vec<(usize, Cell)> = Vec::new();
        for (j, c) in self.columns.iter().enumerate() {
            let v = self.table.value(j, t, c.discrete, after_event);
            let exact = if c.discrete { self.table.integer(j, t, after_event) } else { None };
            let v = Cell { value: v, exact };
            let lane = &mut core.lanes[c.variable.instance];
            if c.discrete && lane.unit.is_some() {
                if self.held[j] != Some(v.key()) {
                    events.push((j, v));
                }
                continue;
            }
            set_input(&mut lane.inst, &c.variable, v)?;
            self.held[j] = Some(v.key());
        }
        if events.is_empty() {
            return Ok(());
        }
        let columns = &self.columns;
        let set = |lanes: &mut [crate::simulate::lane::Lane], of: &dyn Fn(usize) -> bool| -> Result<()> {
            for &(j, v) in events.iter().filter(|(j, _)| of(columns[*j].variable.instance)) {
                set_input(&mut lanes[columns[j].variable.instance].inst, &columns[j].variable, v)?;
            }
            Ok(())
        };
        let mut instances: Vec<usize> = events.iter().map(|(j, _)| columns[*j].variable.instance).collect();
        instances.sort_unstable();
        instances.dedup();
        // the coupled group's members together, in one event
        if let Some(group) = core.group.as_mut() {
            let who: Vec<usize> = instances.iter().copied().filter(|i| group.contains(*i)).collect();
            if !who.is_empty() {
                let members = group.members.clone();
                group.input_event(core.lanes.as_mut_slice(), t, "input", &who, |lanes| {
                    set(lanes, &|i| members.contains(&i))
                })?;
                group.ended(core.lanes.as_mut_slice(), t)?;
            }
        }
        for i in instances {
            let lanes = core.lanes.as_mut_slice();
            let lane = &mut lanes[i];
            let (Some(unit), Some(solo)) = (lane.unit.as_mut(), lane.solo.as_mut()) else { continue };
            let mut one = crate::simulate::me_group::Solo { inst: &mut lane.inst, unit };
            // a group of one: its own lane alone
            let (columns, events) = (&self.columns, &events);
            solo.input_event(&mut one, t, "input", &[i], |one| {
                for &(j, v) in events.iter().filter(|(j, _)| columns[*j].variable.instance == i) {
                    set_input(one.inst, &columns[j].variable, v)?;
                }
                Ok(())
            })?;
            solo.ended(&mut one, t)?;
        }
        for (j, v) in events {
            self.held[j] = Some(v.key());
        }
        Ok(())
    }
}

/// A value of the table at one time: as interpolated, and as written when it is an
/// integer of a discrete column.
#[derive(Clone, Copy, Debug)]
struct Cell {
    value: f64,
    exact: Option<i128>,
}

impl Cell {
    /// What tells two values of one column apart.
    fn key(self) -> i128 {
        self.exact.unwrap_or(self.value.to_bits() as i128)
    }
}

/// Sets input `variable` of `inst` to the table's value `v`: a 64-bit integer (FMI 3.0
/// Int64, UInt64) to the integer as written.
fn set_input(inst: &mut crate::fmu::Instance, variable: &VariableRef, v: Cell) -> Result<()> {
    let vr = [variable.value_reference];
    if let Some(i) = v.exact {
        if inst.fmu().exact_kind(variable.value_reference).is_some_and(|k| k != crate::fmi3::ExactKind::Binary) {
            return inst.set_exact_integer(variable.value_reference, i).map_err(Into::into);
        }
    }
    let v = v.value;
    match variable.base_type {
        BaseType::Real => inst.set_real(&vr, &[v])?,
        // as fmpy's table cast to fmi2Integer / fmi2Boolean: truncated toward zero
        BaseType::Integer => inst.set_integer(&vr, &[v as i32])?,
        BaseType::Boolean => inst.set_boolean(&vr, &[(v as i32 != 0) as i32])?,
        BaseType::String => {}
    }
    Ok(())
}

impl Communication for WithInput<'_> {
    fn propagate(&mut self, core: &mut Core) -> Result<()> {
        self.apply(core, core.clock.t0, false)?;
        self.inner.propagate(core)
    }

    fn step(&mut self, core: &mut Core, p: Point, mut calls: Option<&mut Profiler>) -> Result<()> {
        self.apply(core, p.t, true)?;
        // the input events inside the step: a stop at each, no row recorded there
        let mut t = p.t;
        while let Some(&e) = self.splits.get(self.next_split) {
            if e >= p.t_next || isclose(e, p.t_next) {
                break;
            }
            self.next_split += 1;
            if e <= t || isclose(e, t) {
                continue;
            }
            self.inner.step(core, Point { t, t_next: e, output_point: false, ..p }, calls.as_deref_mut())?;
            self.apply(core, e, true)?;
            t = e;
        }
        self.inner.step(core, Point { t, ..p }, calls)
    }

    fn finish(&mut self, core: &mut Core) -> Result<()> {
        self.inner.finish(core)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_as_fmpy_interpolates_them() {
        // a ramp, a jump at t = 1 (two rows), then constant
        let table =
            InputTable::new(vec!["u".into()], vec![0.0, 0.5, 1.0, 1.0, 2.0], vec![vec![0.0, 1.0, 1.0, 5.0, 5.0]])
                .unwrap();
        let at = |t: f64, discrete: bool, after: bool| table.value(0, t, discrete, after);
        assert_eq!(at(-1.0, false, true), 0.0); // before the first row: held
        assert_eq!(at(0.25, false, true), 0.5); // w0 = w1 = 0.5
        assert_eq!(at(0.5, false, true), 1.0);
        assert_eq!(at(1.0, false, false), 1.0); // the jump: before
        assert_eq!(at(1.0, false, true), 5.0); // and after
        assert_eq!(at(3.0, false, true), 5.0); // after the last row: held
        assert_eq!(at(0.75, true, true), 1.0); // discrete: the last row at or before
        assert_eq!(at(0.25, true, true), 0.0);
        assert_eq!(at(0.5, true, false), 0.0); // at a row, before it applies
        assert_eq!(at(0.5, true, true), 1.0);
        assert!(InputTable::new(vec!["u".into()], vec![1.0, 0.5], vec![vec![0.0, 0.0]]).is_err());
    }
}
