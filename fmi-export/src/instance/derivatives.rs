//! Partial derivatives (directional, and adjoint from the directional ones) and the
//! variable dependencies of FMI 3.0.

use super::{decl, err, Instance, OpResult};
use crate::decl::{BaseType, Causality, Declaration, Initial};
use crate::model::Model;
use crate::states::Machine;
impl<M: Model> Instance<M> {
    pub fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        out: &mut [f64],
    ) -> OpResult {
        if let Some(x) = dv_known.iter().find(|x| !x.is_finite()) {
            return err(format!("dvKnown contains {x}"));
        }
        let binding = |vr: u32| -> OpResult<M::Binding> {
            decl::<M>()
                .row(BaseType::Real, vr)
                .map(|r| decl::<M>().variable(r).binding)
                .ok_or_else(|| format!("unknown Real value reference {vr}").into())
        };
        let d = decl::<M>();
        // before fmi3ExitInitializationMode the initial dependencies (FMI 3.0 section 2.2.11)
        let initialization = matches!(self.core.machine, Machine::Instantiated | Machine::InitializationMode);
        for &vr in knowns {
            let row = Self::row_in(d, BaseType::Real, vr)?;
            let v = d.variable(row);
            // the knowns of FMI 2.0 section 2.2.8: inputs and continuous states, and in
            // Initialization Mode the variables with initial="exact" (a state calculated
            // from its start value stays a known there too: its partials are defined)
            let known = v.causality == Causality::Input
                || d.state_rows.contains(&row)
                || (initialization && v.initial == Some(Initial::Exact));
            if !known {
                return err(format!(
                    "known {} is not an input, a continuous state or (in Initialization Mode) exact",
                    v.name
                ));
            }
            if !M::provides_derivative_with_respect_to(v.binding, initialization) {
                return err(format!(
                    "derivatives with respect to {} are not provided ({} in Initialization Mode)",
                    v.name,
                    if initialization {
                        "only inputs, continuous states and their start values"
                    } else {
                        "only inputs and continuous states"
                    }
                ));
            }
        }
        for &vr in unknowns {
            let row = Self::row_in(d, BaseType::Real, vr)?;
            let v = d.variable(row);
            let unknown =
                v.causality == Causality::Output || d.state_rows.contains(&row) || d.derivative_rows.contains(&row);
            if !unknown {
                return err(format!("unknown {} is not an output, a continuous state or a derivative", v.name));
            }
        }
        let u: Vec<_> = unknowns.iter().map(|&vr| binding(vr)).collect::<OpResult<_>>()?;
        let k: Vec<_> = knowns.iter().map(|&vr| binding(vr)).collect::<OpResult<_>>()?;
        self.core.model.directional_derivative(&u, &k, dv_known, out)?;
        if let Some(i) = out.iter().position(|x| !x.is_finite()) {
            let name = decl::<M>().row(BaseType::Real, unknowns[i]).map(|r| decl::<M>().variable(r).name);
            return err(format!(
                "the derivative of {} evaluated to {} (seed or state out of the model's range)",
                name.unwrap_or("?"),
                out[i]
            ));
        }
        Ok(())
    }

    /// Adjoint derivatives `out = J^T w` (`out[j] = sum_i w_i dUnknown_i/dKnown_j`) from the
    /// columns of `J`: one directional derivative per known (`J e_j`, exact as the model's
    /// directional derivatives are), then the transposed product. Generic: every model with
    /// directional derivatives has it, in the same modes and with the same checks.
    pub fn adjoint_derivative(&mut self, unknowns: &[u32], knowns: &[u32], seed: &[f64], out: &mut [f64]) -> OpResult {
        if let Some(x) = seed.iter().find(|x| !x.is_finite()) {
            return err(format!("seed contains {x}"));
        }
        let mut column = vec![0.0; unknowns.len()];
        for (o, &known) in out.iter_mut().zip(knowns) {
            self.directional_derivative(unknowns, &[known], &[1.0], &mut column)?;
            *o = seed.iter().zip(&column).map(|(w, c)| w * c).sum();
        }
        Ok(())
    }

    /// `fmi3GetVariableDependencies`: the knowns the unknown `vr` depends on in the current
    /// state (the `<InitialUnknown>` entry in Initialization Mode, else the `<Output>` or
    /// `<ContinuousStateDerivative>` entry), as FMI 3.0 value references; an entry without
    /// `dependencies` depends on every known of the mode (FMI 3.0 section 2.4.8).
    pub fn variable_dependencies(&self, vr: u32) -> OpResult<Vec<u32>> {
        let d = decl::<M>();
        let Some(v) = d.variable3(vr) else { return err(format!("unknown value reference {vr}")) };
        let s = &d.model_description3().model_structure;
        // before fmi3ExitInitializationMode the initial dependencies (FMI 3.0 section 2.2.11)
        let initialization = matches!(self.core.machine, Machine::Instantiated | Machine::InitializationMode);
        let entry = if initialization {
            s.initial_unknowns.iter().find(|u| u.value_reference == vr)
        } else {
            s.outputs.iter().chain(&s.continuous_state_derivatives).find(|u| u.value_reference == vr)
        };
        let Some(entry) = entry else {
            return err(format!(
                "{} (value reference {vr}) is no unknown of the ModelStructure {}",
                v.name,
                if initialization { "in Initialization Mode" } else { "after initialization" }
            ));
        };
        Ok(match &entry.dependencies {
            Some(on) => on.clone(),
            None => (0..d.spec.variables.len())
                .filter(|&row| {
                    let k = d.variable(row);
                    k.causality == Causality::Input
                        || if initialization { k.initial == Some(Initial::Exact) } else { d.state_rows.contains(&row) }
                })
                .map(Declaration::<M::Binding>::value_reference3)
                .collect(),
        })
    }
}
