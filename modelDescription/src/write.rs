//! The writer: `modelDescription.xml` text in the element order the XSD fixes.

use std::borrow::Cow;

use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, Event};
use quick_xml::Writer;

use crate::types::*;

/// Formats an `f64` as an `xs:double` that parses back to the identical value:
/// the shortest round-trip representation (plain for moderate magnitudes,
/// exponent form otherwise), `INF`, `-INF` and `NaN` for the non-finite values.
pub fn format_f64(x: f64) -> String {
    if x.is_nan() {
        "NaN".to_string()
    } else if x == f64::INFINITY {
        "INF".to_string()
    } else if x == f64::NEG_INFINITY {
        "-INF".to_string()
    } else {
        let a = x.abs();
        if a == 0.0 || (1e-5..1e16).contains(&a) {
            format!("{x}")
        } else {
            format!("{x:e}")
        }
    }
}

/// Escapes an attribute value: the five XML specials as entities (quick-xml's `escape`),
/// TAB/LF/CR and the other C0 controls as character references, so that no XML parser normalizes them away.
/// (U+0000 cannot be represented in XML at all: it is written as `&#0;`, which readers,
/// ours included, refuse.)
pub(crate) fn escape_attr(s: &str) -> Cow<'_, str> {
    let escaped = quick_xml::escape::escape(s);
    if !escaped.chars().any(|c| (c as u32) < 0x20) {
        return escaped;
    }
    let mut out = String::with_capacity(escaped.len() + 16);
    for c in escaped.chars() {
        if (c as u32) < 0x20 {
            out.push_str(&format!("&#{};", c as u32));
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// An element under construction: name plus attributes in insertion order.
pub(crate) struct Elem {
    pub(crate) start: BytesStart<'static>,
}

impl Elem {
    pub(crate) fn new(name: &'static str) -> Self {
        Elem { start: BytesStart::new(name) }
    }
    pub(crate) fn attr(&mut self, key: &str, value: &str) -> &mut Self {
        let v = escape_attr(value);
        self.start.push_attribute((key.as_bytes(), v.as_bytes()));
        self
    }
    pub(crate) fn opt_str(&mut self, key: &str, value: &Option<String>) -> &mut Self {
        if let Some(v) = value {
            self.attr(key, v);
        }
        self
    }
    pub(crate) fn opt_f64(&mut self, key: &str, value: Option<f64>) -> &mut Self {
        if let Some(v) = value {
            self.attr(key, &format_f64(v));
        }
        self
    }
    pub(crate) fn opt_disp<T: std::fmt::Display>(&mut self, key: &str, value: Option<T>) -> &mut Self {
        if let Some(v) = value {
            self.attr(key, &v.to_string());
        }
        self
    }
    pub(crate) fn flag(&mut self, key: &str, value: bool) -> &mut Self {
        if value {
            self.attr(key, "true");
        }
        self
    }
    /// `dependencies` and `dependenciesKind` of a ModelStructure entry, each when present.
    pub(crate) fn dependencies(
        &mut self,
        dependencies: &Option<Vec<u32>>,
        kinds: &Option<Vec<DependencyKind>>,
    ) -> &mut Self {
        if let Some(d) = dependencies {
            self.attr("dependencies", &join_u32(d));
        }
        if let Some(k) = kinds {
            let s = k.iter().map(|k| k.as_str()).collect::<Vec<_>>().join(" ");
            self.attr("dependenciesKind", &s);
        }
        self
    }
}

pub(crate) struct Out {
    pub(crate) w: Writer<Vec<u8>>,
}

impl Out {
    /// A document: two-space indentation, after the `<?xml version="1.0" encoding="UTF-8"?>`
    /// declaration.
    pub(crate) fn document() -> Out {
        let mut o = Out { w: Writer::new_with_indent(Vec::new(), b' ', 2) };
        o.ev(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)));
        o
    }
    /// The text written, closed by a newline.
    pub(crate) fn finish(self) -> String {
        let mut bytes = self.w.into_inner();
        bytes.push(b'\n');
        // Everything written came from &str and ASCII markup: valid UTF-8.
        String::from_utf8(bytes).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned())
    }
    pub(crate) fn ev(&mut self, e: Event<'_>) {
        // Writing into a Vec<u8> cannot fail.
        let _ = self.w.write_event(e);
    }
    pub(crate) fn empty(&mut self, e: Elem) {
        self.ev(Event::Empty(e.start));
    }
    pub(crate) fn open(&mut self, e: Elem) {
        self.ev(Event::Start(e.start));
    }
    pub(crate) fn close(&mut self, name: &'static str) {
        self.ev(Event::End(BytesEnd::new(name)));
    }
    /// Opens `<name>` (to be closed by the caller) and returns true, or, when it has no
    /// children (`empty`), writes `<name/>` and returns false.
    pub(crate) fn open_unless_empty(&mut self, name: &'static str, empty: bool) -> bool {
        if empty {
            self.empty(Elem::new(name));
        } else {
            self.open(Elem::new(name));
        }
        !empty
    }
}

