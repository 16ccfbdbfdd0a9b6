//! Get and set: the FMI 2.0 calls by base type and value reference (all-or-nothing sets,
//! the lookups of repeated arrays kept), and the FMI 3.0 calls mapped onto them.

use model_description::fmi3::ValueType as ValueType3;

use super::{decl, err, Instance, OpResult};
use crate::decl::{BaseType, Causality, Declaration, Initial, SetAccess, Variability};
use crate::model::{Model, ModelError};
use crate::states::{settable_in, Machine};

/// Values of one `fmi2Set*` call whose earlier values are kept for the way back without
/// copying the model (a longer call copies the model once, at its 33rd value).
const SET_UNDO_CAPACITY: usize = 32;

impl<M: Model> Instance<M> {
    /// The row of value reference `vr` of `base_type` in declaration `d` (fetched once per call).
    #[inline(always)]
    pub(super) fn row_in(d: &Declaration<M::Binding>, base_type: BaseType, vr: u32) -> OpResult<usize> {
        match d.row(base_type, vr) {
            Some(row) => Ok(row),
            None => Self::unknown_value_reference(base_type, vr),
        }
    }

    #[cold]
    #[inline(never)]
    fn unknown_value_reference(base_type: BaseType, vr: u32) -> OpResult<usize> {
        err(format!("unknown {base_type:?} value reference {vr}"))
    }

    /// Refuses the whole call if one value reference is unknown (before anything is read
    /// or changed). The rows are looked up again where they are used: a table lookup is
    /// cheaper than a vector allocated per call.
    #[inline(always)]
    fn check_rows(d: &Declaration<M::Binding>, base_type: BaseType, vrs: &[u32]) -> OpResult {
        for &vr in vrs {
            Self::row_in(d, base_type, vr)?;
        }
        Ok(())
    }

