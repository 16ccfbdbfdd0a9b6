//! FMI 3.0 structural parameters: [`Fmu::configured`] is the FMU with some of them set, its
//! view (see [`crate::fmi3`]) computed with the new values, so that the arrays they size
//! have the new size for the master (connections, results); its instances set them in
//! Configuration Mode before initialization (`instance/configuration.rs`).
//! [`Fmu::sized_for`] is the FMU whose view is sized for a later value of a tunable one,
//! set in Reconfiguration Mode during the run ([`crate::Instance::reconfigure`]): until
//! then the arrays it sizes have fewer elements than the view, and the elements they lack
//! read as NaN ([`resized_arrays`]).
//! [`structural_parameters`] lists them with the arrays each sizes (for `cosim info`).

use std::collections::HashMap;
use std::sync::Arc;

use model_description::fmi3;

use crate::error::{Error, Result};
use crate::fmi3::Access;
use crate::fmu::{Abi, Fmu};

/// A structural parameter of an FMI 3.0 FMU and the arrays whose size it is.
#[derive(Clone, Debug, PartialEq)]
pub struct StructuralParameter {
    /// Its name.
    pub name: String,
    /// `fixed` or `tunable` (tunable ones may change in Reconfiguration Mode too).
    pub variability: &'static str,
    /// Its start value, as written (`None`: the description gives none).
    pub start: Option<String>,
    /// The names of the arrays with a `<Dimension valueReference>` naming it.
    pub sizes: Vec<String>,
}

/// The structural parameters of `md`, in document order.
pub fn structural_parameters(md: &fmi3::ModelDescription) -> Vec<StructuralParameter> {
    md.model_variables
        .iter()
        .filter(|v| v.causality == fmi3::Causality::StructuralParameter)
        .map(|p| StructuralParameter {
            name: p.name.clone(),
            variability: p.variability.as_str(),
            start: p.start.as_ref().map(|s| match s {
                fmi3::Values::Float(x) => x.iter().map(f64::to_string).collect::<Vec<_>>().join(" "),
                fmi3::Values::Int(x) => x.iter().map(i128::to_string).collect::<Vec<_>>().join(" "),
                fmi3::Values::Boolean(x) => x.iter().map(bool::to_string).collect::<Vec<_>>().join(" "),
                fmi3::Values::String(x) => x.join(" "),
                fmi3::Values::Binary(x) => format!("{} binary values", x.len()),
            }),
            sizes: md
                .model_variables
                .iter()
                .filter(|a| a.dimensions.contains(&fmi3::Dimension::Variable(p.value_reference)))
                .map(|a| a.name.clone())
                .collect(),
        })
        .collect()
}

/// The start value of the scalar structural parameter `v` for `value`, checked: a whole
/// number in its type's range for the integer types, within its `min` and `max`.
pub(crate) fn checked_value(instance: &str, v: &fmi3::Variable, value: f64) -> Result<fmi3::Values> {
    use fmi3::ValueType as T;
    let bad = |reason: String| Error::InvalidValue {
        variable: format!("{instance}.{}", v.name),
        value: value.to_string(),
        reason,
    };
    if v.is_array() {
        return Err(bad("an array structural parameter is not set by cosim (only scalars)".into()));
    }
    let (lowest, highest): (i128, i128) = match v.value_type {
        T::Int8 => (i8::MIN.into(), i8::MAX.into()),
        T::UInt8 => (0, u8::MAX.into()),
        T::Int16 => (i16::MIN.into(), i16::MAX.into()),
        T::UInt16 => (0, u16::MAX.into()),
        T::Int32 => (i32::MIN.into(), i32::MAX.into()),
        T::UInt32 => (0, u32::MAX.into()),
        // beyond 2^53 the value is not held exactly as the f64 it arrives as
        T::Int64 | T::UInt64 => (if v.value_type == T::UInt64 { 0 } else { -(1 << 53) }, 1 << 53),
        T::Float32 | T::Float64 => {
            let below = matches!(v.min, Some(fmi3::Bound::Float(m)) if value < m);
            let above = matches!(v.max, Some(fmi3::Bound::Float(m)) if value > m);
            if below || above || !value.is_finite() {
                return Err(bad(format!("outside its range [{:?}, {:?}]", v.min, v.max)));
            }
            return Ok(fmi3::Values::Float(vec![value]));
        }
        other => return Err(bad(format!("a {other:?} structural parameter is not set by cosim"))),
    };
    let whole = value as i128;
    if whole as f64 != value || whole < lowest || whole > highest {
        return Err(bad(format!("not a whole number of {:?} (from {lowest} to {highest})", v.value_type)));
    }
    let min = match v.min {
        Some(fmi3::Bound::Int(m)) => m.max(lowest),
        _ => lowest,
    };
    let max = match v.max {
        Some(fmi3::Bound::Int(m)) => m.min(highest),
        _ => highest,
    };
    if whole < min || whole > max {
        return Err(bad(format!("outside its range [{min}, {max}]")));
    }
    Ok(fmi3::Values::Int(vec![whole]))
}

