//! Systems of FMU instances: the builder (start values, checked connections) and the
//! resolved [`System`] that the stepping code runs.

use crate::error::{Error, Result};
use crate::fmu::{Fmu, Interface};
use model_description::{BaseUnit, Causality, ModelDescription, ScalarVariable, Variability, VariableType};
use std::collections::HashMap;
use std::sync::Arc;

/// The base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BaseType {
    /// `Real`.
    Real,
    /// `Integer` (and Enumeration).
    Integer,
    /// `Boolean`.
    Boolean,
    /// `String`.
    String,
}

impl BaseType {
    /// Of a variable.
    pub fn of(v: &ScalarVariable) -> BaseType {
        match v.variable_type {
            VariableType::Real { .. } => BaseType::Real,
            VariableType::Integer { .. } | VariableType::Enumeration { .. } => BaseType::Integer,
            VariableType::Boolean { .. } => BaseType::Boolean,
            VariableType::String { .. } => BaseType::String,
        }
    }
    /// The XML name.
    pub fn as_str(self) -> &'static str {
        match self {
            BaseType::Real => "Real",
            BaseType::Integer => "Integer",
            BaseType::Boolean => "Boolean",
            BaseType::String => "String",
        }
    }
}

/// A value to set.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// Real.
    Real(f64),
    /// Integer.
    Integer(i32),
    /// Boolean.
    Boolean(bool),
    /// String.
    String(String),
}

impl Value {
    /// Parses `text` for a variable of type `ty` (`true`/`false`/`1`/`0` for Boolean).
    pub fn parse(ty: BaseType, text: &str) -> std::result::Result<Value, String> {
        let t = text.trim();
        match ty {
            BaseType::Real => t
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .map(Value::Real)
                .ok_or_else(|| "not a finite number".to_string()),
            BaseType::Integer => t
                .parse::<i32>()
                .map(Value::Integer)
                .map_err(|_| "not an Integer (a whole number from -2147483648 to 2147483647)".to_string()),
            BaseType::Boolean => match t {
                "true" | "1" => Ok(Value::Boolean(true)),
                "false" | "0" => Ok(Value::Boolean(false)),
                _ => Err("not a Boolean (true, false, 1, 0)".into()),
            },
            BaseType::String => Ok(Value::String(text.to_string())),
        }
    }
    fn base_type(&self) -> BaseType {
        match self {
            Value::Real(_) => BaseType::Real,
            Value::Integer(_) => BaseType::Integer,
            Value::Boolean(_) => BaseType::Boolean,
            Value::String(_) => BaseType::String,
        }
    }
}

impl std::fmt::Display for Value {
    /// The value as it would be written in `--set` or an `.ssv` file.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Real(x) => write!(f, "{x}"),
            Value::Integer(k) => write!(f, "{k}"),
            Value::Boolean(b) => write!(f, "{b}"),
            Value::String(s) => write!(f, "{s:?}"),
        }
    }
}

/// A variable of an instance, resolved.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct VariableRef {
    /// Index of the instance in the system.
    pub instance: usize,
    /// 0-based index into the instance's ModelVariables.
    pub index: usize,
    /// Value reference.
    pub value_reference: u32,
    /// Base type.
    pub base_type: BaseType,
}

/// A checked connection: `to = gain * from + offset` (unit conversion and linear
/// transformation folded in; gain 1 and offset 0 for non-Real).
#[derive(Clone, Debug, PartialEq)]
pub struct Connection {
    /// Source output.
    pub from: VariableRef,
    /// Destination input.
    pub to: VariableRef,
    /// Factor applied to the source value.
    pub gain: f64,
    /// Offset added after the factor.
    pub offset: f64,
    /// The SSP LinearTransformation as given (factor, offset), before unit conversion.
    pub linear_transformation: Option<(f64, f64)>,
}

/// One instance of a system.
#[derive(Debug, Clone)]
pub struct InstanceSpec {
    /// Name (no `.`).
    pub name: String,
    /// The FMU.
    pub fmu: Arc<Fmu>,
    /// Start values and parameters, set before initialization.
    pub start_values: Vec<(usize, Value)>,
}

