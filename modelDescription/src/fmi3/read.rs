//! The FMI 3.0 reader: `modelDescription.xml` text to [`ModelDescription`].
//!
//! The same element tree as the FMI 2.0 reader (depth-limited, linear-time attribute
//! checks, positions in every error), the same [`ReadError`]. Tolerant of attribute order,
//! whitespace, comments, unknown attributes, `<Annotations>`, `<Alias>` and unknown
//! top-level elements. Strict where the schema is closed: an element in
//! `<ModelVariables>`, `<TypeDefinitions>` or `<ModelStructure>` that is not one of the
//! standard's is refused with [`ReadError::UnknownElement`] naming it, as are numbers
//! outside their type's range. Attributes are read as written: a `declaredType`'s unit,
//! bounds and nominal are not copied onto the variable (see [`ModelDescription::unit_of`]).
//! Never panics.

use crate::read::{
    children_once, read_default_experiment, read_log_categories, read_root, read_units, with_document_attributes, Ctx,
    Node, ReadError, DOCUMENT_ELEMENTS,
};
use crate::{Initial, Variability};

use super::*;

/// Whether `v` matches the schema's `fmiVersion` pattern `3[.](0|[1-9][0-9]*)([.](0|[1-9][0-9]*))?(-.+)?`.
fn is_fmi3_version(v: &str) -> bool {
    let (numbers, _suffix) = match v.split_once('-') {
        Some((n, s)) if !s.is_empty() => (n, Some(s)),
        Some(_) => return false,
        None => (v, None),
    };
    let parts: Vec<&str> = numbers.split('.').collect();
    let canonical =
        |p: &str| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()) && (p == "0" || !p.starts_with('0'));
    parts.first() == Some(&"3") && (parts.len() == 2 || parts.len() == 3) && parts[1..].iter().all(|p| canonical(p))
}

/// The `fmiVersion` attribute of the root element of `xml`, without reading the rest
/// (`None` if the document has no `<fmiModelDescription>` root or no such attribute). Lets
/// an importer pick the reader for the generation.
pub fn fmi_version_of(xml: &str) -> Option<String> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(xml);
    loop {
        match reader.read_event().ok()? {
            Event::Start(e) | Event::Empty(e) => {
                if e.name().as_ref() != b"fmiModelDescription" {
                    return None;
                }
                // without quick-xml's duplicate check, quadratic in the attributes (the reader
                // proper checks them in linear time)
                for a in e.attributes().with_checks(false).flatten() {
                    if a.key.as_ref() == b"fmiVersion" {
                        return a.unescape_value().ok().map(|v| v.trim().to_string());
                    }
                }
                return None;
            }
            Event::Eof => return None,
            _ => {}
        }
    }
}

impl Ctx<'_> {
    fn u64_of(&self, n: &Node, label: &str, key: &str) -> Result<Option<u64>, ReadError> {
        n.get(key).map(|v| v.trim().parse::<u64>().map_err(|_| self.bad_number(n, label, key, v))).transpose()
    }

    /// An integer of `value_type`'s range.
    fn int_of(&self, n: &Node, label: &str, key: &str, text: &str, value_type: ValueType) -> Result<i128, ReadError> {
        let (lo, hi) = value_type.integer_range().unwrap_or((i64::MIN as i128, i64::MAX as i128));
        match text.trim().parse::<i128>() {
            Ok(x) if (lo..=hi).contains(&x) => Ok(x),
            _ => Err(self.bad_number(n, label, key, text)),
        }
    }

    /// A float; for Float32, one representable as f32 (rounded to it, as the FMU will).
    fn float_of(&self, n: &Node, label: &str, key: &str, text: &str, value_type: ValueType) -> Result<f64, ReadError> {
        let x = self.f64_of(n, label, key, text)?;
        if value_type == ValueType::Float32 {
            let t = text.trim();
            let single = match t {
                "INF" | "+INF" | "-INF" | "NaN" => x as f32,
                _ => t.parse::<f32>().map_err(|_| self.bad_number(n, label, key, text))?,
            };
            if single.is_infinite() && x.is_finite() {
                return Err(self.bad_number(n, label, key, text));
            }
            return Ok(single as f64);
        }
        Ok(x)
    }

    fn bound(&self, n: &Node, label: &str, key: &str, value_type: ValueType) -> Result<Option<Bound>, ReadError> {
        let Some(text) = n.get(key) else { return Ok(None) };
        Ok(Some(if value_type.is_float() {
            Bound::Float(self.float_of(n, label, key, text, value_type)?)
        } else {
            Bound::Int(self.int_of(n, label, key, text, value_type)?)
        }))
    }
}