pub(crate) fn join_u32(v: &[u32]) -> String {
    v.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" ")
}

fn unknown_elem(u: &Unknown) -> Elem {
    let mut e = Elem::new("Unknown");
    e.attr("index", &u.index.to_string()).dependencies(&u.dependencies, &u.dependencies_kind);
    e
}

/// The optional attributes of `<fmiModelDescription>` FMI 2.0 and 3.0 share, in the order
/// of both schemas, from the fields of the same names (a macro: the two generations'
/// descriptions are different types).
macro_rules! document_attributes {
    ($root:expr, $md:expr) => {
        $root
            .opt_str("description", &$md.description)
            .opt_str("author", &$md.author)
            .opt_str("version", &$md.version)
            .opt_str("copyright", &$md.copyright)
            .opt_str("license", &$md.license)
            .opt_str("generationTool", &$md.generation_tool)
            .opt_str("generationDateAndTime", &$md.generation_date_and_time)
            .opt_str("variableNamingConvention", &$md.variable_naming_convention)
    };
}
pub(crate) use document_attributes;

/// The capability flags that end both FMI 2.0 interface elements, `<ModelExchange>` and
/// `<CoSimulation>`, in the schema's order, each when true, from the fields of the same
/// names of `$interface` (a macro: the two elements are different types).
macro_rules! fmi2_capability_flags {
    ($e:expr, $interface:expr) => {
        $e.flag("canBeInstantiatedOnlyOncePerProcess", $interface.can_be_instantiated_only_once_per_process)
            .flag("canNotUseMemoryManagementFunctions", $interface.can_not_use_memory_management_functions)
            .flag("canGetAndSetFMUstate", $interface.can_get_and_set_fmu_state)
            .flag("canSerializeFMUstate", $interface.can_serialize_fmu_state)
            .flag("providesDirectionalDerivative", $interface.provides_directional_derivative)
    };
}

/// `<UnitDefinitions>` (omitted when there are no units): each `<Unit>` with its
/// `<BaseUnit>`, exponents written when non-zero, `factor` when not 1, `offset` when not 0.
pub(crate) fn write_units(o: &mut Out, units: &[Unit]) {
    if units.is_empty() {
        return;
    }
    o.open(Elem::new("UnitDefinitions"));
    for u in units {
        let mut e = Elem::new("Unit");
        e.attr("name", &u.name);
        match &u.base_unit {
            None => o.empty(e),
            Some(b) => {
                o.open(e);
                let mut be = Elem::new("BaseUnit");
                for (k, v) in [
                    ("kg", b.kg),
                    ("m", b.m),
                    ("s", b.s),
                    ("A", b.a),
                    ("K", b.k),
                    ("mol", b.mol),
                    ("cd", b.cd),
                    ("rad", b.rad),
                ] {
                    if v != 0 {
                        be.attr(k, &v.to_string());
                    }
                }
                // `!=` keeps NaN visible (NaN != 1).
                if b.factor != 1.0 {
                    be.attr("factor", &format_f64(b.factor));
                }
                if b.offset != 0.0 {
                    be.attr("offset", &format_f64(b.offset));
                }
                o.empty(be);
                o.close("Unit");
            }
        }
    }
    o.close("UnitDefinitions");
}

/// An `<Item>` of an enumeration type.
pub(crate) fn item_elem(name: &str, value: impl std::fmt::Display, description: &Option<String>) -> Elem {
    let mut e = Elem::new("Item");
    e.attr("name", name).attr("value", &value.to_string()).opt_str("description", description);
    e
}

/// `<LogCategories>` (omitted when there are none) and `<DefaultExperiment>` (when present),
/// which follow each other in both generations' schemas.
pub(crate) fn write_log_categories_and_experiment(
    o: &mut Out,
    log_categories: &[LogCategory],
    default_experiment: Option<&DefaultExperiment>,
) {
    if !log_categories.is_empty() {
        o.open(Elem::new("LogCategories"));
        for c in log_categories {
            let mut e = Elem::new("Category");
            e.attr("name", &c.name).opt_str("description", &c.description);
            o.empty(e);
        }
        o.close("LogCategories");
    }
    if let Some(d) = default_experiment {
        let mut e = Elem::new("DefaultExperiment");
        e.opt_f64("startTime", d.start_time)
            .opt_f64("stopTime", d.stop_time)
            .opt_f64("tolerance", d.tolerance)
            .opt_f64("stepSize", d.step_size);
        o.empty(e);
    }
}

