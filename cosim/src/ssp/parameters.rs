//! SSP parameter values: the values of a parameter set (`.ssv`, or inline), the entries of
//! a parameter mapping (`.ssm`, or inline) with their transformations, and the units of
//! values (a set's `Units`), converted to the unit of the variable they are applied to.

use super::Element;
use crate::system::{BaseType, System, Value};
use model_description::BaseUnit;
use std::collections::HashMap;

/// A unit in SI terms: exponents of kg, m, s, A, K, mol, cd, rad; SI = factor * v + offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct SiUnit {
    pub dims: [i32; 8],
    pub factor: f64,
    pub offset: f64,
}

impl SiUnit {
    pub fn of_fmu(u: &BaseUnit) -> SiUnit {
        SiUnit { dims: [u.kg, u.m, u.s, u.a, u.k, u.mol, u.cd, u.rad], factor: u.factor, offset: u.offset }
    }
}

/// The `<Unit>`s of a `<Units>` element (of an `.ssv` or `.ssd`), by name.
pub(super) fn units_of(units: Option<&Element>) -> Result<HashMap<String, SiUnit>, String> {
    let mut out = HashMap::new();
    let Some(units) = units else { return Ok(out) };
    for u in units.all("Unit") {
        let name = u.attr("name").unwrap_or("").to_string();
        let b = u.child("BaseUnit");
        let int = |a: &str| -> Result<i32, String> {
            b.and_then(|b| b.attr(a)).map_or(Ok(0), |v| {
                v.trim().parse().map_err(|_| format!("unit {name:?}: BaseUnit {a}={v:?} is not an integer"))
            })
        };
        let real = |a: &str, d: f64| -> Result<f64, String> {
            b.and_then(|b| b.attr(a)).map_or(Ok(d), |v| {
                model_description::parse_xs_double(v)
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("unit {name:?}: BaseUnit {a}={v:?} is not a finite number"))
            })
        };
        let dims = [int("kg")?, int("m")?, int("s")?, int("A")?, int("K")?, int("mol")?, int("cd")?, int("rad")?];
        let factor = real("factor", 1.0)?;
        if factor == 0.0 {
            return Err(format!("unit {name:?}: BaseUnit factor 0"));
        }
        let offset = real("offset", 0.0)?;
        out.insert(name.clone(), SiUnit { dims, factor, offset });
    }
    Ok(out)
}

/// One value of a parameter set: its type element (`Real`, `Integer`, `Boolean`,
/// `String`, `Enumeration`, or an FMI 3.0-style `Float64`, `Int64`, ...), the value as
/// written and, for a Real, its unit (name, and definition when the set defines it).
#[derive(Clone, Debug)]
pub(super) struct ParameterValue {
    pub kind: String,
    pub text: String,
    pub unit: Option<(String, Option<SiUnit>)>,
}

/// The parameters of a `<ParameterSet>`: (name, value), in order.
pub(super) fn parameter_set(set: &Element) -> Result<Vec<(String, ParameterValue)>, String> {
    let units = units_of(set.child("Units"))?;
    let mut out = Vec::new();
    let Some(params) = set.child("Parameters") else { return Ok(out) };
    for p in params.all("Parameter") {
        let name = p.attr("name").unwrap_or("").to_string();
        let v = p
            .children
            .iter()
            .find(|c| !matches!(c.name.as_str(), "Annotations" | "Dimension"))
            .ok_or_else(|| format!("parameter {name:?} has no value"))?;
        if v.name == "Binary" {
            return Err(format!("parameter {name:?}: Binary values are not supported"));
        }
        let text = v.attr("value").ok_or_else(|| format!("parameter {name:?} has no value"))?.to_string();
        let unit = v.attr("unit").map(|u| (u.to_string(), units.get(u).copied()));
        out.push((name, ParameterValue { kind: v.name.clone(), text, unit }));
    }
    Ok(out)
}

/// A transformation of a mapping entry, applied to the value before it is set.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Transformation {
    /// target = factor * source + offset (Reals, after any unit conversion).
    Linear(f64, f64),
    /// source -> target pairs; values not listed pass unchanged.
    Boolean(Vec<(bool, bool)>),
    /// source -> target pairs of integers (and Enumeration values).
    Integer(Vec<(i64, i64)>),
    /// source -> target pairs of enumeration item names.
    Enumeration(Vec<(String, String)>),
}

fn parse_bool(s: &str) -> Option<bool> {
    match s.trim() {
        "true" | "1" => Some(true),
        "false" | "0" => Some(false),
        _ => None,
    }
}

