//! The communication plan: every connected output and recorded variable gets a slot in
//! one value buffer, and every exchange is a batched fmi2Get/fmi2Set call ([`Op`]) of one
//! instance and one base type, resolved to value references before the loop. `ordered`
//! takes its calls in the topological order of the variable graph (connections plus the
//! ModelStructure dependencies of outputs on inputs); `jacobi` per instance.

use crate::error::{Error, Result};
use crate::fmu::Instance;
use crate::simulate::integers::{self, Link};
use crate::simulate::types::Algorithm;
use crate::system::{BaseType, Connection, System, VariableRef};
use model_description::Causality;
use std::collections::{HashMap, HashSet};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum OpKind {
    Get,
    Set,
}

/// What an op carries: values of one base type of the view through their f64 slots, or
/// integers exactly (see `integers.rs`). One flat enum, so that an op's call is one match.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Carried {
    Real,
    Integer,
    Boolean,
    String,
    ExactInteger,
}

impl Carried {
    /// Values of `base_type` through their f64 slots.
    fn view(base_type: BaseType) -> Carried {
        match base_type {
            BaseType::Real => Carried::Real,
            BaseType::Integer => Carried::Integer,
            BaseType::Boolean => Carried::Boolean,
            BaseType::String => Carried::String,
        }
    }
}

/// One batched fmi2Get/fmi2Set call of one instance and one base type (or, carrying
/// integers exactly, one call per variable).
#[derive(Debug)]
pub(crate) struct Op {
    pub(crate) instance: usize,
    pub(crate) kind: OpKind,
    carried: Carried,
    vrs: Vec<u32>,
    /// Get: slot each value goes to. Set: (slot, gain, offset) each value comes from.
    slots: Vec<usize>,
    gains: Vec<(f64, f64)>,
    reals: Vec<f64>,
    ints: Vec<i32>,
    /// A get of Reals whose slots are consecutive, from this one: fetched straight into
    /// the value buffer, with no copy through the op's own.
    direct: Option<usize>,
    /// [`Carried::ExactInteger`]: the link of each variable and the integers read or to set.
    links: Vec<Link>,
    integers: Vec<i128>,
}

impl Op {
    fn new(instance: usize, kind: OpKind, carried: Carried) -> Op {
        Op {
            instance,
            kind,
            carried,
            vrs: vec![],
            slots: vec![],
            gains: vec![],
            reals: vec![],
            ints: vec![],
            direct: None,
            links: vec![],
            integers: vec![],
        }
    }
    fn push(&mut self, vr: u32, slot: usize, gain: (f64, f64), link: Option<Link>) {
        self.direct = match (self.kind, self.carried, self.slots.first()) {
            (OpKind::Get, Carried::Real, None) => Some(slot),
            (_, _, Some(&first)) if self.direct == Some(first) && slot == first + self.slots.len() => Some(first),
            _ => None,
        };
        self.vrs.push(vr);
        self.slots.push(slot);
        self.gains.push(gain);
        if let Some(link) = link {
            self.links.push(link);
            self.integers.push(0);
        } else {
            self.reals.push(0.0);
            self.ints.push(0);
        }
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

    /// The residual slots the op reads (set) or writes (get) beside [`Op::slots`], when it
    /// carries integers exactly (see `integers.rs`).
    pub(crate) fn residual_slots(&self) -> impl Iterator<Item = usize> + '_ {
        self.links.iter().map(Link::residual)
    }

    /// Get: the fmi2Get call into the op's own buffer.
    #[inline]
    pub(crate) fn fetch(&mut self, inst: &mut Instance) -> Result<()> {
        match self.carried {
            Carried::Real => inst.get_real(&self.vrs, &mut self.reals)?,
            Carried::Integer => inst.get_integer(&self.vrs, &mut self.ints)?,
            Carried::Boolean => inst.get_boolean(&self.vrs, &mut self.ints)?,
            Carried::String => {}
            Carried::ExactInteger => self.fetch_integers(inst)?,
        }
        Ok(())
    }

