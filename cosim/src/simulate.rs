//! Fixed-step Co-Simulation of a [`System`]: initialization per the standard, `jacobi`
//! and `ordered` communication, results at output points. Time is `t0 + n h`.
//!
//! Before the loop everything is resolved to value references and buffer slots: the
//! loop does not allocate and looks nothing up by name.

use crate::error::{Error, Result};
use crate::fmu::{Instance, Interface};
use crate::me::MeUnit;
use crate::system::{is_cs, BaseType, System, Value, VariableRef};
use model_description::Causality;
use std::time::{Duration, Instant};

/// How connections are updated at communication points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Algorithm {
    /// Every connection delayed by one step (all outputs read, then all inputs set), as
    /// fmpy `simulate_ssp`, libcosim and ecos do.
    Jacobi,
    /// Outputs flow along direct-feedthrough chains in topological order, so an input sees
    /// its source at the same communication point; algebraic loops are refused by name.
    Ordered,
}

impl std::str::FromStr for Algorithm {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "jacobi" => Ok(Algorithm::Jacobi),
            "ordered" => Ok(Algorithm::Ordered),
            _ => Err(format!("unknown algorithm {s:?} (jacobi, ordered)")),
        }
    }
}

/// What to simulate.
#[derive(Clone, Debug)]
pub struct Experiment {
    /// Start time t0, s.
    pub start_time: f64,
    /// Stop time, s.
    pub stop_time: f64,
    /// Communication step h, s.
    pub step: f64,
    /// Algorithm.
    pub algorithm: Algorithm,
    /// Output interval (a whole multiple of `step`); `None`: every step.
    pub output_interval: Option<f64>,
    /// Variables to record (`instance.variable`); `None`: every output of every instance.
    pub record: Option<Vec<String>>,
    /// Measure the time spent in each FMU (one clock read per call boundary).
    pub profile: bool,
    /// Threads stepping the instances of a `jacobi` system (1: all in the calling
    /// thread). Each instance is called by one thread at a time; the results are the
    /// same for any number. `ordered` always runs in one thread.
    pub threads: usize,
    /// Called with the fraction done (0..=1) at each output point.
    pub progress: Option<fn(f64)>,
    /// Integration method of Model Exchange instances.
    pub solver: crate::me::Solver,
    /// On fmi2Discard from `fmi2DoStep` of an FMU that can get and set its state and
    /// handle variable steps: restore the state and retry in halves (at most 2^10
    /// sub-steps). Costs one `fmi2GetFMUstate` per step of those FMUs. Off: a Discard
    /// stops the run with [`Error::Fmi`].
    pub retry_discard: bool,
}

impl Experiment {
    /// `stop_time` with step `h` from 0, jacobi, every step recorded.
    pub fn new(stop_time: f64, step: f64) -> Experiment {
        Experiment {
            start_time: 0.0,
            stop_time,
            step,
            algorithm: Algorithm::Jacobi,
            output_interval: None,
            record: None,
            profile: false,
            threads: 1,
            progress: None,
            solver: crate::me::Solver::default(),
            retry_discard: false,
        }
    }
}

/// Results: one row per output point, `time` first.
#[derive(Clone, Debug, Default)]
pub struct Results {
    /// Column names after `time` (`instance.variable`, or the bare name for a one-instance system).
    pub names: Vec<String>,
    /// Row-major values: `time, v1, v2, ...` per row.
    pub values: Vec<f64>,
}

impl Results {
    /// Number of columns including time.
    pub fn width(&self) -> usize {
        self.names.len() + 1
    }
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.values.len() / self.width()
    }
    /// Row `k` (time first).
    pub fn row(&self, k: usize) -> &[f64] {
        &self.values[k * self.width()..(k + 1) * self.width()]
    }
    /// The column called `name` (`"time"` for time).
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = if name == "time" { 0 } else { self.names.iter().position(|n| n == name)? + 1 };
        Some((0..self.rows()).map(|k| self.row(k)[j]).collect())
    }

    /// Writes CSV as fmpy does: comma-separated, quoted names, `time` first; numbers
    /// in the shortest form that reads back to the same f64.
    pub fn write_csv<W: std::io::Write>(&self, mut w: W) -> std::io::Result<()> {
        let mut line = String::from("\"time\"");
        for n in &self.names {
            line.push_str(",\"");
            line.push_str(&n.replace('"', "\"\""));
            line.push('"');
        }
        line.push('\n');
        w.write_all(line.as_bytes())?;
        for k in 0..self.rows() {
            line.clear();
            for (j, v) in self.row(k).iter().enumerate() {
                if j > 0 {
                    line.push(',');
                }
                push_number(&mut line, *v);
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        w.flush()
    }
}

/// Shortest round-trip text of `v` (exponent form for very small or large magnitudes).
pub fn push_number(out: &mut String, v: f64) {
    use std::fmt::Write;
    let a = v.abs();
    if v == 0.0 || (1e-5..1e16).contains(&a) || !v.is_finite() {
        let _ = write!(out, "{v}");
    } else {
        let _ = write!(out, "{v:e}");
    }
}

/// A JSON-able run summary.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// Communication steps taken.
    pub steps: u64,
    /// Wall time of initialization + loop.
    pub wall_time: Duration,
    /// Per instance: name and time spent in its fmi2 calls (zero unless profiling).
    pub instance_time: Vec<(String, Duration)>,
    /// Warnings the FMUs logged (instance, message).
    pub warnings: Vec<(String, String)>,
    /// Events of Model Exchange instances.
    pub events: Vec<crate::me::Event>,
    /// Internal integrator steps of Model Exchange instances (accepted, rejected).
    pub integrator_steps: (u64, u64),
    /// Steps redone in halves after an fmi2Discard.
    pub discard_retries: u64,
    /// `jacobi` steps run with the instances spread over threads (0 in one thread).
    pub parallel_steps: u64,
}