impl Fmu {
    /// This FMI 3.0 FMU with the structural parameters `values` (name, value) set for the
    /// instance `instance` (named in errors): its view is that of the new values (an array
    /// a parameter sizes has the new number of elements, named and reached as any array),
    /// and its instances enter Configuration Mode before initialization to set them
    /// (`fmi3EnterConfigurationMode`, the setters, `fmi3ExitConfigurationMode`). Values set
    /// on an FMU configured before add to (or replace) its earlier ones.
    pub fn configured(self: &Arc<Fmu>, instance: &str, values: &[(&str, f64)]) -> Result<Arc<Fmu>> {
        let a = self.fmi3_for_structural(instance, values)?;
        let mut md = a.description.clone();
        let mut configuration = a.configuration.clone();
        // a value set now is the start and the view's size (sized_for after it, if at all)
        let mut initial_sizes = a.initial_sizes.clone();
        for (name, value) in values {
            let v = md
                .model_variables
                .iter_mut()
                .find(|v| v.name == *name && v.causality == fmi3::Causality::StructuralParameter)
                .ok_or_else(|| Error::InvalidValue {
                    variable: format!("{instance}.{name}"),
                    value: value.to_string(),
                    reason: "not a structural parameter of the FMU".into(),
                })?;
            if !matches!(v.variability, fmi3::Variability::Fixed | fmi3::Variability::Tunable) {
                return Err(Error::InvalidValue {
                    variable: format!("{instance}.{name}"),
                    value: value.to_string(),
                    reason: format!("a {} structural parameter cannot be set", v.variability.as_str()),
                });
            }
            v.start = Some(checked_value(instance, v, *value)?);
            let access = Access { vr: v.value_reference, value_type: v.value_type, element: 0, count: 1 };
            configuration.retain(|(set, _)| set.vr != access.vr);
            configuration.push((access, *value));
            initial_sizes.retain(|(vr, _)| *vr != access.vr);
        }
        Ok(self.rebuilt(a, md, configuration, initial_sizes))
    }

    /// This FMU with the view and the settings given, the rest as it is.
    fn rebuilt(
        self: &Arc<Fmu>,
        a: &crate::fmi3::Fmi3Abi,
        md: fmi3::ModelDescription,
        configuration: Vec<(Access, f64)>,
        initial_sizes: Vec<(u32, f64)>,
    ) -> Arc<Fmu> {
        let (view, special, not_in_view) = crate::fmi3::fmi2_view(&md);
        let abi = crate::fmi3::Fmi3Abi {
            functions: a.functions,
            description: md,
            special,
            token: a.token.clone(),
            resource_path: a.resource_path.clone(),
            configuration,
            initial_sizes,
        };
        let root = self.configured_from.clone().unwrap_or_else(|| self.clone());
        Arc::new(Fmu {
            abi: Abi::Fmi3(Arc::new(abi)),
            allow_non_finite: self.allow_non_finite,
            _library: self._library.clone(),
            description: view,
            interface: self.interface,
            source: self.source.clone(),
            origin: self.origin.clone(),
            resource_uri: self.resource_uri.clone(),
            dir: None,
            isolated_from: None,
            library_path: self.library_path.clone(),
            not_in_view,
            configured_from: Some(root),
            event_mode: self.event_mode.clone(),
        })
    }

    /// This FMI 3.0 FMU with its view sized for the values `sizes` (name, value) of tunable
    /// structural parameters that a run sets later in Reconfiguration Mode
    /// ([`crate::Instance::reconfigure`]): the arrays they size have the elements of the
    /// larger of each value and the one the instances start with (their configured value,
    /// else the description's start), so that the results have a column for every element
    /// the run can have. The instances start with their own values (those elements they lack
    /// read as NaN).
    pub fn sized_for(self: &Arc<Fmu>, instance: &str, sizes: &[(&str, f64)]) -> Result<Arc<Fmu>> {
        let a = self.fmi3_for_structural(instance, sizes)?;
        let mut md = a.description.clone();
        let mut initial = a.initial_sizes.clone();
        for (name, value) in sizes {
            let bad = |reason: String| Error::InvalidValue {
                variable: format!("{instance}.{name}"),
                value: value.to_string(),
                reason,
            };
            let v = md
                .model_variables
                .iter_mut()
                .find(|v| v.name == *name && v.causality == fmi3::Causality::StructuralParameter)
                .ok_or_else(|| bad("not a structural parameter of the FMU".into()))?;
            if v.variability != fmi3::Variability::Tunable {
                return Err(bad(format!(
                    "a {} structural parameter is set before initialization only (Reconfiguration Mode changes \
                     tunable ones)",
                    v.variability.as_str()
                )));
            }
            let checked = checked_value(instance, v, *value)?;
            let now = match &v.start {
                Some(fmi3::Values::Int(x)) if x.len() == 1 => x[0] as f64,
                Some(fmi3::Values::Float(x)) if x.len() == 1 => x[0],
                _ => return Err(bad("its start value is not a scalar number".into())),
            };
            let vr = v.value_reference;
            let start = initial.iter().find(|(p, _)| *p == vr).map_or(now, |(_, x)| *x);
            if *value > now {
                v.start = Some(checked);
            }
            initial.retain(|(p, _)| *p != vr);
            let view = match &v.start {
                Some(fmi3::Values::Int(x)) => x[0] as f64,
                Some(fmi3::Values::Float(x)) => x[0],
                _ => now,
            };
            if start != view {
                initial.push((vr, start));
            }
        }
        Ok(self.rebuilt(a, md, a.configuration.clone(), initial))
    }