impl Transformation {
    /// Reads the transformation element `t` (`None`: `t` is no transformation).
    pub fn read(t: &Element) -> Option<Result<Transformation, String>> {
        let entries = |f: &dyn Fn(&str, &str) -> Option<()>| -> Result<(), String> {
            for e in t.all("MapEntry") {
                let (s, g) = (e.attr("source").unwrap_or(""), e.attr("target").unwrap_or(""));
                f(s, g).ok_or_else(|| format!("{}: MapEntry source={s:?} target={g:?} is not valid", t.name))?;
            }
            Ok(())
        };
        Some(match t.name.as_str() {
            "LinearTransformation" => {
                let num = |a: &str, d: f64| -> Result<f64, String> {
                    t.attr(a).map_or(Ok(d), |v| {
                        model_description::parse_xs_double(v)
                            .filter(|x| x.is_finite())
                            .ok_or_else(|| format!("LinearTransformation {a}={v:?} is not a finite number"))
                    })
                };
                num("factor", 1.0).and_then(|f| Ok(Transformation::Linear(f, num("offset", 0.0)?)))
            }
            "BooleanMappingTransformation" => {
                let pairs = std::cell::RefCell::new(Vec::new());
                entries(&|s, g| {
                    pairs.borrow_mut().push((parse_bool(s)?, parse_bool(g)?));
                    Some(())
                })
                .map(|()| Transformation::Boolean(pairs.into_inner()))
            }
            "IntegerMappingTransformation" => {
                let pairs = std::cell::RefCell::new(Vec::new());
                entries(&|s, g| {
                    pairs.borrow_mut().push((s.trim().parse().ok()?, g.trim().parse().ok()?));
                    Some(())
                })
                .map(|()| Transformation::Integer(pairs.into_inner()))
            }
            "EnumerationMappingTransformation" => {
                let pairs = std::cell::RefCell::new(Vec::new());
                entries(&|s, g| {
                    pairs.borrow_mut().push((s.to_string(), g.to_string()));
                    Some(())
                })
                .map(|()| Transformation::Enumeration(pairs.into_inner()))
            }
            _ => return None,
        })
    }

    /// The transformed value: a Real `x` (already in the target's unit) or a value as text
    /// (`Err` says why the transformation does not apply to it).
    pub fn apply_real(&self, x: f64) -> Result<f64, String> {
        match self {
            Transformation::Linear(f, o) => Ok(f * x + o),
            other => Err(format!("{} applies to no Real value", other.name())),
        }
    }

    /// The transformed text of a non-Real value.
    pub fn apply_text(&self, text: &str) -> Result<String, String> {
        let t = text.trim();
        match self {
            Transformation::Linear(..) => Err("LinearTransformation applies to Real values only".into()),
            Transformation::Boolean(pairs) => {
                let b = parse_bool(t).ok_or_else(|| format!("{t:?} is not a Boolean"))?;
                Ok(pairs.iter().find(|(s, _)| *s == b).map_or(b, |(_, g)| *g).to_string())
            }
            Transformation::Integer(pairs) => {
                let k: i64 = t.parse().map_err(|_| format!("{t:?} is not an integer"))?;
                Ok(pairs.iter().find(|(s, _)| *s == k).map_or(k, |(_, g)| *g).to_string())
            }
            Transformation::Enumeration(pairs) => {
                Ok(pairs.iter().find(|(s, _)| s == t).map_or(t, |(_, g)| g.as_str()).to_string())
            }
        }
    }

    /// The element's name.
    pub fn name(&self) -> &'static str {
        match self {
            Transformation::Linear(..) => "LinearTransformation",
            Transformation::Boolean(_) => "BooleanMappingTransformation",
            Transformation::Integer(_) => "IntegerMappingTransformation",
            Transformation::Enumeration(_) => "EnumerationMappingTransformation",
        }
    }
}

impl std::fmt::Display for Transformation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Transformation::Linear(k, o) => write!(f, "x {k} + {o}"),
            Transformation::Boolean(p) => {
                let each: Vec<String> = p.iter().map(|(s, g)| format!("{s}->{g}")).collect();
                write!(f, "map {}", each.join(", "))
            }
            Transformation::Integer(p) => {
                let each: Vec<String> = p.iter().map(|(s, g)| format!("{s}->{g}")).collect();
                write!(f, "map {}", each.join(", "))
            }
            Transformation::Enumeration(p) => {
                let each: Vec<String> = p.iter().map(|(s, g)| format!("{s}->{g}")).collect();
                write!(f, "map {}", each.join(", "))
            }
        }
    }
}