impl Summary {
    /// As a JSON value.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "steps": self.steps,
            "events": self.events.len(),
            "event_times": self.events.iter().map(|e| serde_json::json!({"instance": e.instance, "time": e.time, "kind": e.kind})).collect::<Vec<_>>(),
            "discard_retries": self.discard_retries,
            "parallel_steps": self.parallel_steps,
            "integrator_steps": {"accepted": self.integrator_steps.0, "rejected": self.integrator_steps.1},
            "wall_time_s": self.wall_time.as_secs_f64(),
            "instances": self.instance_time.iter().map(|(n, d)| serde_json::json!({"name": n, "time_s": d.as_secs_f64()})).collect::<Vec<_>>(),
            "warnings": self.warnings.iter().map(|(n, m)| serde_json::json!({"instance": n, "message": m})).collect::<Vec<_>>(),
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OpKind {
    Get,
    Set,
}

/// One batched fmi2Get/fmi2Set call of one instance and one base type.
#[derive(Debug)]
pub(crate) struct Op {
    pub(crate) instance: usize,
    kind: OpKind,
    base_type: BaseType,
    vrs: Vec<u32>,
    /// Get: slot each value goes to. Set: (slot, gain, offset) each value comes from.
    slots: Vec<usize>,
    gains: Vec<(f64, f64)>,
    reals: Vec<f64>,
    ints: Vec<i32>,
    /// A get of Reals whose slots are consecutive, from this one: fetched straight into
    /// the value buffer, with no copy through the op's own.
    direct: Option<usize>,
}

impl Op {
    fn new(instance: usize, kind: OpKind, base_type: BaseType) -> Op {
        Op {
            instance,
            kind,
            base_type,
            vrs: vec![],
            slots: vec![],
            gains: vec![],
            reals: vec![],
            ints: vec![],
            direct: None,
        }
    }
    fn push(&mut self, vr: u32, slot: usize, gain: (f64, f64)) {
        self.direct = match (self.kind, self.base_type, self.slots.first()) {
            (OpKind::Get, BaseType::Real, None) => Some(slot),
            (_, _, Some(&first)) if self.direct == Some(first) && slot == first + self.slots.len() => Some(first),
            _ => None,
        };
        self.vrs.push(vr);
        self.slots.push(slot);
        self.gains.push(gain);
        self.reals.push(0.0);
        self.ints.push(0);
    }

    #[inline]
    pub(crate) fn run(&mut self, inst: &mut Instance, values: &mut [f64]) -> Result<()> {
        match self.kind {
            OpKind::Get => match self.direct {
                Some(first) => inst.get_real(&self.vrs, &mut values[first..first + self.vrs.len()])?,
                None => {
                    self.fetch(inst)?;
                    self.scatter(values);
                }
            },
            OpKind::Set => {
                self.gather(values);
                self.apply(inst)?;
            }
        }
        Ok(())
    }

    /// Whether the op sets inputs.
    pub(crate) fn is_set(&self) -> bool {
        self.kind == OpKind::Set
    }

    /// The value slots the op reads (set) or writes (get).
    pub(crate) fn slots(&self) -> &[usize] {
        &self.slots
    }

    /// Get: the fmi2Get call into the op's own buffer.
    #[inline]
    fn fetch(&mut self, inst: &mut Instance) -> Result<()> {
        match self.base_type {
            BaseType::Real => inst.get_real(&self.vrs, &mut self.reals),
            BaseType::Integer => inst.get_integer(&self.vrs, &mut self.ints),
            BaseType::Boolean => inst.get_boolean(&self.vrs, &mut self.ints),
            BaseType::String => Ok(()),
        }
    }

    /// Get: the fetched values into their slots.
    #[inline]
    fn scatter(&self, values: &mut [f64]) {
        match self.base_type {
            BaseType::Real => {
                for (s, v) in self.slots.iter().zip(&self.reals) {
                    values[*s] = *v;
                }
            }
            BaseType::Integer => {
                for (s, v) in self.slots.iter().zip(&self.ints) {
                    values[*s] = f64::from(*v);
                }
            }
            BaseType::Boolean => {
                for (s, v) in self.slots.iter().zip(&self.ints) {
                    values[*s] = if *v != 0 { 1.0 } else { 0.0 };
                }
            }
            BaseType::String => {}
        }
    }

    /// Set: the source slots, transformed, into the op's buffer.
    #[inline]
    fn gather(&mut self, values: &[f64]) {
        match self.base_type {
            BaseType::Real => {
                for ((r, s), (g, o)) in self.reals.iter_mut().zip(&self.slots).zip(&self.gains) {
                    *r = g * values[*s] + o;
                }
            }
            BaseType::Integer => {
                for (r, s) in self.ints.iter_mut().zip(&self.slots) {
                    *r = values[*s] as i32;
                }
            }
            BaseType::Boolean => {
                for (r, s) in self.ints.iter_mut().zip(&self.slots) {
                    *r = (values[*s] != 0.0) as i32;
                }
            }
            BaseType::String => {}
        }
    }