fn hex_bytes(s: &str) -> Option<Vec<u8>> {
    let s = s.trim();
    if s.len() % 2 != 0 {
        return None;
    }
    (0..s.len()).step_by(2).map(|i| s.get(i..i + 2).and_then(|pair| u8::from_str_radix(pair, 16).ok())).collect()
}

/// The start values of a variable: the `start` attribute (a whitespace-separated list for
/// arrays) or, for String and Binary, the `<Start value="..">` children.
fn read_start(ctx: &Ctx, t: &Node, label: &str, value_type: ValueType) -> Result<Option<Values>, ReadError> {
    if matches!(value_type, ValueType::String | ValueType::Binary) {
        let starts: Vec<&Node> = t.children.iter().filter(|c| c.name == "Start").collect();
        if starts.is_empty() {
            return Ok(None);
        }
        let sl = format!("Start of {label}");
        let texts = starts.iter().map(|s| ctx.req(s, &sl, "value").map(|v| (*s, v))).collect::<Result<Vec<_>, _>>()?;
        return Ok(Some(if value_type == ValueType::String {
            Values::String(texts.into_iter().map(|(_, v)| v.to_string()).collect())
        } else {
            Values::Binary(
                texts
                    .into_iter()
                    .map(|(s, v)| hex_bytes(v).ok_or_else(|| ctx.bad_number(s, &sl, "value", v)))
                    .collect::<Result<Vec<_>, _>>()?,
            )
        }));
    }
    let Some(text) = t.get("start") else { return Ok(None) };
    let tokens = text.split_ascii_whitespace();
    Ok(Some(match value_type {
        ValueType::Float32 | ValueType::Float64 => {
            Values::Float(tokens.map(|tok| ctx.float_of(t, label, "start", tok, value_type)).collect::<Result<_, _>>()?)
        }
        ValueType::Boolean => Values::Boolean(
            tokens
                .map(|tok| match tok {
                    "true" | "1" => Ok(true),
                    "false" | "0" => Ok(false),
                    _ => Err(ctx.bad_enum(t, label, "start", tok)),
                })
                .collect::<Result<_, _>>()?,
        ),
        ValueType::Clock => return Ok(None),
        _ => Values::Int(tokens.map(|tok| ctx.int_of(t, label, "start", tok, value_type)).collect::<Result<_, _>>()?),
    }))
}

fn read_dimension(ctx: &Ctx, d: &Node, label: &str) -> Result<Dimension, ReadError> {
    let dl = format!("Dimension of {label}");
    match (ctx.u64_of(d, &dl, "start")?, ctx.opt_u32(d, &dl, "valueReference")?) {
        (Some(n), None) => Ok(Dimension::Fixed(n)),
        (None, Some(vr)) => Ok(Dimension::Variable(vr)),
        (Some(_), Some(_)) => Err(ReadError::Invalid {
            element: dl,
            message: "has both start and valueReference (exactly one is allowed)".into(),
            position: ctx.pos(d),
        }),
        (None, None) => Err(ReadError::Invalid {
            element: dl,
            message: "has neither start nor valueReference".into(),
            position: ctx.pos(d),
        }),
    }
}