    /// Reads before sample 0 of a sampled model: the discrete outputs from what sample 0
    /// will latch (run on a copy), everything else from the model.
    #[cold]
    #[inline(never)]
    fn get_real_presample(&mut self, vrs: &[u32], out: &mut [f64]) -> OpResult {
        let d = decl::<M>();
        Self::check_rows(d, BaseType::Real, vrs)?;
        let mut sampled: Option<M> = None;
        for (o, &vr) in out.iter_mut().zip(vrs) {
            let row = Self::row_in(d, BaseType::Real, vr)?;
            let v = d.variable(row);
            let latched = v.variability == Variability::Discrete && v.initial == Some(Initial::Calculated);
            let model = if latched {
                if sampled.is_none() {
                    let mut copy = self.core.model.clone();
                    copy.sample(0, self.core.time)?;
                    sampled = Some(copy);
                }
                sampled.as_mut().unwrap_or(&mut self.core.model)
            } else {
                &mut self.core.model
            };
            let x = model.get_real(v.binding)?;
            if !x.is_finite() {
                return Self::not_finite(row, x);
            }
            *o = x;
        }
        Ok(())
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> OpResult {
        let d = decl::<M>();
        if self.clocked {
            self.settle_clock()?;
        } else {
            self.settle_events()?;
        }
        if self.core.presample {
            return self.get_real_presample(vrs, out);
        }
        if let Some(m) = self.get_memo.find(vrs) {
            // the same value references as a recent call: their rows are known
            for (o, r) in out.iter_mut().zip(&self.get_memo.arrays[m].rows) {
                let x = self.core.model.get_real(r.hot.binding)?;
                if !x.is_finite() {
                    return Self::not_finite(r.row, x);
                }
                *o = x;
            }
            return Ok(());
        }
        Self::check_rows(d, BaseType::Real, vrs)?;
        self.get_memo.fill(d, vrs, |_| true);
        for (o, &vr) in out.iter_mut().zip(vrs) {
            let row = Self::row_in(d, BaseType::Real, vr)?;
            let x = self.core.model.get_real(d.hot(row).binding)?;
            if !x.is_finite() {
                return Self::not_finite(row, x);
            }
            *o = x;
        }
        Ok(())
    }

    /// A Real of the model, refusing a non-finite result (an overflowed state, say)
    /// rather than handing NaN or Inf to the importer's solver.
    pub(super) fn finite_real(&mut self, row: usize) -> OpResult<f64> {
        let x = self.core.model.get_real(decl::<M>().variable(row).binding)?;
        if x.is_finite() {
            Ok(x)
        } else {
            Self::not_finite(row, x)
        }
    }

    #[cold]
    #[inline(never)]
    fn not_finite<T>(row: usize, x: f64) -> OpResult<T> {
        let name = decl::<M>().variable(row).name;
        err(format!("{name} evaluated to {x} (the state or inputs are out of the model's range)"))
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> OpResult {
        self.get_discrete(BaseType::Integer, vrs, out, M::get_integer)
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> OpResult {
        self.get_discrete(BaseType::Boolean, vrs, out, M::get_boolean)
    }

    /// The Integers or Booleans of `vrs`, after the events due at the current time.
    #[inline(always)]
    fn get_discrete<T>(
        &mut self,
        base_type: BaseType,
        vrs: &[u32],
        out: &mut [T],
        read: impl Fn(&mut M, M::Binding) -> crate::model::ModelResult<T>,
    ) -> OpResult {
        let d = decl::<M>();
        Self::check_rows(d, base_type, vrs)?;
        if self.clocked {
            self.settle_clock()?;
        } else {
            self.settle_events()?;
        }
        for (o, &vr) in out.iter_mut().zip(vrs) {
            let row = Self::row_in(d, base_type, vr)?;
            *o = read(&mut self.core.model, d.hot(row).binding)?;
        }
        Ok(())
    }

    /// Whether `value` fits variable `row` (min/max of the declaration, enumeration items).
    pub(super) fn check_value(row: usize, value: f64) -> Result<(), String> {
        decl::<M>().check_value(row, value)
    }

    /// Sets all or nothing: every value reference, permission and value is checked first
    /// (from the declaration's tables), then the values are applied in order. If the model
    /// refuses one, the values this call set before it are put back, newest first, with
    /// the values their getters returned before the call (the contract of
    /// [`Model::set_real`]): the model is as before the call. No copy of the model is made
    /// unless a getter fails (then from that value on the call keeps a copy to go back to);
    /// no earlier value is kept when the model refuses none of the call's variables
    /// ([`Model::setter_may_refuse`]).
    fn set_values<T: Copy + Into<f64>>(
        &mut self,
        base_type: BaseType,
        vrs: &[u32],
        values: &[T],
        mut read: impl FnMut(&mut M, M::Binding) -> OpResult<T>,
        mut apply: impl FnMut(&mut M, M::Binding, T) -> OpResult,
    ) -> OpResult {
        let d = decl::<M>();
        let machine_bit = self.core.machine.bit();
        let n = vrs.len().min(values.len());
        // the same Real value references as a recent call: their rows are known
        let memo = if base_type == BaseType::Real { self.set_memo.find(vrs) } else { None };
        let may_refuse = if let Some(m) = memo {
            for (r, &value) in self.set_memo.arrays[m].rows.iter().zip(values) {
                Self::check_set(r.row, r.hot.access, machine_bit, value.into(), self.core.machine)?;
            }
            self.set_memo.arrays[m].may_refuse
        } else {
            let mut may_refuse = false;
            for (&vr, &value) in vrs.iter().zip(values) {
                let row = Self::row_in(d, base_type, vr)?;
                let hot = d.hot(row);
                may_refuse |= M::setter_may_refuse(hot.binding);
                Self::check_set(row, hot.access, machine_bit, value.into(), self.core.machine)?;
            }
            if base_type == BaseType::Real {
                self.set_memo.fill(d, vrs, M::setter_may_refuse);
            }
            may_refuse
        };
        self.unsettle_events();
        if !may_refuse || n == 1 {
            // nothing to put back: the model refuses none of these (or only this one value,
            // which then leaves it unchanged)
            if let Some(m) = memo {
                for (r, &value) in self.set_memo.arrays[m].rows.iter().zip(values) {
                    apply(&mut self.core.model, r.hot.binding, value).map_err(|e| Self::named(r.row, e))?;
                }
                return Ok(());
            }
            for (&vr, &value) in vrs.iter().zip(values) {
                let row = Self::row_in(d, base_type, vr)?;
                apply(&mut self.core.model, d.hot(row).binding, value).map_err(|e| Self::named(row, e))?;
            }
            return Ok(());
        }
        // here n >= 2 and some value may be refused: the earlier values, for the way back
        let Some(&first) = values.first() else { return Ok(()) };
        let mut earlier = [first; SET_UNDO_CAPACITY];
        // from this index on, the way back is a copy of the model (when a getter failed or
        // the call is longer than `earlier`)
        let mut copy: Option<(usize, M)> = None;
        for k in 0..n {
            let row = Self::row_in(d, base_type, vrs[k])?;
            let binding = d.hot(row).binding;
            if copy.is_none() {
                match (k < SET_UNDO_CAPACITY).then(|| read(&mut self.core.model, binding)) {
                    Some(Ok(old)) => earlier[k] = old,
                    _ => copy = Some((k, self.core.model.clone())),
                }
            }
            if let Err(e) = apply(&mut self.core.model, binding, values[k]) {
                let e = Self::named(row, e);
                let undo_to = match copy.take() {
                    Some((from, model)) => {
                        self.core.model = model;
                        from
                    }
                    None => k,
                };
                for j in (0..undo_to).rev() {
                    let row = Self::row_in(d, base_type, vrs[j])?;
                    if let Err(undo) = apply(&mut self.core.model, d.hot(row).binding, earlier[j]) {
                        return err(format!(
                            "{}; putting back {} failed too ({undo}): the model broke the setter contract",
                            e.message(),
                            d.variable(row).name
                        ));
                    }
                }
                return Err(e);
            }
        }
        Ok(())
    }

    /// The checks of one value of `fmi2Set*`: the common case from the precomputed tables,
    /// the full checks (which give the reason) only when these do not accept at once.
    #[inline(always)]
    fn check_set(row: usize, access: SetAccess, machine_bit: u16, x: f64, machine: Machine) -> OpResult {
        if access.settable_in & machine_bit == 0 {
            let v = decl::<M>().variable(row);
            settable_in(v.name, v.causality, v.variability, v.initial, machine)?;
        }
        if !(access.plain && x >= access.lowest && x <= access.highest) {
            Self::check_value(row, x)?;
        }
        Ok(())
    }

    /// A model's refusal, with the variable's name in front.
    #[cold]
    #[inline(never)]
    fn named(row: usize, e: ModelError) -> ModelError {
        let name = decl::<M>().variable(row).name;
        match e {
            ModelError::Error(m) => ModelError::Error(format!("{name}: {m}")),
            ModelError::Discard(m) => ModelError::Discard(format!("{name}: {m}")),
        }
    }

    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> OpResult {
        self.set_values(BaseType::Real, vrs, values, |m, b| m.get_real(b), |m, b, x| m.set_real(b, x))
    }

    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> OpResult {
        self.set_values(BaseType::Integer, vrs, values, |m, b| m.get_integer(b), |m, b, x| m.set_integer(b, x))
    }

    pub fn set_boolean(&mut self, vrs: &[u32], values: &[bool]) -> OpResult {
        let as_f64: Vec<BoolAsF64> = values.iter().map(|&b| BoolAsF64(b)).collect();
        self.set_values(
            BaseType::Boolean,
            vrs,
            &as_f64,
            |m, b| m.get_boolean(b).map(BoolAsF64),
            |m, b, x| m.set_boolean(b, x.0),
        )
    }

    /// The FMI 2.0 value reference (of the base type that `accessed` is in FMI 2.0) of the
    /// FMI 3.0 value reference `vr`, checked to be a variable of type `accessed`. `time` (0)
    /// is refused: the callers that accept it handle it before.
    fn fmi2_reference(vr: u32, accessed: ValueType3) -> OpResult<u32> {
        let d = decl::<M>();
        // the declaration's table answers every accepted reference; the checks below only
        // say why a reference is refused
        if let Some(vr2) = d.fmi2_of_fmi3(vr, accessed) {
            return Ok(vr2);
        }
        let Some(v) = d.variable3(vr) else {
            return err(format!("unknown value reference {vr} (the FMU's are 0 ..= {})", d.spec.variables.len()));
        };
        if v.value_type != accessed {
            return err(format!(
                "value reference {vr} is {}, a {} variable, not a {} one",
                v.name,
                v.value_type.element(),
                accessed.element()
            ));
        }
        match d.row3(vr) {
            Some(row) => Ok(d.variable(row).value_reference),
            None => err(format!("value reference {vr} is {}, the independent variable", v.name)),
        }
    }

    /// [`Instance::fmi2_reference`] of each of `vrs`, all checked before any is used.
    pub fn fmi2_references(&self, vrs: &[u32], accessed: ValueType3) -> OpResult<Vec<u32>> {
        vrs.iter().map(|&vr| Self::fmi2_reference(vr, accessed)).collect()
    }

    /// Runs `f` with the FMI 2.0 value references of `vrs` ([`Instance::fmi2_references`]):
    /// on the stack for the calls a master makes at every communication point (up to 64
    /// values), so that the FMI 3.0 getters and setters allocate no more than FMI 2.0's.
    fn with_fmi2_references<T>(
        &mut self,
        vrs: &[u32],
        accessed: ValueType3,
        f: impl FnOnce(&mut Self, &[u32]) -> OpResult<T>,
    ) -> OpResult<T> {
        const ON_STACK: usize = 64;
        if vrs.len() <= ON_STACK {
            let mut buffer = [0u32; ON_STACK];
            for (slot, &vr) in buffer.iter_mut().zip(vrs) {
                *slot = Self::fmi2_reference(vr, accessed)?;
            }
            f(self, &buffer[..vrs.len()])
        } else {
            let vrs2 = self.fmi2_references(vrs, accessed)?;
            f(self, &vrs2)
        }
    }

    /// Before Initialization Mode an FMI 3.0 getter returns start values (FMI 3.0 section
    /// 2.3.2): a variable without one, calculated in Initialization Mode, is refused.
    fn check_start_values(&self, vrs: &[u32]) -> OpResult {
        if self.core.machine != Machine::Instantiated {
            return Ok(());
        }
        let d = decl::<M>();
        for &vr in vrs {
            let Some(row) = d.row3(vr) else { continue };
            let v = d.variable(row);
            if !matches!(v.initial, Some(Initial::Exact) | Some(Initial::Approx)) && v.causality != Causality::Input {
                return err(format!(
                    "{} (value reference {vr}) has no start value: it is calculated in Initialization Mode, so it \
                     cannot be read in Instantiated",
                    v.name
                ));
            }
        }
        Ok(())
    }

    /// `fmi3GetFloat64`: the Float64 variables, `time` (value reference 0) included.
    pub fn get_float64(&mut self, vrs: &[u32], out: &mut [f64]) -> OpResult {
        self.check_start_values(vrs)?;
        if !vrs.contains(&0) {
            return self.with_fmi2_references(vrs, ValueType3::Float64, |i, vrs2| i.get_real(vrs2, out));
        }
        let others: Vec<u32> = vrs.iter().copied().filter(|&vr| vr != 0).collect();
        let vrs2 = self.fmi2_references(&others, ValueType3::Float64)?;
        let mut values = vec![0.0; vrs2.len()];
        self.get_real(&vrs2, &mut values)?;
        let mut values = values.into_iter();
        for (o, &vr) in out.iter_mut().zip(vrs) {
            if vr == 0 {
                *o = self.core.time;
            } else if let Some(x) = values.next() {
                *o = x;
            }
        }
        Ok(())
    }

    /// `fmi3SetFloat64` (`time` is refused: it is the independent variable).
    pub fn set_float64(&mut self, vrs: &[u32], values: &[f64]) -> OpResult {
        if vrs.contains(&0) {
            return err("time (value reference 0) cannot be set: it is the independent variable, \
                 advanced by fmi3DoStep or set by fmi3SetTime");
        }
        self.with_fmi2_references(vrs, ValueType3::Float64, |i, vrs2| i.set_real(vrs2, values))
    }

    /// `fmi3GetInt32` (Integers) or `fmi3GetInt64` (Enumerations).
    pub fn get_int(&mut self, vrs: &[u32], accessed: ValueType3, out: &mut [i32]) -> OpResult {
        self.check_start_values(vrs)?;
        self.with_fmi2_references(vrs, accessed, |i, vrs2| i.get_integer(vrs2, out))
    }

    /// `fmi3SetInt32` (Integers) or `fmi3SetInt64` (Enumerations): values outside the
    /// 32-bit range of the variables are refused before the declaration's checks.
    pub fn set_int(&mut self, vrs: &[u32], accessed: ValueType3, values: &[i64]) -> OpResult {
        let vrs2 = self.fmi2_references(vrs, accessed)?;
        let narrow: Vec<i32> = values
            .iter()
            .zip(vrs)
            .map(|(&x, &vr)| {
                i32::try_from(x).map_err(|_| {
                    let name = decl::<M>().variable3(vr).map_or("?", |v| v.name.as_str());
                    ModelError::from(format!("{name} = {x} refused: outside the 32-bit range of its values"))
                })
            })
            .collect::<OpResult<_>>()?;
        self.set_integer(&vrs2, &narrow)
    }

    /// `fmi3GetBoolean`.
    pub fn get_boolean3(&mut self, vrs: &[u32], out: &mut [bool]) -> OpResult {
        self.check_start_values(vrs)?;
        let vrs2 = self.fmi2_references(vrs, ValueType3::Boolean)?;
        self.get_boolean(&vrs2, out)
    }

    /// `fmi3SetBoolean`.
    pub fn set_boolean3(&mut self, vrs: &[u32], values: &[bool]) -> OpResult {
        let vrs2 = self.fmi2_references(vrs, ValueType3::Boolean)?;
        self.set_boolean(&vrs2, values)
    }

    /// The FMI 3.0 value references of the Float64 unknowns or knowns of a derivative
    /// call, as FMI 2.0 Real value references.
    pub fn real_references(&self, vrs: &[u32]) -> OpResult<Vec<u32>> {
        if vrs.contains(&0) {
            return err("time (value reference 0) is no unknown or known of a partial derivative here");
        }
        self.fmi2_references(vrs, ValueType3::Float64)
    }
}

/// A Boolean seen as a number for the shared value check (always finite, no bounds).
#[derive(Clone, Copy)]
struct BoolAsF64(bool);

impl From<BoolAsF64> for f64 {
    fn from(b: BoolAsF64) -> f64 {
        b.0 as u8 as f64
    }
}