    /// Set: the fmi2Set call from the op's buffer.
    #[inline]
    fn apply(&mut self, inst: &mut Instance) -> Result<()> {
        match self.base_type {
            BaseType::Real => inst.set_real(&self.vrs, &self.reals),
            BaseType::Integer => inst.set_integer(&self.vrs, &self.ints),
            BaseType::Boolean => inst.set_boolean(&self.vrs, &self.ints),
            BaseType::String => Ok(()),
        }
    }
}

/// Appends `node` to the op list, merging into the last op when it is the same call.
fn emit(ops: &mut Vec<Op>, instance: usize, kind: OpKind, ty: BaseType, vr: u32, slot: usize, gain: (f64, f64)) {
    match ops.last_mut() {
        Some(op) if op.instance == instance && op.kind == kind && op.base_type == ty => {
            if kind == OpKind::Get && op.vrs.contains(&vr) && op.slots.contains(&slot) {
                return;
            }
            op.push(vr, slot, gain)
        }
        _ => {
            let mut op = Op::new(instance, kind, ty);
            op.push(vr, slot, gain);
            ops.push(op);
        }
    }
}

/// The communication plan of a system: slots for every connected output and recorded
/// variable, and the batched calls.
#[derive(Debug)]
struct Plan {
    /// The variable behind each slot of the value buffer.
    sources: Vec<VariableRef>,
    /// `ordered`: the batched calls in topological order (None: the graph has a loop).
    ordered: Option<Vec<Op>>,
    /// `jacobi`, per instance: one get per type of its connected outputs.
    jacobi_gets: Vec<Vec<Op>>,
    /// `jacobi`, per instance: one get per type of its connected outputs and recorded
    /// variables (used at output points instead of `jacobi_gets`).
    jacobi_gets_rec: Vec<Vec<Op>>,
    /// `jacobi`, per instance: one set per type of its connected inputs.
    jacobi_sets: Vec<Vec<Op>>,
}

fn slot_of(sources: &mut Vec<VariableRef>, r: &VariableRef) -> usize {
    if let Some(k) = sources.iter().position(|s| s == r) {
        return k;
    }
    sources.push(r.clone());
    sources.len() - 1
}

/// Whether output `out` of an FMU depends directly on input `input` (0-based indices).
fn depends(md: &model_description::ModelDescription, out: usize, input: usize) -> bool {
    let index = out as u32 + 1;
    match md.model_structure.outputs.iter().find(|u| u.index == index) {
        Some(u) => match &u.dependencies {
            None => true,
            Some(deps) => deps.contains(&(input as u32 + 1)),
        },
        None => true, // not listed: assume the worst
    }
}

/// Topological order of the variable-level graph (connections and direct feedthrough),
/// or the algebraic loop by name.
fn ordered_nodes(system: &System, connected_outputs: &[VariableRef]) -> Result<Vec<(bool, usize)>> {
    // nodes: outputs (is_output = true, index into connected_outputs) and connections' inputs
    let n_out = connected_outputs.len();
    let n = n_out + system.connections.len();
    let mut edges: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (c, conn) in system.connections.iter().enumerate() {
        let src = connected_outputs.iter().position(|o| *o == conn.from).unwrap_or(0);
        edges[src].push(n_out + c); // output -> input (connection)
        for (o, out) in connected_outputs.iter().enumerate() {
            if out.instance == conn.to.instance && depends(system.description(out.instance), out.index, conn.to.index) {
                edges[n_out + c].push(o); // input -> output of the same FMU (feedthrough)
            }
        }
    }
    let mut indegree = vec![0usize; n];
    for e in edges.iter().flatten() {
        indegree[*e] += 1;
    }
    let node_instance =
        |k: usize| if k < n_out { connected_outputs[k].instance } else { system.connections[k - n_out].to.instance };
    let mut ready: Vec<usize> = (0..n).filter(|k| indegree[*k] == 0).collect();
    let mut order = Vec::with_capacity(n);
    // inputs of each instance not yet in the order: an instance's inputs are best set in
    // one call, once all of them are ready
    let mut pending_inputs = vec![0usize; system.instances.len()];
    for c in &system.connections {
        pending_inputs[c.to.instance] += 1;
    }
    let mut last: Option<(usize, bool)> = None;
    while !ready.is_empty() {
        // fewest calls: the same instance and kind as the last node (one batch), then
        // outputs (reading them sets nothing), then an instance whose inputs are all ready
        let is_out = |k: &usize| *k < n_out;
        let same = |k: &usize| last.is_some_and(|(i, o)| node_instance(*k) == i && is_out(k) == o);
        let ready_inputs = |i: usize| ready.iter().filter(|k| !is_out(k) && node_instance(**k) == i).count();
        let complete = |k: &usize| !is_out(k) && ready_inputs(node_instance(*k)) == pending_inputs[node_instance(*k)];
        let pick = ready
            .iter()
            .position(same)
            .or_else(|| ready.iter().position(is_out))
            .or_else(|| ready.iter().position(complete))
            .or_else(|| (0..ready.len()).max_by_key(|p| (ready_inputs(node_instance(ready[*p])), usize::MAX - p)))
            .unwrap_or(0);
        let k = ready.swap_remove(pick);
        if k >= n_out {
            pending_inputs[node_instance(k)] -= 1;
        }
        last = Some((node_instance(k), k < n_out));
        order.push(k);
        for &e in &edges[k] {
            indegree[e] -= 1;
            if indegree[e] == 0 {
                ready.push(e);
            }
        }
    }
    if order.len() < n {
        // a cycle remains among nodes with indegree > 0: walk it from any of them
        let name = |k: usize| {
            if k < n_out {
                system.name_of(&connected_outputs[k])
            } else {
                system.name_of(&system.connections[k - n_out].to)
            }
        };
        // Walk backwards: every node left has a predecessor left (else it would have been
        // ordered), so the walk closes a cycle; walking forwards could run from the loop
        // into nodes that merely depend on it.
        let mut predecessors: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (from, to) in edges.iter().enumerate() {
            for &t in to {
                if indegree[from] > 0 {
                    predecessors[t].push(from);
                }
            }
        }
        let mut k = (0..n).find(|k| indegree[*k] > 0).unwrap_or(0);
        let mut seen = vec![usize::MAX; n];
        let mut path: Vec<usize> = Vec::new();
        while seen[k] == usize::MAX {
            seen[k] = path.len();
            path.push(k);
            k = predecessors[k].first().copied().unwrap_or(k);
        }
        let mut cycle: Vec<usize> = path[seen[k]..].to_vec();
        cycle.reverse(); // in the direction the values flow
        let variables = cycle.iter().chain(cycle.first()).map(|x| name(*x)).collect();
        return Err(Error::AlgebraicLoop { variables });
    }
    Ok(order.into_iter().map(|k| if k < n_out { (true, k) } else { (false, k - n_out) }).collect())
}

impl Plan {
    fn new(system: &System, record: &[VariableRef], algorithm: Algorithm) -> Result<Plan> {
        let mut sources: Vec<VariableRef> = Vec::new();
        let mut connected_outputs: Vec<VariableRef> = Vec::new();
        for c in &system.connections {
            slot_of(&mut sources, &c.from);
            if !connected_outputs.contains(&c.from) {
                connected_outputs.push(c.from.clone());
            }
        }
        for r in record {
            slot_of(&mut sources, r);
        }
        // slots in the order the propagation reads them, then the recorded-only variables
        // by instance and type: every get of the `ordered` plan then fills consecutive
        // slots, straight from its fmi2GetReal (`Op::direct`)
        if let Ok(ops) = ordered_ops(system, &sources, &connected_outputs) {
            let mut order: Vec<usize> = Vec::with_capacity(sources.len());
            for op in ops.iter().filter(|op| op.kind == OpKind::Get) {
                for &slot in &op.slots {
                    if !order.contains(&slot) {
                        order.push(slot);
                    }
                }
            }
            let mut rest: Vec<usize> = (0..sources.len()).filter(|k| !order.contains(k)).collect();
            rest.sort_by_key(|&k| (sources[k].instance, sources[k].base_type));
            order.extend(rest);
            sources = order.into_iter().map(|k| sources[k].clone()).collect();
        }
        // jacobi: per instance and type one get of its connected outputs (and one with the
        // recorded variables too, for output points), then one set of its connected inputs
        let n = system.instances.len();
        let (mut jacobi_gets, mut jacobi_gets_rec, mut jacobi_sets) =
            (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
        for i in 0..n {
            let (mut gets, mut gets_rec, mut sets) = (Vec::new(), Vec::new(), Vec::new());
            for ty in [BaseType::Real, BaseType::Integer, BaseType::Boolean] {
                let mut get = Op::new(i, OpKind::Get, ty);
                let mut get_rec = Op::new(i, OpKind::Get, ty);
                for (k, s) in sources.iter().enumerate() {
                    if s.instance == i && s.base_type == ty {
                        if connected_outputs.contains(s) {
                            get.push(s.value_reference, k, (1.0, 0.0));
                        }
                        get_rec.push(s.value_reference, k, (1.0, 0.0));
                    }
                }
                if !get.vrs.is_empty() {
                    gets.push(get);
                }
                if !get_rec.vrs.is_empty() {
                    gets_rec.push(get_rec);
                }
                let mut set = Op::new(i, OpKind::Set, ty);
                for c in system.connections.iter().filter(|c| c.to.instance == i && c.to.base_type == ty) {
                    let slot = sources.iter().position(|s| *s == c.from).unwrap_or(0);
                    set.push(c.to.value_reference, slot, (c.gain, c.offset));
                }
                if !set.vrs.is_empty() {
                    sets.push(set);
                }
            }
            jacobi_gets.push(gets);
            jacobi_gets_rec.push(gets_rec);
            jacobi_sets.push(sets);
        }
        let ordered = match ordered_ops(system, &sources, &connected_outputs) {
            Ok(ops) => Some(ops),
            Err(e) if algorithm == Algorithm::Ordered => return Err(e),
            Err(_) => None,
        };
        Ok(Plan { sources, ordered, jacobi_gets, jacobi_gets_rec, jacobi_sets })
    }
}

/// The batched gets and sets that carry every connection of `system` in topological
/// order (slots: positions in `sources`), or the algebraic loop by name.
pub(crate) fn ordered_ops(
    system: &System,
    sources: &[VariableRef],
    connected_outputs: &[VariableRef],
) -> Result<Vec<Op>> {
    let nodes = ordered_nodes(system, connected_outputs)?;
    let mut ops = Vec::new();
    for (is_output, k) in nodes {
        if is_output {
            let r = &connected_outputs[k];
            let slot = sources.iter().position(|s| s == r).unwrap_or(0);
            emit(&mut ops, r.instance, OpKind::Get, r.base_type, r.value_reference, slot, (1.0, 0.0));
        } else {
            let c = &system.connections[k];
            let slot = sources.iter().position(|s| *s == c.from).unwrap_or(0);
            emit(&mut ops, c.to.instance, OpKind::Set, c.to.base_type, c.to.value_reference, slot, (c.gain, c.offset));
        }
    }
    Ok(ops)
}

/// Time spent in each instance's calls, one clock read per call boundary: the time from
/// the previous mark to the end of a call is charged to that call's instance (the
/// master's marshalling of the call's arguments included).
struct Profiler {
    last: Instant,
    spent: Vec<Duration>,
}

impl Profiler {
    fn new(n: usize) -> Profiler {
        Profiler { last: Instant::now(), spent: vec![Duration::ZERO; n] }
    }
    #[inline]
    fn restart(&mut self) {
        self.last = Instant::now();
    }
    /// Charges the time since the last mark evenly to `instances` (a coupled group).
    fn charge_shared(&mut self, instances: &[usize]) {
        let now = Instant::now();
        let share = (now - self.last) / instances.len().max(1) as u32;
        for &i in instances {
            self.spent[i] += share;
        }
        self.last = now;
    }