fn read_variable(ctx: &Ctx, t: &Node, value_type: ValueType) -> Result<Variable, ReadError> {
    let name = ctx.req(t, t.name.as_str(), "name")?.to_string();
    let l = format!("{} \"{name}\"", t.name);
    let value_reference = ctx.req_u32(t, &l, "valueReference")?;
    let causality = ctx.opt_enum(t, &l, "causality", Causality::parse)?.unwrap_or(Causality::Local);
    let default_variability = if value_type.is_float() { Variability::Continuous } else { Variability::Discrete };
    let variability = ctx.opt_enum(t, &l, "variability", Variability::parse)?.unwrap_or(default_variability);
    let float = value_type.is_float();
    let mut v = Variable::new(name, value_reference, value_type, causality, variability);
    v.description = Ctx::opt_string(t, "description");
    v.initial = ctx.opt_enum(t, &l, "initial", Initial::parse)?;
    v.can_handle_multiple_set_per_time_instant = ctx.opt_bool(t, &l, "canHandleMultipleSetPerTimeInstant")?;
    v.intermediate_update = ctx.flag(t, &l, "intermediateUpdate")?;
    v.previous = ctx.opt_u32(t, &l, "previous")?;
    v.clocks = ctx.u32_list(t, &l, "clocks")?.unwrap_or_default();
    v.declared_type = Ctx::opt_string(t, "declaredType");
    if value_type == ValueType::Enumeration && v.declared_type.is_none() {
        return Err(ReadError::MissingAttribute { element: l, attribute: "declaredType".into(), position: ctx.pos(t) });
    }
    v.quantity = Ctx::opt_string(t, "quantity");
    if float {
        v.unit = Ctx::opt_string(t, "unit");
        v.display_unit = Ctx::opt_string(t, "displayUnit");
        v.relative_quantity = ctx.flag(t, &l, "relativeQuantity")?;
        v.unbounded = ctx.flag(t, &l, "unbounded")?;
        v.nominal = ctx.opt_f64(t, &l, "nominal")?;
        v.derivative = ctx.opt_u32(t, &l, "derivative")?;
        v.reinit = ctx.flag(t, &l, "reinit")?;
    }
    if float || value_type.is_integer() {
        v.min = ctx.bound(t, &l, "min", value_type)?;
        v.max = ctx.bound(t, &l, "max", value_type)?;
    }
    if value_type == ValueType::Binary {
        v.mime_type = Ctx::opt_string(t, "mimeType");
        v.max_size = ctx.u64_of(t, &l, "maxSize")?;
    }
    if value_type == ValueType::Clock {
        v.clock = Some(ClockAttributes {
            can_be_deactivated: ctx.flag(t, &l, "canBeDeactivated")?,
            priority: ctx.opt_u32(t, &l, "priority")?,
            interval_variability: Ctx::opt_string(t, "intervalVariability"),
            interval_decimal: ctx.opt_f64(t, &l, "intervalDecimal")?,
            shift_decimal: ctx.opt_f64(t, &l, "shiftDecimal")?,
            supports_fraction: ctx.flag(t, &l, "supportsFraction")?,
            resolution: ctx.u64_of(t, &l, "resolution")?,
            interval_counter: ctx.u64_of(t, &l, "intervalCounter")?,
            shift_counter: ctx.u64_of(t, &l, "shiftCounter")?,
        });
    }
    v.start = read_start(ctx, t, &l, value_type)?;
    v.dimensions = t
        .children
        .iter()
        .filter(|c| c.name == "Dimension")
        .map(|d| read_dimension(ctx, d, &l))
        .collect::<Result<_, _>>()?;
    v.aliases = t
        .children
        .iter()
        .filter(|c| c.name == "Alias")
        .map(|a| {
            let name = ctx.req(a, &format!("Alias of {l}"), "name")?.to_string();
            let display_unit = if float { Ctx::opt_string(a, "displayUnit") } else { None };
            Ok(Alias { name, description: Ctx::opt_string(a, "description"), display_unit })
        })
        .collect::<Result<_, ReadError>>()?;
    Ok(v)
}