/// One entry of a parameter mapping: the source parameter's name, the target's name, and
/// whether unit conversion is suppressed, with an optional transformation.
#[derive(Clone, Debug)]
pub(super) struct MappingEntry {
    pub source: String,
    pub target: String,
    pub suppress_unit_conversion: bool,
    pub transformation: Option<Transformation>,
}

/// The entries of a `<ParameterMapping>` (the `ssm` root element).
pub(super) fn mapping_entries(mapping: &Element) -> Result<Vec<MappingEntry>, String> {
    let mut out = Vec::new();
    for e in mapping.all("MappingEntry") {
        let source = e.attr("source").ok_or("a MappingEntry without source")?.to_string();
        let target = e.attr("target").ok_or("a MappingEntry without target")?.to_string();
        let mut transformation = None;
        for t in &e.children {
            match Transformation::read(t) {
                Some(r) => {
                    transformation = Some(r.map_err(|why| format!("MappingEntry {source:?} -> {target:?}: {why}"))?)
                }
                None if t.name == "Annotations" => {}
                None => return Err(format!("MappingEntry {source:?} -> {target:?}: {} is not supported", t.name)),
            }
        }
        out.push(MappingEntry {
            source,
            target,
            suppress_unit_conversion: e.attr("suppressUnitConversion") == Some("true"),
            transformation,
        });
    }
    Ok(out)
}

/// A value to apply: the value as the set gives it, the mapping's transformation and
/// unit-conversion choice, and where it comes from (for messages and `cosim info`).
#[derive(Clone, Debug)]
pub(super) struct Bound {
    pub value: ParameterValue,
    pub transformation: Option<Transformation>,
    pub suppress_unit_conversion: bool,
    pub origin: String,
}