/// A system: instances and checked connections. Build it with [`SystemBuilder`].
#[derive(Debug, Clone, Default)]
pub struct System {
    /// Instances, in the order they were added.
    pub instances: Vec<InstanceSpec>,
    /// Connections, in the order they were added.
    pub connections: Vec<Connection>,
    /// Connections from an FMI 3.0 output clock to a triggered input clock.
    pub clock_connections: Vec<ClockConnection>,
}

/// A connection from an output clock to a triggered input clock: every tick of the source
/// ticks the destination (at the next communication point, as `jacobi` carries every
/// connection).
#[derive(Clone, Debug, PartialEq)]
pub struct ClockConnection {
    /// The source: instance index and the output clock's value reference.
    pub from: (usize, u32),
    /// The destination: instance index and the input clock's value reference.
    pub to: (usize, u32),
}

/// Builds a [`System`], checking every name, value and connection as it is added.
#[derive(Debug, Default)]
pub struct SystemBuilder {
    system: System,
    names: HashMap<String, usize>,
    /// (instance, variable index) of the inputs connected so far
    connected: std::collections::HashSet<(usize, usize)>,
}

/// Splits `instance.variable` at the first `.`.
pub fn split_name(full: &str) -> Option<(&str, &str)> {
    full.split_once('.').filter(|(a, b)| !a.is_empty() && !b.is_empty())
}

impl System {
    /// The clock `instance.clock` names, if it names one: (instance index, clock).
    pub fn clock_of(&self, full: &str) -> Option<(usize, crate::clocks::Clock)> {
        full.match_indices('.').find_map(|(dot, _)| {
            let i = self.instance_index(&full[..dot])?;
            let clock = self.instances[i].fmu.clocks().into_iter().find(|c| c.name == full[dot + 1..])?;
            Some((i, clock))
        })
    }

    /// A one-instance system of a single FMU.
    pub fn single(name: &str, fmu: Arc<Fmu>) -> Result<System> {
        let mut b = SystemBuilder::new();
        b.add_instance(name, fmu)?;
        Ok(b.build())
    }

    /// Index of the instance called `name`.
    pub fn instance_index(&self, name: &str) -> Option<usize> {
        self.instances.iter().position(|i| i.name == name)
    }

    /// The model description of instance `i`.
    pub fn description(&self, i: usize) -> &ModelDescription {
        self.instances[i].fmu.description()
    }

    /// Resolves `instance.variable`. Instance names of flattened nested systems contain
    /// `.` themselves, and so may variable names (`body.v_x`): every split of `full` at a
    /// `.` into an instance and one of its variables is a reading; one reading wins, two
    /// are refused as ambiguous, none is an error naming the closest names.
    pub fn resolve(&self, full: &str) -> Result<VariableRef> {
        let mut found: Vec<VariableRef> = Vec::new();
        let mut longest_instance: Option<(usize, usize)> = None;
        for (dot, _) in full.match_indices('.') {
            let Some(i) = self.instance_index(&full[..dot]) else { continue };
            longest_instance = Some((i, dot));
            if let Some(r) = self.variable_of(i, &full[dot + 1..]) {
                found.push(r);
            }
        }
        match (found.len(), longest_instance) {
            (1, _) => Ok(found.remove(0)),
            (0, Some((i, dot))) => Err(self.unknown_variable(i, &full[dot + 1..])),
            (0, None) => Err(self.no_instance(full)),
            _ => Err(Error::Import(crate::ImportError::InvalidValue {
                variable: full.into(),
                value: String::new(),
                reason: format!(
                    "the name is ambiguous: it reads as {}",
                    found
                        .iter()
                        .map(|r| format!(
                            "variable {:?} of instance {:?}",
                            self.variable(r).name,
                            self.instances[r.instance].name
                        ))
                        .collect::<Vec<_>>()
                        .join(" and as ")
                ),
            })),
        }
    }

    fn variable_of(&self, i: usize, variable: &str) -> Option<VariableRef> {
        let md = self.description(i);
        let index = md.model_variables.iter().position(|v| v.name == variable)?;
        let v = &md.model_variables[index];
        Some(VariableRef { instance: i, index, value_reference: v.value_reference, base_type: BaseType::of(v) })
    }