fn read_type_definition(ctx: &Ctx, t: &Node) -> Result<TypeDefinition, ReadError> {
    let element = t.name.as_str();
    let Some(value_type) = element.strip_suffix("Type").and_then(ValueType::parse) else {
        return Err(ReadError::UnknownElement {
            element: element.to_string(),
            parent: "TypeDefinitions".into(),
            position: ctx.pos(t),
        });
    };
    let name = ctx.req(t, element, "name")?.to_string();
    let l = format!("{element} \"{name}\"");
    let quantity = Ctx::opt_string(t, "quantity");
    let kind = if value_type.is_float() {
        TypeKind::Float {
            value_type,
            quantity,
            unit: Ctx::opt_string(t, "unit"),
            display_unit: Ctx::opt_string(t, "displayUnit"),
            min: t.get("min").map(|s| ctx.float_of(t, &l, "min", s, value_type)).transpose()?,
            max: t.get("max").map(|s| ctx.float_of(t, &l, "max", s, value_type)).transpose()?,
            nominal: ctx.opt_f64(t, &l, "nominal")?,
        }
    } else if value_type == ValueType::Enumeration {
        let il = format!("Item of {l}");
        let items = t
            .children
            .iter()
            .filter(|c| c.name == "Item")
            .map(|item| -> Result<EnumerationItem, ReadError> {
                let text = ctx.req(item, &il, "value")?;
                Ok(EnumerationItem {
                    name: ctx.req(item, &il, "name")?.to_string(),
                    value: text.trim().parse::<i64>().map_err(|_| ctx.bad_number(item, &il, "value", text))?,
                    description: Ctx::opt_string(item, "description"),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        TypeKind::Enumeration { quantity, items }
    } else if value_type.is_integer() {
        TypeKind::Integer {
            value_type,
            quantity,
            min: t.get("min").map(|s| ctx.int_of(t, &l, "min", s, value_type)).transpose()?,
            max: t.get("max").map(|s| ctx.int_of(t, &l, "max", s, value_type)).transpose()?,
        }
    } else {
        TypeKind::Other { value_type }
    };
    Ok(TypeDefinition { name, description: Ctx::opt_string(t, "description"), kind })
}

fn read_unknown(ctx: &Ctx, u: &Node) -> Result<Unknown, ReadError> {
    let l = u.name.as_str();
    let value_reference = ctx.req_u32(u, l, "valueReference")?;
    let dependencies = ctx.u32_list(u, l, "dependencies")?;
    let dependencies_kind = ctx.dependency_kinds(u, l)?;
    Ok(Unknown { value_reference, dependencies, dependencies_kind })
}

fn read_common(ctx: &Ctx, n: &Node) -> Result<InterfaceCommon, ReadError> {
    let l = n.name.as_str();
    Ok(InterfaceCommon {
        model_identifier: ctx.req(n, l, "modelIdentifier")?.to_string(),
        needs_execution_tool: ctx.flag(n, l, "needsExecutionTool")?,
        can_be_instantiated_only_once_per_process: ctx.flag(n, l, "canBeInstantiatedOnlyOncePerProcess")?,
        can_get_and_set_fmu_state: ctx.flag(n, l, "canGetAndSetFMUState")?,
        can_serialize_fmu_state: ctx.flag(n, l, "canSerializeFMUState")?,
        provides_directional_derivatives: ctx.flag(n, l, "providesDirectionalDerivatives")?,
        provides_adjoint_derivatives: ctx.flag(n, l, "providesAdjointDerivatives")?,
        provides_per_element_dependencies: ctx.flag(n, l, "providesPerElementDependencies")?,
    })
}

impl ModelDescription {
    /// Reads an FMI 3.0 `modelDescription.xml`. See [`ReadError`] for what is refused
    /// (an FMI 2.0 document is [`ReadError::UnsupportedFmiVersion`]; pick the reader with
    /// [`fmi_version_of`]).
    pub fn from_xml(xml: &str) -> Result<ModelDescription, ReadError> {
        let (root, ctx, fmi_version) = read_root(xml, "3.0", is_fmi3_version)?;
        let label = "fmiModelDescription";
        let model_name = ctx.req(&root, label, "modelName")?.to_string();
        let instantiation_token = ctx.req(&root, label, "instantiationToken")?.to_string();

        // Annotations and elements of later minor versions are skipped.
        let [me, cs, units, types, logs, exp, vars, ms] = children_once(&ctx, &root, DOCUMENT_ELEMENTS)?;
        let [se] = children_once(&ctx, &root, ["ScheduledExecution"])?;

        let model_exchange = me
            .map(|n| -> Result<ModelExchange, ReadError> {
                let l = "ModelExchange";
                Ok(ModelExchange {
                    common: read_common(&ctx, n)?,
                    needs_completed_integrator_step: ctx.flag(n, l, "needsCompletedIntegratorStep")?,
                    provides_evaluate_discrete_states: ctx.flag(n, l, "providesEvaluateDiscreteStates")?,
                })
            })
            .transpose()?;
        let co_simulation = cs
            .map(|n| -> Result<CoSimulation, ReadError> {
                let l = "CoSimulation";
                Ok(CoSimulation {
                    common: read_common(&ctx, n)?,
                    can_handle_variable_communication_step_size: ctx.flag(
                        n,
                        l,
                        "canHandleVariableCommunicationStepSize",
                    )?,
                    fixed_internal_step_size: ctx.opt_f64(n, l, "fixedInternalStepSize")?,
                    max_output_derivative_order: ctx.opt_u32(n, l, "maxOutputDerivativeOrder")?.unwrap_or(0),
                    recommended_intermediate_input_smoothness: ctx
                        .opt_i32(n, l, "recommendedIntermediateInputSmoothness")?
                        .unwrap_or(0),
                    provides_intermediate_update: ctx.flag(n, l, "providesIntermediateUpdate")?,
                    might_return_early_from_do_step: ctx.flag(n, l, "mightReturnEarlyFromDoStep")?,
                    can_return_early_after_intermediate_update: ctx.flag(
                        n,
                        l,
                        "canReturnEarlyAfterIntermediateUpdate",
                    )?,
                    has_event_mode: ctx.flag(n, l, "hasEventMode")?,
                    provides_evaluate_discrete_states: ctx.flag(n, l, "providesEvaluateDiscreteStates")?,
                })
            })
            .transpose()?;
        let scheduled_execution =
            se.map(|n| read_common(&ctx, n).map(|common| ScheduledExecution { common })).transpose()?;

        let unit_definitions = read_units(&ctx, units)?;
        let type_definitions = match types {
            Some(t) => t
                .children
                .iter()
                .filter(|c| c.name != "Annotations")
                .map(|c| read_type_definition(&ctx, c))
                .collect::<Result<_, _>>()?,
            None => Vec::new(),
        };
        let log_categories = read_log_categories(&ctx, logs)?;
        let default_experiment = read_default_experiment(&ctx, exp)?;

        let mut model_variables = Vec::new();
        for c in vars.map_or(&[][..], |n| &n.children[..]) {
            match ValueType::parse(&c.name) {
                Some(value_type) => model_variables.push(read_variable(&ctx, c, value_type)?),
                None if c.name == "Annotations" => {}
                None => {
                    return Err(ReadError::UnknownElement {
                        element: c.name.clone(),
                        parent: "ModelVariables".into(),
                        position: ctx.pos(c),
                    })
                }
            }
        }

        let mut model_structure = ModelStructure::default();
        for c in ms.map_or(&[][..], |n| &n.children[..]) {
            let list = match c.name.as_str() {
                "Output" => &mut model_structure.outputs,
                "ContinuousStateDerivative" => &mut model_structure.continuous_state_derivatives,
                "ClockedState" => &mut model_structure.clocked_states,
                "InitialUnknown" => &mut model_structure.initial_unknowns,
                "EventIndicator" => &mut model_structure.event_indicators,
                other => {
                    return Err(ReadError::UnknownElement {
                        element: other.to_string(),
                        parent: "ModelStructure".into(),
                        position: ctx.pos(c),
                    })
                }
            };
            list.push(read_unknown(&ctx, c)?);
        }

        Ok(with_document_attributes!(ModelDescription, &root, {
            fmi_version: fmi_version.trim().to_string(),
            model_name,
            instantiation_token,
            model_exchange,
            co_simulation,
            scheduled_execution,
            unit_definitions,
            type_definitions,
            log_categories,
            default_experiment,
            model_variables,
            model_structure,
        }))
    }

    /// The unit of a Float variable: its own `unit`, else its `declaredType`'s.
    pub fn unit_of<'a>(&'a self, v: &'a Variable) -> Option<&'a str> {
        v.unit.as_deref().or_else(|| match &self.type_definition(v.declared_type.as_deref()?)?.kind {
            TypeKind::Float { unit, .. } => unit.as_deref(),
            _ => None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmi_version_pattern() {
        for ok in ["3.0", "3.0.2", "3.1", "3.0-beta.2", "3.10.1"] {
            assert!(is_fmi3_version(ok), "{ok}");
        }
        for bad in ["2.0", "3", "3.", "3.01", "3.0.", "3.0-", "30", " 3.0x", "3.0.1.2", ""] {
            assert!(!is_fmi3_version(bad), "{bad}");
        }
    }

    #[test]
    fn hex() {
        assert_eq!(hex_bytes("00fFa1"), Some(vec![0, 0xff, 0xa1]));
        assert_eq!(hex_bytes(""), Some(vec![]));
        assert_eq!(hex_bytes("abc"), None);
        assert_eq!(hex_bytes("zz"), None);
        assert_eq!(hex_bytes("é1"), None);
    }
}