/// The value `bound` gives the variable `instance.variable` of `system`, after the unit
/// conversion (unless suppressed) and the mapping's transformation, then `then` (a
/// connection's factor and offset, for a value reaching the variable through system
/// connectors); a note where a unit is taken as written.
pub(super) fn value_for(
    system: &System,
    instance: &str,
    variable: &str,
    bound: &Bound,
    then: (f64, f64, bool),
    notes: &mut Vec<String>,
) -> std::result::Result<(Value, String), String> {
    let r = system.resolve_parts(instance, variable).map_err(|e| e.to_string())?;
    let v = system.variable(&r);
    let md = system.description(r.instance);
    let name = format!("{instance}.{variable}");
    let b = &bound.value;
    match r.base_type {
        BaseType::Real => {
            let x = model_description::parse_xs_double(&b.text)
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{name}: value {:?} is not a finite number", b.text))?;
            let mut how = String::new();
            let mut y = x;
            let suppress = bound.suppress_unit_conversion || then.2;
            if let (Some((unit, def)), false) = (&b.unit, suppress) {
                let declared = v.variable_type.unit();
                let target = declared.and_then(|u| md.unit_definitions.iter().find(|d| d.name == u));
                match (declared, def, target.and_then(|t| t.base_unit.as_ref())) {
                    (Some(d), _, _) if d == unit => {}
                    (Some(d), Some(from), Some(to)) => {
                        let to = SiUnit::of_fmu(to);
                        if from.dims != to.dims {
                            return Err(format!("{name}: a value in {unit:?} for a variable in {d:?}: different dimensions"));
                        }
                        y = (from.factor * x + from.offset - to.offset) / to.factor;
                        how = format!(" (from {x} {unit})");
                    }
                    (Some(d), None, _) if unit.trim_start_matches('[').trim_end_matches(']') == d => {
                        notes.push(format!(
                            "{name}: the value's unit {unit:?} is defined in no Units of its file: taken as the variable's unit {d:?}"
                        ));
                    }
                    (Some(d), None, _) => {
                        return Err(format!(
                            "{name}: the value's unit {unit:?} is defined in no Units of its file and is not the variable's unit {d:?}"
                        ))
                    }
                    (Some(d), Some(_), None) => {
                        return Err(format!(
                            "{name}: a value in {unit:?} for a variable in {d:?}, which its FMU defines by no BaseUnit: cannot convert"
                        ))
                    }
                    (None, _, _) => notes.push(format!(
                        "{name}: the value is given in {unit:?}, the variable has no unit: applied as written"
                    )),
                }
            }
            if let Some(t) = &bound.transformation {
                y = t.apply_real(y).map_err(|why| format!("{name}: {why}"))?;
                how.push_str(&format!(" ({t})"));
            }
            if then.0 != 1.0 || then.1 != 0.0 {
                y = then.0 * y + then.1;
                how.push_str(&format!(" (x {} + {})", then.0, then.1));
            }
            Ok((Value::Real(y), how))
        }
        ty => {
            if then.0 != 1.0 || then.1 != 0.0 {
                return Err(format!("{name}: a linear transformation needs a Real variable"));
            }
            let mut text = b.text.clone();
            let mut how = String::new();
            if let Some(t) = &bound.transformation {
                text = t.apply_text(&text).map_err(|why| format!("{name}: {why}"))?;
                how = format!(" ({t})");
            }
            // an enumeration value by its item's name
            if let (BaseType::Integer, model_description::VariableType::Enumeration { declared_type, .. }) =
                (ty, &v.variable_type)
            {
                if text.trim().parse::<i64>().is_err() {
                    let item = md
                        .type_definitions
                        .iter()
                        .find(|t| &t.name == declared_type)
                        .and_then(|t| t.items.iter().find(|i| i.name == text.trim()))
                        .ok_or_else(|| format!("{name}: {text:?} is no item of its enumeration {declared_type}"))?;
                    text = item.value.to_string();
                }
            }
            Value::parse(ty, &text)
                .map(|value| (value, how))
                .map_err(|why| format!("{name}: the {} value {text:?}: {why}", b.kind))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn element(xml: &str) -> Element {
        super::super::parse_xml(xml, std::path::Path::new("t.ssm")).unwrap()
    }

    #[test]
    fn mapping_transformations_map_listed_values_and_pass_the_others() {
        let m = element(
            r#"<ssm:ParameterMapping xmlns:ssm="x" xmlns:ssc="y" version="1.0">
  <ssm:MappingEntry source="b" target="B"><ssc:BooleanMappingTransformation><ssc:MapEntry source="true" target="false"/></ssc:BooleanMappingTransformation></ssm:MappingEntry>
  <ssm:MappingEntry source="i" target="I" suppressUnitConversion="true"><ssc:IntegerMappingTransformation><ssc:MapEntry source="1" target="10"/><ssc:MapEntry source="2" target="-20"/></ssc:IntegerMappingTransformation></ssm:MappingEntry>
  <ssm:MappingEntry source="e" target="E"><ssc:EnumerationMappingTransformation><ssc:MapEntry source="low" target="high"/></ssc:EnumerationMappingTransformation></ssm:MappingEntry>
  <ssm:MappingEntry source="r" target="R"><ssc:LinearTransformation factor="-2"/></ssm:MappingEntry>
</ssm:ParameterMapping>"#,
        );
        let e = mapping_entries(&m).unwrap();
        let t = |k: usize| e[k].transformation.clone().unwrap();
        // listed: true -> false; not listed: false stays false
        assert_eq!(t(0).apply_text("true").unwrap(), "false");
        assert_eq!(t(0).apply_text("0").unwrap(), "false");
        assert!(e[1].suppress_unit_conversion && !e[0].suppress_unit_conversion);
        assert_eq!(t(1).apply_text("2").unwrap(), "-20");
        assert_eq!(t(1).apply_text("3").unwrap(), "3");
        assert_eq!(t(2).apply_text("low").unwrap(), "high");
        assert_eq!(t(2).apply_text("mid").unwrap(), "mid");
        // -2 * 1.5 + 0 (offset defaults to 0)
        assert_eq!(t(3).apply_real(1.5).unwrap(), -3.0);
        assert!(t(3).apply_text("1").is_err() && t(1).apply_real(1.0).is_err());
        let bad = element(
            r#"<ParameterMapping><MappingEntry source="a" target="b"><IntegerMappingTransformation><MapEntry source="x" target="1"/></IntegerMappingTransformation></MappingEntry></ParameterMapping>"#,
        );
        assert!(mapping_entries(&bad).unwrap_err().contains("MapEntry source=\"x\""));
    }

    #[test]
    fn units_of_a_set_are_read_with_their_factor_and_offset() {
        let u = units_of(Some(&element(
            r#"<Units><Unit name="degC"><BaseUnit K="1" offset="273.15"/></Unit><Unit name="km/h"><BaseUnit m="1" s="-1" factor="0.2777777777777778"/></Unit></Units>"#,
        )))
        .unwrap();
        assert_eq!(u["degC"], SiUnit { dims: [0, 0, 0, 0, 1, 0, 0, 0], factor: 1.0, offset: 273.15 });
        assert_eq!(u["km/h"].dims, [0, 1, -1, 0, 0, 0, 0, 0]);
    }
}