    #[inline]
    fn charge(&mut self, instance: usize) {
        let now = Instant::now();
        self.spent[instance] += now - self.last;
        self.last = now;
    }
}

fn run_ops(ops: &mut [Op], lanes: &mut [Lane], values: &mut [f64], mut profiler: Option<&mut Profiler>) -> Result<()> {
    if let Some(p) = profiler.as_deref_mut() {
        p.restart();
    }
    for op in ops.iter_mut() {
        op.run(&mut lanes[op.instance].inst, values)?;
        if let Some(p) = profiler.as_deref_mut() {
            p.charge(op.instance);
        }
    }
    Ok(())
}

/// One instance with everything its steps need: its integrator (Model Exchange), its
/// saved state (Discard retry) and, for `jacobi`, its own batched gets and sets. A lane
/// is stepped by one thread at a time.
pub(crate) struct Lane {
    pub(crate) index: usize,
    pub(crate) inst: Instance,
    pub(crate) unit: Option<MeUnit>,
    saved: Option<crate::fmu::FmuState>,
    gets: Vec<Op>,
    gets_rec: Vec<Op>,
    sets: Vec<Op>,
    /// Time in this lane's calls (when profiling in parallel).
    pub(crate) spent: Duration,
    retries: u64,
    /// The first error of this lane's last step.
    pub(crate) error: Option<Error>,
}

/// What every lane does in one `jacobi` step.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct StepArgs {
    /// Set the inputs (from the values of the previous step) before stepping.
    pub(crate) set_inputs: bool,
    pub(crate) t: f64,
    pub(crate) t_next: f64,
    /// Read the recorded variables too.
    pub(crate) output_point: bool,
    pub(crate) profile: bool,
}

impl Lane {
    /// `do_step` (or the integrator over the step), with the Discard retry if enabled.
    #[inline]
    fn advance(&mut self, solver: crate::me::Solver, t: f64, t_next: f64) -> Result<()> {
        let dt = t_next - t; // as fmpy: the step is the difference of the two points
        match (&mut self.unit, &mut self.saved) {
            (Some(unit), _) => unit.advance(&mut self.inst, solver, t, t_next),
            (None, None) => self.inst.do_step(t, dt),
            (None, Some(state)) => {
                self.retries += step_with_retry(&mut self.inst, state, t, dt, 0)?;
                Ok(())
            }
        }
    }