    fn unknown_variable(&self, i: usize, variable: &str) -> Error {
        if let Some((_, reason)) = self.instances[i].fmu.not_in_view().iter().find(|(name, _)| name == variable) {
            return Error::NotInView {
                instance: self.instances[i].name.clone(),
                variable: variable.into(),
                reason: *reason,
            };
        }
        let md = self.description(i);
        let closest = crate::suggest::closest(variable, md.model_variables.iter().map(|v| v.name.as_str()));
        Error::UnknownVariable {
            instance: self.instances[i].name.clone(),
            variable: variable.into(),
            closest: closest.into_iter().map(String::from).collect(),
        }
    }

    fn instance_names(&self) -> Vec<String> {
        self.instances.iter().map(|i| i.name.clone()).collect()
    }

    /// The error for a name whose part before the last `.` (or whole) is no instance.
    fn no_instance(&self, full: &str) -> Error {
        match full.rsplit_once('.') {
            Some((instance, _)) if !instance.is_empty() => {
                Error::UnknownInstance { name: instance.into(), instances: self.instance_names() }
            }
            _ => {
                let candidates = self
                    .instances
                    .iter()
                    .filter(|i| i.fmu.description().variable(full).is_some())
                    .map(|i| format!("{}.{full}", i.name))
                    .collect();
                Error::NoInstance { name: full.into(), instances: self.instance_names(), candidates }
            }
        }
    }

    /// The variables `full` names for recording: the one variable, or, when `full` names an
    /// array of an FMI 3.0 FMU (`instance.a`), its elements in the view's order (`a[1]`,
    /// `a[2]`, ...).
    pub fn resolve_record(&self, full: &str) -> Result<Vec<VariableRef>> {
        let error = match self.resolve(full) {
            Ok(r) => return Ok(vec![r]),
            Err(e) => e,
        };
        for (dot, _) in full.match_indices('.') {
            let Some(i) = self.instance_index(&full[..dot]) else { continue };
            let prefix = format!("{}[", &full[dot + 1..]);
            let elements: Vec<VariableRef> = self
                .description(i)
                .model_variables
                .iter()
                .enumerate()
                .filter(|(_, v)| v.name.starts_with(&prefix) && v.name.ends_with(']'))
                .map(|(index, v)| VariableRef {
                    instance: i,
                    index,
                    value_reference: v.value_reference,
                    base_type: BaseType::of(v),
                })
                .collect();
            if !elements.is_empty() {
                return Ok(elements);
            }
        }
        Err(error)
    }

    /// Resolves an instance name and a variable name.
    pub fn resolve_parts(&self, instance: &str, variable: &str) -> Result<VariableRef> {
        let i = self
            .instance_index(instance)
            .ok_or_else(|| Error::UnknownInstance { name: instance.into(), instances: self.instance_names() })?;
        self.variable_of(i, variable).ok_or_else(|| self.unknown_variable(i, variable))
    }

    /// `instance.variable` of a resolved reference.
    pub fn name_of(&self, r: &VariableRef) -> String {
        format!("{}.{}", self.instances[r.instance].name, self.variable(r).name)
    }

    /// Whether `r` is an FMI 3.0 structural parameter (set in Configuration Mode, and a
    /// tunable one in Reconfiguration Mode).
    pub fn is_structural(&self, r: &VariableRef) -> bool {
        let name = &self.variable(r).name;
        self.instances[r.instance].fmu.fmi3_description().is_some_and(|md| {
            md.model_variables
                .iter()
                .any(|x| &x.name == name && x.causality == model_description::fmi3::Causality::StructuralParameter)
        })
    }

    /// The ScalarVariable of a resolved reference.
    pub fn variable(&self, r: &VariableRef) -> &ScalarVariable {
        &self.description(r.instance).model_variables[r.index]
    }
}

/// The parameter that sets the initial value of the calculated variable `name`: one whose
/// description says "initial value of NAME" (word for word), else one called `NAME_start`,
/// `NAME0`, `NAME_0` or `start_NAME`.
fn start_parameter<'a>(md: &'a ModelDescription, name: &str) -> Option<&'a str> {
    let params = || md.model_variables.iter().filter(|p| p.causality == Causality::Parameter);
    let phrase = format!("initial value of {name}");
    let by_description = params().find(|p| {
        p.description.as_deref().is_some_and(|d| {
            d.match_indices(&phrase).any(|(at, _)| {
                // the name ends there: not "initial value of v_x_dot" for v_x
                !d[at + phrase.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
            })
        })
    });
    let names = [format!("{name}_start"), format!("{name}0"), format!("{name}_0"), format!("start_{name}")];
    by_description.or_else(|| params().find(|p| names.contains(&p.name))).map(|p| p.name.as_str())
}

