//! Algebraic loops of a system at initialization: a cycle of connections closed through
//! FMUs whose connected outputs depend directly on their connected inputs (by the model
//! description's InitialUnknowns, else its Outputs; no dependency list: on every input).
//! A value on such a loop enters `fmi2ExitInitializationMode` at its converged value only
//! if the connections are carried until they settle: [`initialization_loop`] finds one
//! such loop, and the run then iterates the connections to their fixed point in
//! Initialization Mode (`simulate::init_loop`), saying so in a note.

use crate::system::System;
use std::collections::HashMap;

/// A variable of an instance: (instance, 0-based variable index).
type Var = (usize, usize);

/// One algebraic loop at initialization, as `a.y -> b.u` connections in order, or `None`.
pub fn initialization_loop(system: &System) -> Option<Vec<String>> {
    // nodes: connected inputs and outputs, (instance, 0-based variable index)
    let mut feeds: HashMap<(usize, usize), Vec<(usize, usize)>> = HashMap::new();
    let mut inputs_of: HashMap<usize, Vec<usize>> = HashMap::new();
    for c in &system.connections {
        feeds.entry((c.from.instance, c.from.index)).or_default().push((c.to.instance, c.to.index));
        inputs_of.entry(c.to.instance).or_default().push(c.to.index);
    }
    // within an FMU: connected input -> connected output that depends on it
    let depends = |instance: usize, output: usize, input: usize| -> bool {
        let ms = &system.description(instance).model_structure;
        let of = |list: &[model_description::Unknown]| {
            list.iter().find(|u| u.index as usize == output + 1).map(|u| u.dependencies.clone())
        };
        match of(&ms.initial_unknowns).or_else(|| of(&ms.outputs)) {
            Some(Some(deps)) => deps.contains(&(input as u32 + 1)),
            // listed without dependencies, or not listed: on every known
            _ => true,
        }
    };
    let outputs: Vec<(usize, usize)> = feeds.keys().copied().collect();
    // edges output -> output: o1 feeds input i of instance j, and j's output o2 depends on i
    let mut next: HashMap<Var, Vec<(Var, Var)>> = HashMap::new();
    for &o in &outputs {
        for &(j, i) in &feeds[&o] {
            for &o2 in outputs.iter().filter(|(inst, _)| *inst == j) {
                if depends(j, o2.1, i) {
                    next.entry(o).or_default().push(((j, i), o2));
                }
            }
        }
    }
    // depth-first search for a cycle (iterative: 0 unseen, 1 on the path, 2 done)
    let mut state: HashMap<(usize, usize), u8> = HashMap::new();
    let mut sorted = outputs.clone();
    sorted.sort_unstable();
    for &start in &sorted {
        if state.get(&start).copied().unwrap_or(0) != 0 {
            continue;
        }
        let mut stack: Vec<((usize, usize), usize)> = vec![(start, 0)];
        let mut via: Vec<(usize, usize)> = Vec::new(); // the input taken to each stacked node
        state.insert(start, 1);
        while let Some(&(node, k)) = stack.last() {
            let edges = next.get(&node).map(Vec::as_slice).unwrap_or(&[]);
            if k < edges.len() {
                let (input, o2) = edges[k];
                if let Some(top) = stack.last_mut() {
                    top.1 += 1;
                }
                match state.get(&o2).copied().unwrap_or(0) {
                    0 => {
                        state.insert(o2, 1);
                        stack.push((o2, 0));
                        via.push(input);
                    }
                    1 => {
                        // the cycle: from o2 on the stack to node, then node -> o2
                        let at = stack.iter().position(|(n, _)| *n == o2).unwrap_or(0);
                        let name = |(i, v): (usize, usize)| {
                            format!("{}.{}", system.instances[i].name, system.description(i).model_variables[v].name)
                        };
                        let mut out = Vec::new();
                        for s in at..stack.len() {
                            let target = if s + 1 < stack.len() { via[s] } else { input };
                            out.push(format!("{} -> {}", name(stack[s].0), name(target)));
                        }
                        return Some(out);
                    }
                    _ => {}
                }
            } else {
                state.insert(node, 2);
                stack.pop();
                via.pop();
            }
        }
    }
    None
}