    /// Get: the fetched values into their slots.
    #[inline]
    pub(crate) fn scatter(&self, values: &mut [f64]) {
        match self.carried {
            Carried::Real => {
                for (s, v) in self.slots.iter().zip(&self.reals) {
                    values[*s] = *v;
                }
            }
            Carried::Integer => {
                for (s, v) in self.slots.iter().zip(&self.ints) {
                    values[*s] = f64::from(*v);
                }
            }
            Carried::Boolean => {
                for (s, v) in self.slots.iter().zip(&self.ints) {
                    values[*s] = if *v != 0 { 1.0 } else { 0.0 };
                }
            }
            Carried::String => {}
            Carried::ExactInteger => self.scatter_integers(values),
        }
    }

    /// Set: the source slots, transformed, into the op's buffer.
    #[inline]
    pub(crate) fn gather(&mut self, values: &[f64]) {
        match self.carried {
            Carried::Real => {
                for ((r, s), (g, o)) in self.reals.iter_mut().zip(&self.slots).zip(&self.gains) {
                    *r = g * values[*s] + o;
                }
            }
            Carried::Integer => {
                for (r, s) in self.ints.iter_mut().zip(&self.slots) {
                    *r = values[*s] as i32;
                }
            }
            Carried::Boolean => {
                for (r, s) in self.ints.iter_mut().zip(&self.slots) {
                    *r = (values[*s] != 0.0) as i32;
                }
            }
            Carried::String => {}
            Carried::ExactInteger => self.gather_integers(values),
        }
    }

    /// Set: the fmi2Set call from the op's buffer.
    #[inline]
    pub(crate) fn apply(&mut self, inst: &mut Instance) -> Result<()> {
        match self.carried {
            Carried::Real => inst.set_real(&self.vrs, &self.reals)?,
            Carried::Integer => inst.set_integer(&self.vrs, &self.ints)?,
            Carried::Boolean => inst.set_boolean(&self.vrs, &self.ints)?,
            Carried::String => {}
            Carried::ExactInteger => self.apply_integers(inst)?,
        }
        Ok(())
    }

    // The integer ops' calls, out of line: the calls of the other types (every step of
    // every run) keep the few registers and instructions they had.

    #[inline(never)]
    fn fetch_integers(&mut self, inst: &mut Instance) -> Result<()> {
        for ((vr, link), value) in self.vrs.iter().zip(&self.links).zip(&mut self.integers) {
            if let Link::Source { read, .. } = link {
                *value = integers::read(inst, *vr, *read)?;
            }
        }
        Ok(())
    }

    #[inline(never)]
    fn scatter_integers(&self, values: &mut [f64]) {
        for ((s, link), v) in self.slots.iter().zip(&self.links).zip(&self.integers) {
            (values[*s], values[link.residual()]) = integers::split(*v);
        }
    }

    #[inline(never)]
    fn gather_integers(&mut self, values: &[f64]) {
        for ((r, s), link) in self.integers.iter_mut().zip(&self.slots).zip(&self.links) {
            *r = integers::join(values[*s], values[link.residual()]);
        }
    }

    #[inline(never)]
    fn apply_integers(&mut self, inst: &mut Instance) -> Result<()> {
        for ((vr, link), value) in self.vrs.iter().zip(&self.links).zip(&self.integers) {
            if let Link::Sink { sink, .. } = link {
                integers::write(inst, *vr, *value, sink)?;
            }
        }
        Ok(())
    }
}

/// Appends `node` to the op list, merging into the last op when it is the same call (the
/// callers emit each get once: connected outputs and recorded variables without repeats).
#[allow(clippy::too_many_arguments)]
fn emit(
    ops: &mut Vec<Op>,
    instance: usize,
    kind: OpKind,
    carried: Carried,
    vr: u32,
    slot: usize,
    gain: (f64, f64),
    link: Option<Link>,
) {
    match ops.last_mut() {
        Some(op) if op.instance == instance && op.kind == kind && op.carried == carried => {
            op.push(vr, slot, gain, link)
        }
        _ => {
            let mut op = Op::new(instance, kind, carried);
            op.push(vr, slot, gain, link);
            ops.push(op);
        }
    }
}