/// The value `k` a description lists as "k name" ("which steering feedback: 1 open_loop
/// (K = 0), 2 pole_placement (...), 3 robust (...)"), for a name given where an Integer is due.
fn listed_value(description: &str, name: &str) -> Option<i32> {
    let words: Vec<&str> = description
        .split(|c: char| c.is_whitespace() || matches!(c, ',' | ':' | ';'))
        .filter(|w| !w.is_empty())
        .collect();
    words.windows(2).find(|w| w[1] == name).and_then(|w| w[0].parse().ok())
}

fn base_unit<'a>(md: &'a ModelDescription, unit: &str) -> Option<&'a BaseUnit> {
    md.unit_definitions.iter().find(|u| u.name == unit).and_then(|u| u.base_unit.as_ref())
}

/// `(gain, offset)` converting a value in the source unit to the destination unit, or why not.
fn unit_conversion(
    from_md: &ModelDescription,
    from: &ScalarVariable,
    to_md: &ModelDescription,
    to: &ScalarVariable,
) -> std::result::Result<(f64, f64), String> {
    let (Some(fu), Some(tu)) = (from.variable_type.unit(), to.variable_type.unit()) else {
        return Ok((1.0, 0.0)); // a unitless side: nothing to check
    };
    let (fb, tb) = (base_unit(from_md, fu), base_unit(to_md, tu));
    match (fb, tb) {
        (Some(a), Some(b)) => {
            let dims = |u: &BaseUnit| [u.kg, u.m, u.s, u.a, u.k, u.mol, u.cd, u.rad];
            if dims(a) != dims(b) {
                return Err(format!("units {fu:?} and {tu:?} have different dimensions"));
            }
            // SI = a.factor * v + a.offset ; to = (SI - b.offset) / b.factor
            Ok((a.factor / b.factor, (a.offset - b.offset) / b.factor))
        }
        _ if fu == tu => Ok((1.0, 0.0)),
        _ => Err(format!("units {fu:?} and {tu:?} differ and are not both defined by base units")),
    }
}

impl SystemBuilder {
    /// An empty system.
    pub fn new() -> SystemBuilder {
        SystemBuilder::default()
    }

    /// Continues building an existing system (e.g. one read from an SSP).
    pub fn from_system(system: System) -> SystemBuilder {
        let names = system.instances.iter().enumerate().map(|(i, s)| (s.name.clone(), i)).collect();
        let connected = system.connections.iter().map(|c| (c.to.instance, c.to.index)).collect();
        SystemBuilder { system, names, connected }
    }

    /// Adds an instance of `fmu` called `name` (unique, non-empty; `.` only between the
    /// element names of a flattened nested system); returns its index.
    pub fn add_instance(&mut self, name: &str, fmu: Arc<Fmu>) -> Result<usize> {
        if name.is_empty() || name.contains('\0') || name.split('.').any(|p| p.is_empty()) {
            return Err(Error::Import(crate::ImportError::Instance {
                name: name.into(),
                reason: "instance names are non-empty dotted paths without NUL",
            }));
        }
        if self.names.contains_key(name) {
            return Err(Error::Import(crate::ImportError::Instance {
                name: name.into(),
                reason: "instance name used twice",
            }));
        }
        let i = self.system.instances.len();
        self.system.instances.push(InstanceSpec { name: name.into(), fmu, start_values: Vec::new() });
        self.names.insert(name.into(), i);
        Ok(i)
    }