    /// One `jacobi` step of this instance: its inputs set from `values` (the outputs of
    /// the previous step), the step, its outputs fetched into its get buffers. The call
    /// sequence of an instance is the same whichever thread runs it.
    #[inline]
    pub(crate) fn jacobi_step(&mut self, values: &[f64], a: StepArgs, solver: crate::me::Solver) -> Result<()> {
        let start = a.profile.then(Instant::now);
        self.jacobi_inputs(values, a)?;
        self.advance(solver, a.t, a.t_next)?;
        self.jacobi_outputs(a)?;
        if let Some(start) = start {
            self.spent += start.elapsed();
        }
        Ok(())
    }

    /// The first part of a `jacobi` step: the inputs (unless the first step).
    #[inline]
    fn jacobi_inputs(&mut self, values: &[f64], a: StepArgs) -> Result<()> {
        if a.set_inputs {
            for op in self.sets.iter_mut() {
                op.gather(values);
                op.apply(&mut self.inst)?;
            }
        }
        Ok(())
    }

    /// The last part of a `jacobi` step: the outputs fetched.
    #[inline]
    fn jacobi_outputs(&mut self, a: StepArgs) -> Result<()> {
        let gets = if a.output_point { &mut self.gets_rec } else { &mut self.gets };
        for op in gets.iter_mut() {
            op.fetch(&mut self.inst)?;
        }
        Ok(())
    }

    /// The outputs fetched by the last [`Lane::jacobi_step`] into their slots.
    #[inline]
    pub(crate) fn scatter(&self, values: &mut [f64], output_point: bool) {
        let gets = if output_point { &self.gets_rec } else { &self.gets };
        for op in gets {
            op.scatter(values);
        }
    }

