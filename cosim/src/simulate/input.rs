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
use crate::simulate::observer::Profiler;
use crate::system::{BaseType, System, VariableRef};
use model_description::{Causality, Variability};
use std::path::Path;

/// An input table: times ascending (equal neighbours allowed, a jump), one column of
/// values per named variable.
#[derive(Clone, Debug, PartialEq)]
pub struct InputTable {
    /// Variable names, as `--set` names them (`instance.variable`, or the bare name for a
    /// one-instance system).
    pub names: Vec<String>,
    /// The times, s.
    pub time: Vec<f64>,
    /// `columns[j][k]`: variable `j` at `time[k]`.
    pub columns: Vec<Vec<f64>>,
    /// `integers[j]`: column `j` as written, when every value of it is an integer (read
    /// from a file), so that a 64-bit integer input gets the value itself, not the nearest
    /// f64; `None` for the others.
    pub integers: Vec<Option<Vec<i128>>>,
}

impl InputTable {
    /// A table from its parts, checked: times finite and not decreasing, every column as
    /// long as the time column, values finite.
    pub fn new(names: Vec<String>, time: Vec<f64>, columns: Vec<Vec<f64>>) -> Result<InputTable> {
        let bad = |m: String| Error::Experiment(format!("input: {m}"));
        if time.is_empty() {
            return Err(bad("the table has no rows".into()));
        }
        if names.len() != columns.len() {
            return Err(bad(format!("{} names for {} columns", names.len(), columns.len())));
        }
        if let Some(t) = time.iter().find(|t| !t.is_finite()) {
            return Err(bad(format!("time {t} is not finite")));
        }
        if let Some(k) = time.windows(2).position(|w| w[1] < w[0]) {
            return Err(bad(format!("time goes back from {} to {} s at row {}", time[k], time[k + 1], k + 2)));
        }
        for (name, c) in names.iter().zip(&columns) {
            if c.len() != time.len() {
                return Err(bad(format!("column {name:?} has {} values for {} times", c.len(), time.len())));
            }
            if let Some(k) = c.iter().position(|v| !v.is_finite()) {
                return Err(bad(format!("{name} = {} at t = {} s is not finite", c[k], time[k])));
            }
        }
        let integers = vec![None; columns.len()];
        Ok(InputTable { names, time, columns, integers })
    }

    /// Reads a CSV file in fmpy's format: a header of names (quoted or not, the first
    /// being the time column), then rows of numbers separated by commas.
    pub fn read_csv(path: &Path) -> Result<InputTable> {
        let text = crate::unpack::read_text_file(path, "the input file", 1 << 30)?;
        let bad = |line: usize, m: String| Error::Experiment(format!("{}:{line}: {m}", path.display()));
        let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines.next().ok_or_else(|| bad(1, "empty file, expected a header of names".into()))?;
        let cells = |l: &str| -> Vec<String> {
            l.split(',').map(|c| c.trim().trim_matches('"').replace("\"\"", "\"")).collect()
        };
        let names = cells(header);
        if names.len() < 2 {
            return Err(bad(1, "expected a time column and at least one input column".into()));
        }
        let mut time = Vec::new();
        let mut columns = vec![Vec::new(); names.len() - 1];
        let mut integers: Vec<Option<Vec<i128>>> = vec![Some(Vec::new()); names.len() - 1];
        for (k, line) in lines {
            let row = cells(line);
            if row.len() != names.len() {
                return Err(bad(k + 1, format!("{} values, the header has {} names", row.len(), names.len())));
            }
            let num = |j: usize| {
                row[j]
                    .parse::<f64>()
                    .map_err(|_| bad(k + 1, format!("{:?} (column {:?}) is not a number", row[j], names[j])))
            };
            time.push(num(0)?);
            for (j, c) in columns.iter_mut().enumerate() {
                c.push(num(j + 1)?);
                if let Some(ints) = &mut integers[j] {
                    match row[j + 1].parse::<i128>() {
                        Ok(i) => ints.push(i),
                        Err(_) => integers[j] = None,
                    }
                }
            }
        }
        let mut table = InputTable::new(names[1..].to_vec(), time, columns)?;
        table.integers = integers;
        Ok(table)
    }

    /// The index `i0` of the first time at or after `t` (numpy's `searchsorted`, left).
    fn search(&self, t: f64) -> usize {
        self.time.partition_point(|x| *x < t)
    }

    /// The row whose values a discrete column holds at `t` (fmpy's `Input.interpolate`).
    fn discrete_row(&self, t: f64, after_event: bool) -> usize {
        let (time, n) = (&self.time, self.time.len());
        let i0 = self.search(t);
        if n < 2 || i0 == 0 {
            return 0;
        }
        if i0 == n {
            return n - 1;
        }
        let mut i = i0 - 1;
        if after_event {
            while i + 1 < n && (time[i + 1] < t || isclose(t, time[i + 1])) {
                i += 1;
            }
        }
        i
    }

    /// Column `j` at `t` as written, if it is a discrete column of integers.
    fn integer(&self, j: usize, t: f64, after_event: bool) -> Option<i128> {
        let ints = self.integers.get(j)?.as_ref()?;
        ints.get(self.discrete_row(t, after_event)).copied()
    }

    /// The value of column `j` at `t`, as fmpy's `Input.interpolate` computes it.
    pub fn value(&self, j: usize, t: f64, discrete: bool, after_event: bool) -> f64 {
        let (time, v) = (&self.time, &self.columns[j]);
        let n = time.len();
        if n < 2 {
            return v[0];
        }
        let i0 = self.search(t);
        if i0 == 0 {
            return v[0];
        }
        if i0 == n {
            return v[n - 1];
        }
        if discrete {
            return v[self.discrete_row(t, after_event)];
        }
        let mut i0 = i0;
        if isclose(t, time[i0]) && i0 < n - 1 && isclose(time[i0], time[i0 + 1]) {
            if after_event {
                while i0 < n - 1 && isclose(time[i0], time[i0 + 1]) {
                    i0 += 1;
                }
            }
            return v[i0];
        }
        let (t0, t1) = (time[i0 - 1], time[i0]);
        let w0 = (t1 - t) / (t1 - t0);
        let w1 = 1.0 - w0;
        w0 * v[i0 - 1] + w1 * v[i0]
    }
}

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

/// Python's `math.isclose` with its defaults (relative tolerance 1e-9, no absolute one),
/// which fmpy uses to compare times.
fn isclose(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
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