    /// Sets a start value or parameter (`instance.variable`), checked for type and causality.
    pub fn set(&mut self, variable: &str, value: Value) -> Result<&mut Self> {
        let r = self.system.resolve(variable)?;
        let v = self.system.variable(&r);
        let bad = |reason: String| {
            Error::Import(crate::ImportError::InvalidValue {
                variable: variable.into(),
                value: value.to_string(),
                reason,
            })
        };
        let value = match (r.base_type, &value) {
            (BaseType::Real, Value::Integer(i)) => Value::Real(f64::from(*i)),
            (t, v) if t == v.base_type() => v.clone(),
            (t, _) => return Err(bad(format!("the variable is {}", t.as_str()))),
        };
        if let Value::Real(x) = value {
            if !x.is_finite() {
                return Err(bad("not finite".into()));
            }
        }
        let settable = v.variability != Variability::Constant
            && (matches!(v.causality, Causality::Parameter | Causality::Input)
                || v.variable_type.has_start() && v.causality != Causality::CalculatedParameter);
        let structural = self.system.instances[r.instance].fmu.fmi3_description().is_some_and(|md| {
            md.model_variables
                .iter()
                .any(|x| x.name == v.name && x.causality == model_description::fmi3::Causality::StructuralParameter)
        });
        if structural {
            let x = match value {
                Value::Real(x) => x,
                Value::Integer(k) => f64::from(k),
                _ => return Err(bad(format!("the variable is {}", r.base_type.as_str()))),
            };
            let name = v.name.clone();
            return self.configure(r.instance, &name, x).map(|()| self);
        }
        if !settable {
            let what = if v.variability == Variability::Constant {
                format!("a constant cannot be set (causality {})", v.causality.as_str())
            } else if v.causality == Causality::CalculatedParameter {
                "a calculated parameter is computed by the FMU from other parameters and cannot be set".to_string()
            } else {
                format!(
                    "a {} {} variable without a start value is calculated by the FMU and cannot be set",
                    v.variability.as_str(),
                    v.causality.as_str()
                )
            };
            let hint = match start_parameter(self.system.description(r.instance), &v.name) {
                Some(p) => format!("; its initial value is set by the parameter {p:?}"),
                None => String::new(),
            };
            return Err(bad(format!("{what}{hint}")));
        }
        let spec = &mut self.system.instances[r.instance];
        spec.start_values.retain(|(i, _)| *i != r.index);
        spec.start_values.push((r.index, value));
        Ok(self)
    }

    /// Sets the FMI 3.0 structural parameter `name` of instance `i` to `value`: the
    /// instance's FMU becomes [`Fmu::configured`] with it (set in Configuration Mode before
    /// initialization), the arrays it sizes take the new size, and what the system already
    /// refers to in the instance (start values, connections) is found again by name.
    fn configure(&mut self, i: usize, name: &str, value: f64) -> Result<()> {
        let spec = &self.system.instances[i];
        let fmu = spec.fmu.configured(&spec.name, &[(name, value)])?;
        self.replace_fmu(i, fmu, name, value)
    }

    /// Sizes the results for the FMI 3.0 tunable structural parameter `variable`
    /// (`instance.parameter`) taking the value `value` during the run, in Reconfiguration
    /// Mode ([`crate::simulate::Execution::reconfigure`]): the instance's FMU becomes
    /// [`Fmu::sized_for`] it (the arrays it sizes have a column per element they can have;
    /// the instance starts with its own value), what the system refers to in it found again
    /// by name.
    pub fn size_for(&mut self, variable: &str, value: f64) -> Result<&mut Self> {
        let r = self.system.resolve(variable)?;
        let name = self.system.variable(&r).name.clone();
        let spec = &self.system.instances[r.instance];
        let fmu = spec.fmu.sized_for(&spec.name, &[(&name, value)])?;
        self.replace_fmu(r.instance, fmu, &name, value)?;
        Ok(self)
    }

    /// Instance `i` with the FMU `fmu`, a view of the same FMU resized by its structural
    /// parameter `name` (the value `value`, for errors): start values and connections found
    /// again by name.
    fn replace_fmu(&mut self, i: usize, fmu: Arc<Fmu>, name: &str, value: f64) -> Result<()> {
        let spec = &self.system.instances[i];
        let old = spec.fmu.description().clone();
        let new = fmu.description();
        let gone = |index: usize| {
            let variable = &old.model_variables[index].name;
            Error::Import(crate::ImportError::InvalidValue {
                variable: format!("{}.{name}", spec.name),
                value: value.to_string(),
                reason: format!("{variable} is set or connected, and the arrays {name} sizes no longer have it"),
            })
        };
        let moved = |index: usize| new.model_variables.iter().position(|v| v.name == old.model_variables[index].name);
        let mut start_values = spec.start_values.clone();
        for (index, _) in &mut start_values {
            *index = moved(*index).ok_or_else(|| gone(*index))?;
        }
        let mut connections = self.system.connections.clone();
        for end in connections.iter_mut().flat_map(|c| [&mut c.from, &mut c.to]).filter(|e| e.instance == i) {
            end.index = moved(end.index).ok_or_else(|| gone(end.index))?;
            end.value_reference = new.model_variables[end.index].value_reference;
        }
        self.connected = connections.iter().map(|c| (c.to.instance, c.to.index)).collect();
        self.system.connections = connections;
        let spec = &mut self.system.instances[i];
        spec.start_values = start_values;
        spec.fmu = fmu;
        Ok(())
    }