impl ModelDescription {
    /// Writes `modelDescription.xml`: UTF-8, two-space indentation, elements in the
    /// order fixed by `fmi2ModelDescription.xsd`, optional attributes only when set,
    /// boolean capability flags only when true. Equal descriptions give byte-identical
    /// output; reals parse back to the identical `f64` (see [`format_f64`]); strings
    /// round-trip through [`ModelDescription::from_xml`] (except U+0000, which XML
    /// cannot carry).
    pub fn to_xml(&self) -> String {
        let mut o = Out::document();

        let mut root = Elem::new("fmiModelDescription");
        root.attr("fmiVersion", &self.fmi_version).attr("modelName", &self.model_name).attr("guid", &self.guid);
        document_attributes!(root, self).attr("numberOfEventIndicators", &self.number_of_event_indicators.to_string());
        o.open(root);

        if let Some(me) = &self.model_exchange {
            let mut e = Elem::new("ModelExchange");
            e.attr("modelIdentifier", &me.model_identifier)
                .flag("needsExecutionTool", me.needs_execution_tool)
                .flag("completedIntegratorStepNotNeeded", me.completed_integrator_step_not_needed);
            fmi2_capability_flags!(e, me);
            o.empty(e);
        }
        if let Some(cs) = &self.co_simulation {
            let mut e = Elem::new("CoSimulation");
            e.attr("modelIdentifier", &cs.model_identifier)
                .flag("needsExecutionTool", cs.needs_execution_tool)
                .flag("canHandleVariableCommunicationStepSize", cs.can_handle_variable_communication_step_size)
                .flag("canInterpolateInputs", cs.can_interpolate_inputs);
            if cs.max_output_derivative_order != 0 {
                e.attr("maxOutputDerivativeOrder", &cs.max_output_derivative_order.to_string());
            }
            e.flag("canRunAsynchronuously", cs.can_run_asynchronuously);
            fmi2_capability_flags!(e, cs);
            o.empty(e);
        }

        write_units(&mut o, &self.unit_definitions);

        if !self.type_definitions.is_empty() {
            o.open(Elem::new("TypeDefinitions"));
            for t in &self.type_definitions {
                let mut e = Elem::new("SimpleType");
                e.attr("name", &t.name).opt_str("description", &t.description);
                o.open(e);
                o.open(Elem::new("Enumeration"));
                for item in &t.items {
                    o.empty(item_elem(&item.name, item.value, &item.description));
                }
                o.close("Enumeration");
                o.close("SimpleType");
            }
            o.close("TypeDefinitions");
        }

        write_log_categories_and_experiment(&mut o, &self.log_categories, self.default_experiment.as_ref());

        if o.open_unless_empty("ModelVariables", self.model_variables.is_empty()) {
            for v in &self.model_variables {
                let mut e = Elem::new("ScalarVariable");
                e.attr("name", &v.name)
                    .attr("valueReference", &v.value_reference.to_string())
                    .opt_str("description", &v.description)
                    .attr("causality", v.causality.as_str())
                    .attr("variability", v.variability.as_str());
                if let Some(init) = v.initial {
                    e.attr("initial", init.as_str());
                }
                o.open(e);
                let t = match &v.variable_type {
                    VariableType::Real { start, unit, derivative, min, max, nominal } => {
                        let mut t = Elem::new("Real");
                        t.opt_str("unit", unit)
                            .opt_disp("derivative", *derivative)
                            .opt_f64("min", *min)
                            .opt_f64("max", *max)
                            .opt_f64("nominal", *nominal)
                            .opt_f64("start", *start);
                        t
                    }
                    VariableType::Integer { start, min, max } => {
                        let mut t = Elem::new("Integer");
                        t.opt_disp("min", *min).opt_disp("max", *max).opt_disp("start", *start);
                        t
                    }
                    VariableType::Enumeration { declared_type, start, min, max } => {
                        let mut t = Elem::new("Enumeration");
                        t.attr("declaredType", declared_type)
                            .opt_disp("min", *min)
                            .opt_disp("max", *max)
                            .opt_disp("start", *start);
                        t
                    }
                    VariableType::Boolean { start } => {
                        let mut t = Elem::new("Boolean");
                        t.opt_disp("start", *start);
                        t
                    }
                    VariableType::String { start } => {
                        let mut t = Elem::new("String");
                        t.opt_str("start", start);
                        t
                    }
                };
                o.empty(t);
                o.close("ScalarVariable");
            }
            o.close("ModelVariables");
        }

        let ms = &self.model_structure;
        if ms.outputs.is_empty() && ms.derivatives.is_empty() && ms.initial_unknowns.is_empty() {
            o.empty(Elem::new("ModelStructure"));
        } else {
            o.open(Elem::new("ModelStructure"));
            for (name, list) in
                [("Outputs", &ms.outputs), ("Derivatives", &ms.derivatives), ("InitialUnknowns", &ms.initial_unknowns)]
            {
                if list.is_empty() {
                    continue;
                }
                o.open(Elem::new(name));
                for u in list {
                    o.empty(unknown_elem(u));
                }
                o.close(name);
            }
            o.close("ModelStructure");
        }

        o.close("fmiModelDescription");
        o.finish()
    }
}