/// What a get of `r` carries, and its link when an integer (`links`: the integer
/// connections' outputs, see [`source_links`]).
fn get_carried(links: &HashMap<VariableRef, Link>, r: &VariableRef) -> (Carried, Option<Link>) {
    match links.get(r) {
        Some(link) => (Carried::ExactInteger, Some(link.clone())),
        None => (Carried::view(r.base_type), None),
    }
}

/// What the set of `c`'s input carries, and its link when an integer.
fn set_carried(system: &System, residuals: &HashMap<VariableRef, usize>, c: &Connection) -> (Carried, Option<Link>) {
    match integers::sink_link(system, residuals, c) {
        Some(link) => (Carried::ExactInteger, Some(link)),
        None => (Carried::view(c.to.base_type), None),
    }
}

/// The link of every integer connection's output among `sources` (its residual slot after
/// the slots of `sources`).
fn source_links(system: &System, sources: &[VariableRef]) -> (HashMap<VariableRef, usize>, HashMap<VariableRef, Link>) {
    let residuals = integers::residual_slots(system, sources);
    let links =
        residuals.keys().filter_map(|r| Some((r.clone(), integers::source_link(system, &residuals, r)?))).collect();
    (residuals, links)
}

/// The communication plan of a system: slots for every connected output and recorded
/// variable, and the batched calls.
#[derive(Debug)]
pub(crate) struct Plan {
    /// The slot of each connected output and recorded variable in the value buffer.
    slots: HashMap<VariableRef, usize>,
    /// `ordered`: the batched calls in topological order (None: the graph has a loop).
    pub(crate) ordered: Option<Vec<Op>>,
    /// `jacobi`, per instance: one get per type of its connected outputs.
    pub(crate) jacobi_gets: Vec<Vec<Op>>,
    /// `jacobi`, per instance: one get per type of its connected outputs and recorded
    /// variables (used at output points instead of `jacobi_gets`).
    pub(crate) jacobi_gets_rec: Vec<Vec<Op>>,
    /// `jacobi`, per instance: one set per type of its connected inputs.
    pub(crate) jacobi_sets: Vec<Vec<Op>>,
    /// The outputs of integer connections, each with its residual slot after the slots
    /// of `sources` (see `integers.rs`).
    links: HashMap<VariableRef, Link>,
    /// The length of the value buffer: the slots of `sources` and the residual slots.
    pub(crate) exchange_len: usize,
}

/// The slot of `r` in `sources` (`slots`: the slot of each), added if new.
fn slot_of(sources: &mut Vec<VariableRef>, slots: &mut HashMap<VariableRef, usize>, r: &VariableRef) -> usize {
    *slots.entry(r.clone()).or_insert_with(|| {
        sources.push(r.clone());
        sources.len() - 1
    })
}