    /// Sets a value given as text, parsed for the variable's type. An array of an FMI 3.0
    /// FMU (its elements `name[1]`, `name[2]`, ... in the view) takes all its elements at
    /// once as `[v1, v2, ...]` (row-major; commas, semicolons or spaces between them).
    pub fn set_text(&mut self, variable: &str, text: &str) -> Result<&mut Self> {
        let t = text.trim();
        if let (Some(inner), Some(elements)) =
            (t.strip_prefix('[').and_then(|t| t.strip_suffix(']')), self.array_elements(variable))
        {
            let items: Vec<&str> =
                inner.split(|c: char| c == ',' || c == ';' || c.is_whitespace()).filter(|s| !s.is_empty()).collect();
            if items.len() != elements.len() {
                return Err(Error::Import(crate::ImportError::InvalidValue {
                    variable: variable.into(),
                    value: text.into(),
                    reason: format!("{} values for the {} elements of the array", items.len(), elements.len()),
                }));
            }
            for (element, item) in elements.iter().zip(items) {
                self.set_text(element, item)?;
            }
            return Ok(self);
        }
        let r = self.system.resolve(variable)?;
        let value = Value::parse(r.base_type, text).map_err(|reason| {
            Error::Import(crate::ImportError::InvalidValue {
                variable: variable.into(),
                value: text.into(),
                reason: match (r.base_type, self.system.variable(&r).description.as_deref()) {
                    // a switch whose values are listed in its description ("1 open_loop (...), 2 ...")
                    (BaseType::Integer, Some(d)) => match listed_value(d, text.trim()) {
                        Some(k) => format!("{reason}; {text:?} is value {k} of this Integer: set {variable}={k}"),
                        None => format!("{reason} (its description: {d})"),
                    },
                    _ => reason,
                },
            })
        })?;
        self.set(variable, value)
    }

    /// The elements `instance.name[...]` of the array `variable` (`instance.name`), in
    /// order; `None` when `variable` is a variable itself or has no elements.
    fn array_elements(&self, variable: &str) -> Option<Vec<String>> {
        if self.system.resolve(variable).is_ok() {
            return None;
        }
        let (instance, name) = split_name(variable)?;
        let md = self.system.description(self.system.instance_index(instance)?);
        let prefix = format!("{name}[");
        let elements: Vec<String> = md
            .model_variables
            .iter()
            .filter(|v| {
                v.name.strip_prefix(&prefix).and_then(|rest| rest.strip_suffix(']')).is_some_and(|i| !i.contains('['))
            })
            .map(|v| format!("{instance}.{}", v.name))
            .collect();
        (!elements.is_empty()).then_some(elements)
    }

    /// Connects output `from` to input `to` (`instance.variable` each).
    pub fn connect(&mut self, from: &str, to: &str) -> Result<&mut Self> {
        self.connect_linear(from, to, None)
    }

    /// Connects with an SSP-style linear transformation `to = factor * from + offset`
    /// (applied after unit conversion, in the destination unit).
    pub fn connect_linear(&mut self, from: &str, to: &str, linear: Option<(f64, f64)>) -> Result<&mut Self> {
        self.connect_with(from, to, linear, true)
    }

    /// Connects without unit conversion (SSP `suppressUnitConversion`), types and
    /// causalities still checked.
    pub fn connect_unconverted(&mut self, from: &str, to: &str, linear: Option<(f64, f64)>) -> Result<&mut Self> {
        self.connect_with(from, to, linear, false)
    }