    /// The inputs set from `values` (after the last step, as the serial order does).
    fn set_inputs(&mut self, values: &[f64]) -> Result<()> {
        for op in self.sets.iter_mut() {
            op.gather(values);
            op.apply(&mut self.inst)?;
        }
        Ok(())
    }
}

/// The variables recorded by default: every output of every instance.
pub fn default_record(system: &System) -> Vec<VariableRef> {
    let mut out = Vec::new();
    for (i, spec) in system.instances.iter().enumerate() {
        for (index, v) in spec.fmu.description().model_variables.iter().enumerate() {
            if v.causality == Causality::Output && BaseType::of(v) != BaseType::String {
                out.push(VariableRef {
                    instance: i,
                    index,
                    value_reference: v.value_reference,
                    base_type: BaseType::of(v),
                });
            }
        }
    }
    out
}

/// Number of steps, the output stride, and whether the last step is shorter (the
/// interval is not a whole number of steps: allowed only when every Co-Simulation
/// instance has `canHandleVariableCommunicationStepSize`), checked.
fn schedule(e: &Experiment, system: &System) -> Result<(u64, u64, bool)> {
    let ok = |x: f64| x.is_finite();
    if !(ok(e.start_time) && ok(e.stop_time) && ok(e.step)) || e.step <= 0.0 || e.stop_time < e.start_time {
        return Err(Error::Experiment(format!(
            "need finite times with stop >= start and step > 0 (start {}, stop {}, step {})",
            e.start_time, e.stop_time, e.step
        )));
    }
    let span = (e.stop_time - e.start_time) / e.step;
    let mut steps = span.round();
    let partial = (span - steps).abs() > 1e-9 * span.max(1.0);
    if partial {
        if let Some(fixed) = system.instances.iter().find(|i| is_cs(i) && !i.fmu.can_handle_variable_step()) {
            return Err(Error::Experiment(format!(
                "the interval {} s is not a whole number of steps of {} s, and {} cannot take a shorter last step (canHandleVariableCommunicationStepSize is false)",
                e.stop_time - e.start_time,
                e.step,
                fixed.name
            )));
        }
        steps = span.ceil();
    }
    if steps > 1e12 {
        return Err(Error::Experiment(format!("{steps} steps is too many")));
    }
    let stride = match e.output_interval {
        None => 1.0,
        Some(d) => {
            let r = d / e.step;
            if !(d.is_finite() && d > 0.0) || (r - r.round()).abs() > 1e-9 * r.max(1.0) || r.round() < 1.0 {
                return Err(Error::Experiment(format!(
                    "the output interval {d} s must be a whole multiple of the step {} s",
                    e.step
                )));
            }
            r.round()
        }
    };
    Ok((steps as u64, stride as u64, partial))
}

/// Refuses a system with two instances of an FMU that declares
/// `canBeInstantiatedOnlyOncePerProcess`.
fn check_single_instance(system: &System) -> Result<()> {
    for (k, spec) in system.instances.iter().enumerate() {
        let md = spec.fmu.description();
        let once = match spec.fmu.interface() {
            Interface::CoSimulation => {
                md.co_simulation.as_ref().is_some_and(|c| c.can_be_instantiated_only_once_per_process)
            }
            Interface::ModelExchange => {
                md.model_exchange.as_ref().is_some_and(|m| m.can_be_instantiated_only_once_per_process)
            }
        };
        if !once {
            continue;
        }
        if let Some(other) = system.instances[k + 1..].iter().find(|o| o.fmu.description().guid == md.guid) {
            return Err(Error::Experiment(format!(
                "{} and {} are instances of {} (GUID {}), which can be instantiated only once per process (canBeInstantiatedOnlyOncePerProcess)",
                spec.name, other.name, md.model_name, md.guid
            )));
        }
    }
    Ok(())
}

/// Instantiates, initializes and runs `system` with fixed-step Co-Simulation.
pub fn simulate(system: &System, experiment: &Experiment) -> Result<(Results, Summary)> {
    let wall = Instant::now();
    let (steps, stride, partial) = schedule(experiment, system)?;
    check_single_instance(system)?;
    if experiment.threads == 0 {
        return Err(Error::Experiment("threads must be at least 1".into()));
    }
    let record: Vec<VariableRef> = match &experiment.record {
        None => default_record(system),
        Some(names) => names.iter().map(|n| system.resolve(n)).collect::<Result<_>>()?,
    };
    if let Some(r) = record.iter().find(|r| r.base_type == BaseType::String) {
        return Err(Error::InvalidValue {
            variable: system.name_of(r),
            value: String::new(),
            reason: "String variables cannot be recorded in CSV".into(),
        });
    }
    let mut plan = Plan::new(system, &record, experiment.algorithm)?;
    // Model Exchange instances connected to each other are integrated together
    let mut group = crate::coupled::MeGroup::of(system)?;
    let record_slots: Vec<usize> =
        record.iter().map(|r| plan.sources.iter().position(|s| s == r).unwrap_or(0)).collect();
    // all recorded variables, one get per instance and type (for the first row)
    let merged_record_gets = |record: &[VariableRef]| {
        let mut sorted: Vec<&VariableRef> = record.iter().collect();
        sorted.sort_by_key(|r| (r.instance, r.base_type));
        let mut ops: Vec<Op> = Vec::new();
        for r in sorted {
            let slot = plan.sources.iter().position(|s| s == r).unwrap_or(0);
            emit(&mut ops, r.instance, OpKind::Get, r.base_type, r.value_reference, slot, (1.0, 0.0));
        }
        ops
    };
    let mut record_gets = merged_record_gets(&record);
    // ordered: a recorded variable that the propagation reads after the last set of its
    // instance is already current in its slot; only the others are read at output points
    let mut record_gets_ordered = match &plan.ordered {
        Some(ops) => {
            let mut last_set = vec![None; system.instances.len()];
            for (k, op) in ops.iter().enumerate() {
                if op.kind == OpKind::Set {
                    last_set[op.instance] = Some(k);
                }
            }
            let fresh = |slot: usize| {
                ops.iter().enumerate().any(|(k, op)| {
                    op.kind == OpKind::Get && last_set[op.instance].is_none_or(|l| k > l) && op.slots.contains(&slot)
                })
            };
            let stale: Vec<VariableRef> = record
                .iter()
                .filter(|r| !fresh(plan.sources.iter().position(|s| s == *r).unwrap_or(0)))
                .cloned()
                .collect();
            merged_record_gets(&stale)
        }
        None => Vec::new(),
    };

    let single = system.instances.len() == 1;
    let names: Vec<String> =
        record.iter().map(|r| if single { system.variable(r).name.clone() } else { system.name_of(r) }).collect();
    let mut values = vec![0.0; plan.sources.len()];
    let rows = steps / stride + 2;
    // reserve for the whole run, up to 64 MiB up front (a huge run grows as it goes)
    let wanted = (rows as usize).saturating_mul(record.len() + 1).min(8 << 20);
    let mut results = Results { names, values: Vec::with_capacity(wanted) };

    // instantiate and initialize (FMI 2.0 section 4.2.4)
    let mut lanes: Vec<Lane> = Vec::with_capacity(system.instances.len());
    for (index, spec) in system.instances.iter().enumerate() {
        lanes.push(Lane {
            index,
            inst: Instance::new(&spec.fmu, &spec.name)?,
            unit: None,
            saved: None,
            gets: std::mem::take(&mut plan.jacobi_gets[index]),
            gets_rec: std::mem::take(&mut plan.jacobi_gets_rec[index]),
            sets: std::mem::take(&mut plan.jacobi_sets[index]),
            spent: Duration::ZERO,
            retries: 0,
            error: None,
        });
    }
    let t0 = experiment.start_time;
    for (lane, spec) in lanes.iter_mut().zip(&system.instances) {
        lane.inst.setup_experiment(None, t0, Some(experiment.stop_time))?;
        apply_start_values(&mut lane.inst, spec)?;
        lane.inst.enter_initialization_mode()?;
    }
    let propagate_initial = |plan: &mut Plan, lanes: &mut [Lane], values: &mut [f64]| -> Result<()> {
        match plan.ordered.as_mut() {
            Some(ops) => run_ops(ops, lanes, values, None),
            None => {
                for lane in lanes.iter_mut() {
                    for op in lane.gets.iter_mut() {
                        op.run(&mut lane.inst, values)?;
                    }
                }
                for lane in lanes.iter_mut() {
                    lane.set_inputs(values)?;
                }
                Ok(())
            }
        }
    };
    propagate_initial(&mut plan, &mut lanes, &mut values)?;
    for lane in lanes.iter_mut() {
        lane.inst.exit_initialization_mode()?;
        lane.unit = match lane.inst.fmu().interface() {
            Interface::ModelExchange if group.as_ref().is_some_and(|g| g.contains(lane.index)) => {
                Some(MeUnit::new(&lane.inst))
            }
            Interface::ModelExchange => Some(MeUnit::initialize(&mut lane.inst)?),
            Interface::CoSimulation => None,
        };
    }
    if let Some(g) = group.as_mut() {
        g.iterate(&mut lanes, t0)?; // the initial event iteration of the coupled ones, together
    }
    for lane in lanes.iter_mut() {
        let fmu = lane.inst.fmu();
        let capable =
            fmu.interface() == Interface::CoSimulation && fmu.can_get_and_set_state() && fmu.can_handle_variable_step();
        if experiment.retry_discard && capable {
            lane.saved = Some(lane.inst.get_state()?);
        }
    }
    propagate_initial(&mut plan, &mut lanes, &mut values)?;
    run_ops(&mut record_gets, &mut lanes, &mut values, None)?;
    push_row(&mut results, t0, &values, &record_slots);

    let profile = experiment.profile;
    let mut profiler = Profiler::new(lanes.len());
    let mut parallel_steps = 0u64;
    let h = experiment.step;
    let solver = experiment.solver;
    let point = |n: u64| {
        let last = n + 1 == steps;
        let t_next = if last && partial { experiment.stop_time } else { t0 + (n + 1) as f64 * h };
        (t0 + n as f64 * h, t_next, (n + 1).is_multiple_of(stride) || last)
    };
    let row = |results: &mut Results, n: u64, t_next: f64, values: &[f64]| {
        push_row(results, t_next, values, &record_slots);
        if let Some(p) = experiment.progress {
            p((n + 1) as f64 / steps as f64);
        }
    };
    match (experiment.algorithm, plan.ordered.as_mut()) {
        (Algorithm::Ordered, Some(ops)) => {
            for n in 0..steps {
                let (t, t_next, output_point) = point(n);
                let mut prof = profile.then_some(&mut profiler);
                if let Some(p) = prof.as_deref_mut() {
                    p.restart();
                }
                for lane in lanes.iter_mut() {
                    if group.as_ref().is_some_and(|g| g.contains(lane.index)) {
                        continue;
                    }
                    lane.advance(solver, t, t_next)?;
                    if let Some(p) = prof.as_deref_mut() {
                        p.charge(lane.index);
                    }
                }
                if let Some(g) = group.as_mut() {
                    g.advance(&mut lanes, solver, t, t_next)?;
                    if let Some(p) = prof.as_deref_mut() {
                        p.charge_shared(&g.members);
                    }
                }
                run_ops(ops, &mut lanes, &mut values, prof)?;
                if output_point {
                    run_ops(&mut record_gets_ordered, &mut lanes, &mut values, None)?;
                    row(&mut results, n, t_next, &values);
                }
            }
        }
        _ => {
            // jacobi: per instance (in parallel when asked) inputs from the previous
            // step, the step, its outputs; then all outputs into their slots
            // a coupled Model Exchange group steps as one: no threads then
            let threads = if group.is_some() { 1 } else { experiment.threads.min(lanes.len()) };
            let mut first = 0;
            // the pool stops when it is slower than one thread (see parallel.rs)
            if threads > 1 {
                // a few steps in one thread to measure each instance's cost, then the
                // instances spread over the threads by that cost
                let calibration = steps.min(CALIBRATION_STEPS);
                let calibration_start = Instant::now();
                for n in 0..calibration {
                    let (t, t_next, output_point) = point(n);
                    let a = StepArgs { set_inputs: n > 0, t, t_next, output_point, profile: true };
                    for lane in lanes.iter_mut() {
                        lane.jacobi_step(&values, a, solver)?;
                    }
                    for lane in lanes.iter() {
                        lane.scatter(&mut values, output_point);
                    }
                    if output_point {
                        row(&mut results, n, t_next, &values);
                    }
                }
                first = calibration;
                let serial_step = calibration_start.elapsed() / calibration.max(1) as u32;
                if first < steps {
                    let mut step_rows = |n: u64, values: &[f64]| {
                        let (_, t_next, output_point) = point(n);
                        if output_point {
                            row(&mut results, n, t_next, values);
                        }
                    };
                    let args = |n: u64| {
                        let (t, t_next, output_point) = point(n);
                        StepArgs { set_inputs: n > 0, t, t_next, output_point, profile }
                    };
                    let pool = crate::parallel::Pool { threads, solver, serial_step };
                    let (back, next) = pool.run(lanes, &mut values, first..steps, &args, &mut step_rows)?;
                    lanes = back;
                    parallel_steps = next - first;
                    first = next;
                }
            }
            for n in first..steps {
                let (t, t_next, output_point) = point(n);
                let a = StepArgs { set_inputs: n > 0, t, t_next, output_point, profile };
                match group.as_mut() {
                    None => {
                        for lane in lanes.iter_mut() {
                            lane.jacobi_step(&values, a, solver)?;
                        }
                    }
                    Some(g) => {
                        // the group's members: all inputs, the steps together, all outputs
                        for lane in lanes.iter_mut() {
                            if g.contains(lane.index) {
                                lane.jacobi_inputs(&values, a)?;
                            } else {
                                lane.jacobi_step(&values, a, solver)?;
                            }
                        }
                        let start = profile.then(Instant::now);
                        g.advance(&mut lanes, solver, t, t_next)?;
                        if let Some(start) = start {
                            let share = start.elapsed() / g.members.len().max(1) as u32;
                            for &m in g.members.iter() {
                                lanes[m].spent += share;
                            }
                        }
                        for &m in g.members.iter() {
                            lanes[m].jacobi_outputs(a)?;
                        }
                    }
                }
                for lane in lanes.iter() {
                    lane.scatter(&mut values, output_point);
                }
                if output_point {
                    row(&mut results, n, t_next, &values);
                }
            }
            // the inputs of the last point, as after every other step
            if steps > 0 {
                for lane in lanes.iter_mut() {
                    lane.set_inputs(&values)?;
                }
            }
            if profile {
                for lane in lanes.iter() {
                    profiler.spent[lane.index] += lane.spent;
                }
            }
        }
    }
    let mut summary = Summary { steps, parallel_steps, wall_time: Duration::ZERO, ..Summary::default() };
    for lane in lanes.iter_mut() {
        summary.discard_retries += lane.retries;
        if let Some(state) = lane.saved.take() {
            lane.inst.free_state(state)?;
        }
        if let Some(unit) = lane.unit.take() {
            summary.integrator_steps.0 += unit.steps;
            summary.integrator_steps.1 += unit.rejected;
            summary.events.extend(unit.events);
        }
    }
    for lane in lanes.iter_mut() {
        lane.inst.terminate()?;
        for rec in lane.inst.take_log() {
            if rec.status != crate::error::Status::Ok {
                summary.warnings.push((lane.inst.name().to_string(), rec.message));
            }
        }
    }
    drop(lanes);
    summary.instance_time = system.instances.iter().map(|s| s.name.clone()).zip(profiler.spent).collect();
    summary.wall_time = wall.elapsed();
    Ok((results, summary))
}

/// Steps run in one thread before the instances are spread over threads by their
/// measured cost (and the time of one step in one thread taken as the mark the pool must
/// beat).
const CALIBRATION_STEPS: u64 = 200;

/// `fmi2DoStep` with the state saved first; on fmi2Discard the state is restored and the
/// step taken as two halves (recursively, at most 10 levels). Returns the number of retries.
fn step_with_retry(inst: &mut Instance, state: &mut crate::fmu::FmuState, t: f64, dt: f64, depth: u32) -> Result<u64> {
    inst.update_state(state)?;
    match inst.do_step(t, dt) {
        Ok(()) => Ok(0),
        Err(Error::Fmi { status: crate::Status::Discard, .. }) if depth < 10 => {
            inst.set_state(state)?;
            let half = 0.5 * dt;
            let a = step_with_retry(inst, state, t, half, depth + 1)?;
            let b = step_with_retry(inst, state, t + half, dt - half, depth + 1)?;
            Ok(1 + a + b)
        }
        Err(e) => Err(e),
    }
}

#[inline]
fn push_row(results: &mut Results, t: f64, values: &[f64], slots: &[usize]) {
    results.values.push(t);
    results.values.extend(slots.iter().map(|s| values[*s]));
}

/// Sets the start values of an instance (before initialization mode), one call each.
pub fn apply_start_values(inst: &mut Instance, spec: &crate::system::InstanceSpec) -> Result<()> {
    let md = spec.fmu.description();
    for (index, value) in &spec.start_values {
        let vr = md.model_variables[*index].value_reference;
        match value {
            Value::Real(x) => inst.set_real(&[vr], &[*x])?,
            Value::Integer(x) => inst.set_integer(&[vr], &[*x])?,
            Value::Boolean(x) => inst.set_boolean(&[vr], &[*x as i32])?,
            Value::String(s) => inst.set_string(vr, s)?,
        }
    }
    Ok(())
}