    /// The FMI 3.0 functions of this FMU, for setting the structural parameters `values` of
    /// `instance`; an FMI 2.0 FMU has none (the error names the first value's variable).
    fn fmi3_for_structural(&self, instance: &str, values: &[(&str, f64)]) -> Result<&crate::fmi3::Fmi3Abi> {
        match &self.abi {
            Abi::Fmi3(a) => Ok(a),
            Abi::Fmi2(_) => Err(Error::InvalidValue {
                variable: format!("{instance}.{}", values.first().map_or("", |(n, _)| *n)),
                value: String::new(),
                reason: "structural parameters are FMI 3.0's; this FMU is an FMI 2.0 one".into(),
            }),
        }
    }

    /// The structural parameters this FMU was [configured](Fmu::configured) with (name,
    /// value), in the order they were set.
    pub fn configuration(&self) -> Vec<(String, f64)> {
        let Abi::Fmi3(a) = &self.abi else { return Vec::new() };
        a.configuration
            .iter()
            .filter_map(|(access, x)| a.description.variable(access.vr).map(|v| (v.name.clone(), *x)))
            .collect()
    }
}

/// The arrays of `md` (the view's description) whose size differs when the structural
/// parameters `now` (value reference, value) have those values: by the FMU's value
/// reference, the view's dimensions and those of now.
pub(crate) fn resized_arrays(md: &fmi3::ModelDescription, now: &[(u32, f64)]) -> HashMap<u32, (Vec<u64>, Vec<u64>)> {
    let mut out = HashMap::new();
    if now.is_empty() {
        return out;
    }
    let mut current = md.clone();
    for v in current.model_variables.iter_mut() {
        if let Some((_, x)) = now.iter().find(|(vr, _)| *vr == v.value_reference) {
            v.start = Some(match v.value_type {
                fmi3::ValueType::Float32 | fmi3::ValueType::Float64 => fmi3::Values::Float(vec![*x]),
                _ => fmi3::Values::Int(vec![*x as i128]),
            });
        }
    }
    for v in md.model_variables.iter().filter(|v| v.is_array()) {
        let (Some(view), Some(dims)) = (crate::fmi3::sizes(md, v), crate::fmi3::sizes(&current, v)) else { continue };
        if view != dims {
            out.insert(v.value_reference, (view, dims));
        }
    }
    out
}

/// Element `k` (row-major) of an array of dimensions `view` as an element of the same
/// array with dimensions `now`: the same indices, `None` when `now` has no such element.
pub(crate) fn element_now(view: &[u64], now: &[u64], k: usize) -> Option<usize> {
    let mut rest = k as u64;
    let mut index = vec![0u64; view.len()];
    for (i, n) in view.iter().enumerate().rev() {
        index[i] = rest % n;
        rest /= n;
    }
    let mut flat = 0u64;
    for (i, n) in index.iter().zip(now) {
        if i >= n {
            return None;
        }
        flat = flat * n + i;
    }
    Some(flat as usize)
}

#[cfg(test)]
mod tests {
    use super::element_now;

    /// A 4 x 3 view of an array that has 2 x 3 now: row-major, element [i, j] is i 3 + j in
    /// both (rows 2 and 3 are not there); a 1-D view of 3 that has 1: only element 0.
    #[test]
    fn elements_keep_their_indices_when_an_array_is_smaller() {
        assert_eq!(element_now(&[4, 3], &[2, 3], 5), Some(5));
        assert_eq!(element_now(&[4, 3], &[2, 3], 6), None);
        // the trailing dimension smaller: [1, 1] is 4 in the view, 3 in a 4 x 2
        assert_eq!(element_now(&[4, 3], &[4, 2], 4), Some(3));
        assert_eq!(element_now(&[4, 3], &[4, 2], 2), None);
        assert_eq!(element_now(&[3], &[1], 0), Some(0));
        assert_eq!(element_now(&[3], &[1], 1), None);
    }
}