    fn connect_with(&mut self, from: &str, to: &str, linear: Option<(f64, f64)>, convert: bool) -> Result<&mut Self> {
        let err = |reason: String| Error::Connection { from: from.into(), to: to.into(), reason };
        match (self.system.clock_of(from), self.system.clock_of(to)) {
            (None, None) => {}
            (Some(a), Some(b)) => return self.connect_clocks(a, b, linear).map_err(err),
            (Some(_), None) => return Err(err("the source is a clock: a clock connects to a clock only".into())),
            (None, Some(_)) => return Err(err("the destination is a clock: a clock connects to a clock only".into())),
        }
        let a = self.system.resolve(from).map_err(|e| err(e.to_string()))?;
        let b = self.system.resolve(to).map_err(|e| err(e.to_string()))?;
        let (va, vb) = (self.system.variable(&a), self.system.variable(&b));
        if va.causality != Causality::Output {
            return Err(err(format!("the source is a {} variable, not an output", va.causality.as_str())));
        }
        if vb.causality != Causality::Input {
            return Err(err(format!("the destination is a {} variable, not an input", vb.causality.as_str())));
        }
        // integers of different widths connect (an FMI 3.0 Int64, UInt64 or UInt32 is a
        // Real of the view, the smaller ones Integers): the value is carried as an integer
        // and checked against the input's type at every set (`simulate/integers.rs`)
        let integer = |r: &VariableRef| self.system.instances[r.instance].fmu.integer_type(r.value_reference);
        let integers = integer(&a).zip(integer(&b));
        if a.base_type != b.base_type && integers.is_none() {
            return Err(err(format!("types differ: {} -> {}", a.base_type.as_str(), b.base_type.as_str())));
        }
        if a.base_type == BaseType::String {
            return Err(err("String connections are not supported".into()));
        }
        if a.instance == b.instance {
            // legal in FMI, but a direct self-loop through an FMU is rarely meant; allowed
        }
        if self.connected.contains(&(b.instance, b.index)) {
            return Err(err("the input is already connected".into()));
        }
        let (mut gain, mut offset) = (1.0, 0.0);
        if a.base_type == BaseType::Real && convert {
            (gain, offset) =
                unit_conversion(self.system.description(a.instance), va, self.system.description(b.instance), vb)
                    .map_err(err)?;
        }
        if let Some((f, o)) = linear {
            if (a.base_type != BaseType::Real || a.base_type != b.base_type) && (f != 1.0 || o != 0.0) {
                return Err(err("a linear transformation needs Real variables".into()));
            }
            if !f.is_finite() || !o.is_finite() {
                return Err(err("non-finite linear transformation".into()));
            }
            (gain, offset) = (f * gain, f * offset + o);
        }
        self.connected.insert((b.instance, b.index));
        self.system.connections.push(Connection { from: a, to: b, gain, offset, linear_transformation: linear });
        Ok(self)
    }

    /// A connection between two clocks (see [`ClockConnection`]).
    fn connect_clocks(
        &mut self,
        (ia, a): (usize, crate::clocks::Clock),
        (ib, b): (usize, crate::clocks::Clock),
        linear: Option<(f64, f64)>,
    ) -> std::result::Result<&mut Self, String> {
        use crate::clocks::{ClockCausality, ClockKind};
        if a.causality != ClockCausality::Output {
            return Err(format!("the source is an {} clock, not an output clock", a.causality.as_str()));
        }
        if b.causality != ClockCausality::Input || b.kind != ClockKind::Triggered {
            return Err(format!(
                "the destination is a {} {} clock: only a triggered input clock ticks when another clock does",
                b.kind.as_str(),
                b.causality.as_str()
            ));
        }
        if linear.is_some_and(|l| l != (1.0, 0.0)) {
            return Err("a clock connection takes no linear transformation".into());
        }
        let to = (ib, b.value_reference);
        if self.system.clock_connections.iter().any(|c| c.to == to) {
            return Err("the input clock is already connected".into());
        }
        self.system.clock_connections.push(ClockConnection { from: (ia, a.value_reference), to });
        Ok(self)
    }

    /// The system so far (for inspection while building).
    pub fn system(&self) -> &System {
        &self.system
    }

    /// The finished system.
    pub fn build(self) -> System {
        self.system
    }
}

/// Whether an instance's interface is Co-Simulation.
pub fn is_cs(spec: &InstanceSpec) -> bool {
    spec.fmu.interface() == Interface::CoSimulation
}