/// The slot of each variable of `sources`.
fn slots_of(sources: &[VariableRef]) -> HashMap<VariableRef, usize> {
    let mut slots = HashMap::with_capacity(sources.len());
    for (k, s) in sources.iter().enumerate() {
        slots.entry(s.clone()).or_insert(k);
    }
    slots
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
    /// The plan of `system` recording `record`; an algebraic loop is an error only for
    /// `ordered`.
    pub(crate) fn new(system: &System, record: &[VariableRef], algorithm: Algorithm) -> Result<Plan> {
        // (hash maps and sets: a system of 100,000 recorded array elements is planned in
        // time linear in them)
        let mut sources: Vec<VariableRef> = Vec::new();
        let mut slots: HashMap<VariableRef, usize> = HashMap::new();
        let mut connected_outputs: Vec<VariableRef> = Vec::new();
        let mut connected: HashSet<VariableRef> = HashSet::new();
        for c in &system.connections {
            slot_of(&mut sources, &mut slots, &c.from);
            if connected.insert(c.from.clone()) {
                connected_outputs.push(c.from.clone());
            }
        }
        for r in record {
            slot_of(&mut sources, &mut slots, r);
        }
        // slots in the order the propagation reads them, then the recorded-only variables
        // by instance and type: every get of the `ordered` plan then fills consecutive
        // slots, straight from its fmi2GetReal (`Op::direct`)
        if let Ok(ops) = ordered_ops(system, &sources, &connected_outputs) {
            let mut order: Vec<usize> = Vec::with_capacity(sources.len());
            let mut placed = vec![false; sources.len()];
            for op in ops.iter().filter(|op| op.kind == OpKind::Get) {
                for &slot in &op.slots {
                    if !placed[slot] {
                        placed[slot] = true;
                        order.push(slot);
                    }
                }
            }
            let mut rest: Vec<usize> = (0..sources.len()).filter(|k| !placed[*k]).collect();
            rest.sort_by_key(|&k| (sources[k].instance, sources[k].base_type));
            order.extend(rest);
            sources = order.into_iter().map(|k| sources[k].clone()).collect();
        }
        let slots = slots_of(&sources);
        let (residuals, links) = source_links(system, &sources);
        // jacobi: per instance and type one get of its connected outputs (and one with the
        // recorded variables too, for output points), then one set of its connected inputs
        let n = system.instances.len();
        let (mut jacobi_gets, mut jacobi_gets_rec, mut jacobi_sets) =
            (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
        let carried_types = [Carried::Real, Carried::Integer, Carried::Boolean, Carried::ExactInteger];
        for i in 0..n {
            let (mut gets, mut gets_rec, mut sets) = (Vec::new(), Vec::new(), Vec::new());
            for carried in carried_types {
                let mut get = Op::new(i, OpKind::Get, carried);
                let mut get_rec = Op::new(i, OpKind::Get, carried);
                for (k, s) in sources.iter().enumerate().filter(|(_, s)| s.instance == i) {
                    let (c, link) = get_carried(&links, s);
                    if c == carried {
                        if connected.contains(s) {
                            get.push(s.value_reference, k, (1.0, 0.0), link.clone());
                        }
                        get_rec.push(s.value_reference, k, (1.0, 0.0), link);
                    }
                }
                if !get.vrs.is_empty() {
                    gets.push(get);
                }
                if !get_rec.vrs.is_empty() {
                    gets_rec.push(get_rec);
                }
                let mut set = Op::new(i, OpKind::Set, carried);
                for c in system.connections.iter().filter(|c| c.to.instance == i) {
                    let (carries, link) = set_carried(system, &residuals, c);
                    if carries == carried {
                        let slot = slots.get(&c.from).copied().unwrap_or(0);
                        set.push(c.to.value_reference, slot, (c.gain, c.offset), link);
                    }
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
        let exchange_len = sources.len() + residuals.len();
        Ok(Plan { slots, ordered, jacobi_gets, jacobi_gets_rec, jacobi_sets, links, exchange_len })
    }

    /// The slots of the integer connections' outputs and their residual slots: the values
    /// that are integers, exact or wrong (see `integers.rs`).
    pub(crate) fn exact_slots(&self) -> Vec<usize> {
        self.links.iter().flat_map(|(r, link)| [self.slot(r), link.residual()]).collect()
    }

    /// The slot of a planned variable.
    pub(crate) fn slot(&self, r: &VariableRef) -> usize {
        self.slots.get(r).copied().unwrap_or(0)
    }

    /// One get per instance and type of the variables `record` (sorted by instance and
    /// type; a variable named twice read once).
    pub(crate) fn record_gets(&self, record: &[VariableRef]) -> Vec<Op> {
        let mut seen = HashSet::with_capacity(record.len());
        let mut sorted: Vec<&VariableRef> = record.iter().filter(|r| seen.insert(*r)).collect();
        sorted.sort_by_key(|r| (r.instance, r.base_type, self.links.contains_key(r)));
        let mut ops: Vec<Op> = Vec::new();
        for r in sorted {
            let (carried, link) = get_carried(&self.links, r);
            emit(&mut ops, r.instance, OpKind::Get, carried, r.value_reference, self.slot(r), (1.0, 0.0), link);
        }
        ops
    }

    /// `ordered`: the gets of the recorded variables at output points. A recorded variable
    /// that the propagation reads after the last set of its instance is already current
    /// in its slot; only the others are read.
    pub(crate) fn ordered_record_gets(&self, record: &[VariableRef]) -> Vec<Op> {
        let Some(ops) = &self.ordered else { return Vec::new() };
        let mut last_set = vec![None; self.jacobi_sets.len()];
        for (k, op) in ops.iter().enumerate() {
            if op.kind == OpKind::Set {
                last_set[op.instance] = Some(k);
            }
        }
        let fresh: HashSet<usize> = ops
            .iter()
            .enumerate()
            .filter(|(k, op)| op.kind == OpKind::Get && last_set[op.instance].is_none_or(|l| *k > l))
            .flat_map(|(_, op)| op.slots.iter().copied())
            .collect();
        let stale: Vec<VariableRef> = record.iter().filter(|r| !fresh.contains(&self.slot(r))).cloned().collect();
        self.record_gets(&stale)
    }
}

/// Access to the instances of a run by index (the lanes, or a part of them).
pub(crate) trait Instances {
    /// Instance `i` of the system.
    fn instance(&mut self, i: usize) -> &mut Instance;
}

/// Runs the calls `ops`, telling `calls` (the profiler, when one is attached) after each.
#[inline]
pub(crate) fn run_ops<I: Instances + ?Sized>(
    ops: &mut [Op],
    insts: &mut I,
    values: &mut [f64],
    mut calls: Option<&mut crate::simulate::profiler::Profiler>,
) -> Result<()> {
    if let Some(p) = calls.as_deref_mut() {
        p.restart();
    }
    for op in ops.iter_mut() {
        op.run(insts.instance(op.instance), values)?;
        if let Some(p) = calls.as_deref_mut() {
            p.charge(op.instance);
        }
    }
    Ok(())
}

/// The batched gets and sets that carry every connection of `system` in topological
/// order (slots: positions in `sources`), or the algebraic loop by name.
pub(crate) fn ordered_ops(
    system: &System,
    sources: &[VariableRef],
    connected_outputs: &[VariableRef],
) -> Result<Vec<Op>> {
    let nodes = ordered_nodes(system, connected_outputs)?;
    let slots = slots_of(sources);
    let (residuals, links) = source_links(system, sources);
    let mut ops = Vec::new();
    for (is_output, k) in nodes {
        if is_output {
            let r = &connected_outputs[k];
            let slot = slots.get(r).copied().unwrap_or(0);
            let (carried, link) = get_carried(&links, r);
            emit(&mut ops, r.instance, OpKind::Get, carried, r.value_reference, slot, (1.0, 0.0), link);
        } else {
            let c = &system.connections[k];
            let slot = slots.get(&c.from).copied().unwrap_or(0);
            let (carried, link) = set_carried(system, &residuals, c);
            emit(&mut ops, c.to.instance, OpKind::Set, carried, c.to.value_reference, slot, (c.gain, c.offset), link);
        }
    }
    Ok(ops)
}

/// The length of the value buffer of `ordered_ops(system, sources, ..)`: the slots of
/// `sources` and the residual slots of the integer connections' outputs among them.
pub(crate) fn exchange_len(system: &System, sources: &[VariableRef]) -> usize {
    sources.len() + integers::residual_slots(system, sources).len()
}

/// The variables recorded by default: every output of every instance.
pub fn default_record(system: &System) -> Vec<VariableRef> {
    let mut out = Vec::new();
    for (i, spec) in system.instances.iter().enumerate() {
        for (index, v) in spec.fmu.description().model_variables.iter().enumerate() {
            if v.causality == Causality::Output {
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
