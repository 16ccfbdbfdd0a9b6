//! SSP 1.0 import (`.ssp` archives and bare `.ssd` files) into a [`System`]; the values
//! it applies are `ssp/parameters.rs`, the export of a [`System`] as an `.ssp` is
//! `ssp/write.rs`.
//!
//! Supported (docs/ssp.md says it in full): Components of type
//! `application/x-fmu-sharedlibrary`, their Connectors, Connections in the direction
//! their connectors' kinds give (start and end carry none) with `LinearTransformation`
//! and `suppressUnitConversion`, ParameterBindings inline or from `.ssv` files (with
//! `prefix`, units of values converted) through ParameterMappings (`.ssm` or inline,
//! with their transformations), values of system connectors, nested Systems (flattened:
//! instance names are the element paths joined with `.`; connections through system
//! connectors are followed), DefaultExperiment. Refused by name: signal dictionaries,
//! array connectors, mapping transformations on connections, other component types.
//! Geometry, annotations and graphical elements are ignored.

mod parameters;
mod write;
mod xml;
pub use write::{write_ssp, SSP_PARAMETER_SET};

use crate::error::{Error, Result};
use crate::fmu::{Fmu, ImportOptions};
use crate::system::{BaseType, System, SystemBuilder};
use model_description::Causality;
use parameters::{value_for, Bound, ParameterValue, Transformation};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use xml::{parse_xml, Element};

/// An SSP system, imported: the flattened [`System`] and its default experiment. The
/// FMUs of an `.ssp` are read from it in place (each unpacks only what a run uses).
pub struct SspSystem {
    /// The flattened system.
    pub system: System,
    /// `DefaultExperiment` start and stop time, if given.
    pub default_start_stop: (Option<f64>, Option<f64>),
    /// The name of the root system.
    pub root_name: String,
    /// What was read that the standard leaves to the importer or that changes no value
    /// (parameter values matching no variable, units taken as written, an SSD of the 2.0
    /// draft): said, not silent. `cosim run` prints each as a note.
    pub notes: Vec<String>,
    /// Every value the SSD applies, one line each, with where it comes from (a binding,
    /// a parameter mapping and its transformation, a system connector's value, a unit
    /// conversion): what `cosim info` lists.
    pub applied: Vec<String>,
    /// The `.ssp` file (`None` for a bare `.ssd`).
    archive: Option<PathBuf>,
}

impl SspSystem {
    /// Where an FMU of the system is inside the `.ssp` archive (`resources/x.fmu`), for
    /// FMUs read from it (their [`Fmu::source`] is `<ssp>/<entry>`); `None` for a bare
    /// `.ssd`, whose FMU paths are real files.
    pub fn path_in_archive<'a>(&self, fmu_path: &'a Path) -> Option<&'a Path> {
        self.archive.as_ref().and_then(|a| fmu_path.strip_prefix(a).ok())
    }
}

type Zip = zip::ZipArchive<std::io::BufReader<std::fs::File>>;

/// One endpoint in the SSD before flattening: an FMU variable or a system connector.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Node {
    Variable { instance: String, variable: String },
    SystemConnector { system: String, connector: String },
}

/// Which way data flows through one end of a connection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Flow {
    Out,
    In,
}

/// What a parameter value of a binding names, resolved: a variable of an instance or a
/// connector of a system.
#[derive(Clone, Debug)]
enum Target {
    Variable { instance: String, variable: String },
    Connector { system: String, connector: String },
}

struct Flattener<'a> {
    root: &'a Path,
    path: &'a Path,
    /// The `.ssp` and its checked entries (relative path -> entry name); `None` for an `.ssd`.
    archive: Option<(std::cell::RefCell<Zip>, HashMap<PathBuf, String>)>,
    options: &'a ImportOptions,
    fmus: HashMap<PathBuf, Arc<Fmu>>,
    builder: SystemBuilder,
    root_name: String,
    /// (from, to, factor, offset, suppress_unit_conversion), in the direction of the data
    edges: Vec<Edge>,
    /// declared system connectors: (system path, connector name) -> kind
    connectors: HashMap<(String, String), String>,
    /// the elements of every system: system path -> element name -> is a system
    elements: HashMap<String, HashMap<String, bool>>,
    /// values bound to FMU variables, in the order they apply (the last one wins)
    bound: Vec<(String, String, Bound)>,
    /// values bound to system connectors (the last one wins)
    connector_values: HashMap<(String, String), Bound>,
    notes: Vec<String>,
}

const FMU_TYPE: &str = "application/x-fmu-sharedlibrary";

/// Connector types of a Real variable, and of an Integer (or Enumeration) one.
const REAL_TYPES: [&str; 3] = ["Real", "Float64", "Float32"];
const INTEGER_TYPES: [&str; 10] =
    ["Integer", "Enumeration", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64"];

impl Flattener<'_> {
    fn err(&self, reason: String) -> Error {
        Error::Ssp { path: self.path.to_path_buf(), reason }
    }

    /// A system as messages name it: the root by its name, the others by their path.
    fn shown(&self, system: &str) -> String {
        if system.is_empty() {
            format!("root system {:?}", self.root_name)
        } else {
            format!("system {system:?}")
        }
    }

    /// The relative path `source` names inside the package.
    fn resource(&self, source: &str) -> Result<PathBuf> {
        let rel = source.strip_prefix("file:").map(|s| s.trim_start_matches("//")).unwrap_or(source);
        if source.contains("://") && !source.starts_with("file:") {
            return Err(self.err(format!("source {source:?}: only files inside the package are supported")));
        }
        crate::unpack::safe_relative_path(rel).map_err(|why| self.err(format!("source {source:?} refused: {why}")))
    }

    /// Where the file `rel` of the package is, or why there is none (`what` names the
    /// component or binding that refers to it, `source` as written).
    fn locate(&self, rel: &Path, what: &str, source: &str) -> Result<crate::unpack::ArchiveSource> {
        match &self.archive {
            Some((_, entries)) => match entries.get(rel) {
                Some(entry) => {
                    Ok(crate::unpack::ArchiveSource::Nested { outer: self.path.to_path_buf(), entry: entry.clone() })
                }
                None => {
                    let mut held: Vec<&str> = entries.values().map(String::as_str).collect();
                    held.sort_unstable();
                    Err(self.err(format!(
                        "{what}: its source {source:?} is not in the archive{}",
                        crate::suggest::did_you_mean(&rel.to_string_lossy(), held.iter().copied(), "its entries")
                    )))
                }
            },
            None => Ok(crate::unpack::ArchiveSource::File(self.root.join(rel))),
        }
    }

    /// The text of the parameter file `rel` (from the archive or next to the `.ssd`).
    fn read_text(&self, rel: &Path, what: &str, source: &str) -> Result<String> {
        let limit = self.options.limits.max_xml_bytes;
        match self.locate(rel, what, source)? {
            crate::unpack::ArchiveSource::Nested { entry, .. } => {
                let (zip, _) = self.archive.as_ref().expect("located in the archive");
                let mut zip = zip.borrow_mut();
                crate::unpack::read_text_entry(&mut zip, self.path, &entry, limit)?
                    .ok_or_else(|| self.err(format!("{what}: its source {source:?} is not in the archive")))
            }
            crate::unpack::ArchiveSource::File(file) => {
                crate::unpack::read_text_file(&file, source, limit).map_err(|e| match e {
                    crate::ImportError::Io { source: io, .. } => {
                        self.err(format!("{what}: {source:?} ({}): {io}", file.display()))
                    }
                    other => other.into(),
                })
            }
        }
    }

    /// The XML document of the file `source` (a `.ssv` or `.ssm`), its root element checked.
    fn read_document(&self, source: &str, sbase: Option<&str>, what: &str, root: &str) -> Result<Element> {
        if sbase.is_some_and(|b| b != "SSD") {
            return Err(self.err(format!(
                "{what}: sourceBase={:?} is not supported (files of the package, sourceBase=\"SSD\", are)",
                sbase.unwrap_or("")
            )));
        }
        let rel = self.resource(source)?;
        let text = self.read_text(&rel, what, source)?;
        let doc = parse_xml(&text, &self.path.join(&rel))?;
        if doc.name != root {
            return Err(self.err(format!("{what} {source:?} has the root element <{}>, not <{root}>", doc.name)));
        }
        Ok(doc)
    }

    fn system(&mut self, el: &Element, prefix: &str) -> Result<()> {
        let here = |name: &str| if prefix.is_empty() { name.to_string() } else { format!("{prefix}.{name}") };
        if el.child("SignalDictionaries").is_some() {
            return Err(self.err(format!(
                "{}: SignalDictionaries are not supported (signal dictionaries and their references are refused)",
                self.shown(prefix)
            )));
        }
        if let Some(connectors) = el.child("Connectors") {
            for c in connectors.all("Connector") {
                let name = c.attr("name").unwrap_or("");
                let kind = c.attr("kind").unwrap_or("").to_string();
                if self.connectors.insert((prefix.to_string(), name.to_string()), kind).is_some() {
                    return Err(self.err(format!("{}: connector {name:?} is declared twice", self.shown(prefix))));
                }
            }
        }
        let mut elements: HashMap<String, bool> = HashMap::new();
        if let Some(list) = el.child("Elements") {
            for e in &list.children {
                let name = e.attr("name").ok_or_else(|| self.err(format!("an element {} without name", e.name)))?;
                if name.contains('.') || name.is_empty() || elements.contains_key(name) {
                    return Err(self.err(format!(
                        "{}: element name {name:?}: empty, containing '.' or repeated",
                        self.shown(prefix)
                    )));
                }
                elements.insert(name.to_string(), e.name == "System");
                match e.name.as_str() {
                    "Component" => self.component(e, &here(name))?,
                    "System" => self.system(e, &here(name))?,
                    "SignalDictionaryReference" => {
                        return Err(self.err(format!(
                            "{}: element {name:?}: SignalDictionaryReference is not supported (signal dictionaries are refused)",
                            self.shown(prefix)
                        )))
                    }
                    other => {
                        return Err(self.err(format!(
                            "{}: element {name:?}: {other} is not supported",
                            self.shown(prefix)
                        )))
                    }
                }
            }
        }
        self.elements.insert(prefix.to_string(), elements);
        // the system's bindings after those of its elements: a higher level wins
        if let Some(bindings) = el.child("ParameterBindings") {
            self.bindings(bindings, prefix, false)?;
        }
        if let Some(connections) = el.child("Connections") {
            for c in connections.all("Connection") {
                self.connection(c, prefix)?;
            }
        }
        Ok(())
    }

    /// One connection of the system `prefix`: its ends resolved, its direction decided by
    /// the kinds of its connectors (SSP 1.0: start and end carry no direction).
    fn connection(&mut self, c: &Element, prefix: &str) -> Result<()> {
        let here = |name: &str| if prefix.is_empty() { name.to_string() } else { format!("{prefix}.{name}") };
        let start = c.attr("startConnector").ok_or_else(|| self.err("Connection without startConnector".into()))?;
        let end = c.attr("endConnector").ok_or_else(|| self.err("Connection without endConnector".into()))?;
        // startElement="" (as OMSimulator writes it) or absent: the system itself
        let (start_el, end_el) =
            (c.attr("startElement").filter(|e| !e.is_empty()), c.attr("endElement").filter(|e| !e.is_empty()));
        let shown = |element: Option<&str>, connector: &str| match element {
            Some(e) => format!("{e}.{connector}"),
            None => connector.to_string(),
        };
        let what = format!("connection {} -> {} of {}", shown(start_el, start), shown(end_el, end), self.shown(prefix));
        for a in ["startIndices", "endIndices"] {
            if c.attr(a).is_some() {
                return Err(self.err(format!("{what}: {a} (array connectors) is not supported")));
            }
        }
        let elements = self.elements.get(prefix).cloned().unwrap_or_default();
        // a component's variable, or a connector of this system or of a nested one
        let node = |element: Option<&str>, connector: &str| -> Result<Node> {
            let system = match element {
                None => prefix.to_string(),
                Some(e) => match elements.get(e) {
                    None => {
                        let mut known: Vec<&str> = elements.keys().map(String::as_str).collect();
                        known.sort_unstable();
                        return Err(self.err(format!(
                            "{what}: names an unknown element {e:?}{}",
                            crate::suggest::did_you_mean(e, known.iter().copied(), "elements")
                        )));
                    }
                    Some(false) => return Ok(Node::Variable { instance: here(e), variable: connector.to_string() }),
                    Some(true) => here(e),
                },
            };
            if !self.connectors.contains_key(&(system.clone(), connector.to_string())) {
                let mut declared: Vec<&str> =
                    self.connectors.keys().filter(|(s, _)| *s == system).map(|(_, c)| c.as_str()).collect();
                declared.sort_unstable();
                return Err(self.err(format!(
                    "{what}: {} declares no connector {connector:?}{}",
                    self.shown(&system),
                    crate::suggest::did_you_mean(connector, declared.iter().copied(), "its connectors")
                )));
            }
            Ok(Node::SystemConnector { system, connector: connector.to_string() })
        };
        let (a, b) = (node(start_el, start)?, node(end_el, end)?);
        let (fa, fb) = (self.flow(&a, prefix), self.flow(&b, prefix));
        let reversed = match (fa, fb) {
            (Some(Flow::Out), Some(Flow::Out)) | (Some(Flow::In), Some(Flow::In)) => {
                let side = if fa == Some(Flow::Out) { "sources (outputs)" } else { "destinations (inputs)" };
                return Err(Error::Connection {
                    from: shown(start_el, start),
                    to: shown(end_el, end),
                    reason: format!(
                        "in {}: both ends are {side} by their kinds ({} and {}): not an output to an input",
                        self.shown(prefix),
                        self.kind_of(&a, prefix),
                        self.kind_of(&b, prefix)
                    ),
                });
            }
            (Some(Flow::In), _) | (_, Some(Flow::Out)) => true,
            _ => false,
        };
        let mut linear = (1.0, 0.0);
        for t in &c.children {
            match Transformation::read(t) {
                Some(Ok(Transformation::Linear(f, o))) => linear = (f, o),
                Some(Ok(other)) => {
                    return Err(self.err(format!(
                        "{what}: {} on a connection is not supported (LinearTransformation is; \
                         mapping transformations are supported in parameter mappings)",
                        other.name()
                    )))
                }
                Some(Err(why)) => return Err(self.err(format!("{what}: {why}"))),
                None if matches!(t.name.as_str(), "ConnectionGeometry" | "Annotations") => {}
                None => return Err(self.err(format!("{what}: {} is not supported", t.name))),
            }
        }
        let suppress = c.attr("suppressUnitConversion") == Some("true");
        let (from, to) = if reversed { (b, a) } else { (a, b) };
        self.edges.push((from, to, linear.0, linear.1, suppress));
        Ok(())
    }

    /// The kind of a connection's end as messages name it.
    fn kind_of(&self, n: &Node, _prefix: &str) -> String {
        match n {
            Node::Variable { instance, variable } => {
                let causality = self
                    .builder
                    .system()
                    .resolve_parts(instance, variable)
                    .map(|r| self.builder.system().variable(&r).causality.as_str())
                    .unwrap_or("unknown");
                format!("{instance}.{variable} is {causality}")
            }
            Node::SystemConnector { system, connector } => {
                let kind = self.connectors.get(&(system.clone(), connector.clone())).map_or("", String::as_str);
                format!("connector {connector} of {} is {kind}", self.shown(system))
            }
        }
    }

    /// Which way data flows through `n` in a connection of the system `prefix`: an FMU
    /// variable by its causality; a system connector by its kind, seen from inside its own
    /// system (an input feeds) or from the enclosing one (an input is fed). `None`: the
    /// kind does not say (inout, unspecified, absent).
    fn flow(&self, n: &Node, prefix: &str) -> Option<Flow> {
        match n {
            Node::Variable { instance, variable } => {
                let s = self.builder.system();
                let r = s.resolve_parts(instance, variable).ok()?;
                Some(match s.variable(&r).causality {
                    Causality::Input | Causality::Parameter => Flow::In,
                    _ => Flow::Out,
                })
            }
            Node::SystemConnector { system, connector } => {
                let kind = self.connectors.get(&(system.clone(), connector.clone()))?;
                let inward = match kind.as_str() {
                    "input" | "parameter" | "structuralParameter" => true,
                    "output" | "calculatedParameter" | "local" | "constant" => false,
                    _ => return None,
                };
                let inside = system == prefix;
                Some(if inward == inside { Flow::Out } else { Flow::In })
            }
        }
    }

    fn component(&mut self, el: &Element, name: &str) -> Result<()> {
        let ty = el.attr("type").unwrap_or(FMU_TYPE);
        if ty != FMU_TYPE {
            return Err(self.err(format!("component {name:?}: type {ty:?} is not supported (only {FMU_TYPE})")));
        }
        let source = el.attr("source").ok_or_else(|| self.err(format!("component {name:?} has no source")))?;
        let rel = self.resource(source)?;
        let what = format!("component {name:?}");
        let origin = self.locate(&rel, &what, source)?;
        let file = origin.shown();
        let fmu = match self.fmus.get(&file) {
            Some(f) => f.clone(),
            None => {
                let mut options = self.options.clone();
                // the interface asked for by the importer wins over the SSD's choice
                match el.attr("implementation") {
                    _ if options.interface.is_some() => {}
                    Some("ModelExchange") => options.interface = Some(crate::Interface::ModelExchange),
                    Some("CoSimulation") => options.interface = Some(crate::Interface::CoSimulation),
                    _ => {}
                }
                // a missing or unreadable FMU is named by its component and the package
                let f = Fmu::load_from(&origin, &options).map_err(|e| match e {
                    crate::ImportError::Io { path, source: io } => {
                        self.err(format!("{what}: cannot read its source {source:?} ({}): {io}", path.display()))
                    }
                    e @ (crate::ImportError::Archive { .. }
                    | crate::ImportError::NotRegularFile { .. }
                    | crate::ImportError::MissingBinary { .. }) => self.err(format!("{what} (source {source:?}): {e}")),
                    other => other.into(),
                })?;
                self.fmus.insert(file.clone(), f.clone());
                f
            }
        };
        self.builder.add_instance(name, fmu.clone())?;
        if let Some(connectors) = el.child("Connectors") {
            for c in connectors.all("Connector") {
                let cname = c.attr("name").unwrap_or("");
                let declared_clock = c.child("Clock").is_some();
                // SSP 2.0: a clock connector (ssc:Clock) names a clock of the FMU; its
                // connections are checked as every connection (clock to clock only)
                if fmu.clocks().iter().any(|k| k.name == cname) {
                    let other = c.children.iter().map(|t| t.name.as_str()).find(|t| {
                        REAL_TYPES.contains(t)
                            || INTEGER_TYPES.contains(t)
                            || ["Boolean", "String", "Binary"].contains(t)
                    });
                    if let Some(other) = other {
                        return Err(self.err(format!(
                            "component {name:?}: connector {cname:?} is declared {other} but the variable is a clock"
                        )));
                    }
                    continue;
                }
                if declared_clock {
                    return Err(self.err(format!(
                        "component {name:?}: connector {cname:?} is declared Clock but the variable is no clock of {}",
                        fmu.source().display()
                    )));
                }
                let v = fmu.description().variable(cname).ok_or_else(|| {
                    self.err(format!(
                        "component {name:?}: connector {cname:?} is not a variable of {}",
                        fmu.source().display()
                    ))
                })?;
                let declared = c.children.iter().map(|t| t.name.as_str()).find(|t| {
                    REAL_TYPES.contains(t) || INTEGER_TYPES.contains(t) || ["Boolean", "String", "Binary"].contains(t)
                });
                if let Some(declared) = declared {
                    let actual = BaseType::of(v);
                    // an FMI 3.0 64-bit or unsigned 32-bit integer is a Real of the master's
                    // view, and connections carry it as an integer, exactly
                    // (`simulate/integers.rs`): ssc:Integer declares it
                    let wide_integer = fmu.fmi3_description().is_some_and(|md| {
                        md.model_variables.iter().any(|x| {
                            x.name == cname
                                && matches!(
                                    x.value_type,
                                    model_description::fmi3::ValueType::Int64
                                        | model_description::fmi3::ValueType::UInt64
                                        | model_description::fmi3::ValueType::UInt32
                                )
                        })
                    });
                    let fits = match actual {
                        BaseType::Real => {
                            REAL_TYPES.contains(&declared) || wide_integer && INTEGER_TYPES.contains(&declared)
                        }
                        BaseType::Integer => INTEGER_TYPES.contains(&declared),
                        BaseType::Boolean => declared == "Boolean",
                        BaseType::String => declared == "String",
                    };
                    if !fits {
                        return Err(self.err(format!(
                            "component {name:?}: connector {cname:?} is declared {declared} but the variable is {}",
                            actual.as_str()
                        )));
                    }
                }
            }
        }
        if let Some(bindings) = el.child("ParameterBindings") {
            self.bindings(bindings, name, true)?;
        }
        Ok(())
    }

    /// Resolves the hierarchical `name` of a value bound in the system `system`: a
    /// connector of it, or `element.rest` with `rest` a variable of a component or a
    /// name inside a nested system.
    fn resolve_in_system(&self, system: &str, name: &str) -> Option<Target> {
        if self.connectors.contains_key(&(system.to_string(), name.to_string())) {
            return Some(Target::Connector { system: system.to_string(), connector: name.to_string() });
        }
        let (head, rest) = name.split_once('.')?;
        let path = if system.is_empty() { head.to_string() } else { format!("{system}.{head}") };
        match self.elements.get(system)?.get(head)? {
            true => self.resolve_in_system(&path, rest),
            false => self.resolve_in_component(&path, rest),
        }
    }

    fn resolve_in_component(&self, instance: &str, variable: &str) -> Option<Target> {
        let s = self.builder.system();
        let i = s.instance_index(instance)?;
        s.description(i).variable(variable)?;
        Some(Target::Variable { instance: instance.to_string(), variable: variable.to_string() })
    }

    /// The ParameterBindings of a component (`is_component`) or a system at `owner`.
    fn bindings(&mut self, el: &Element, owner: &str, is_component: bool) -> Result<()> {
        let whose = if is_component { format!("component {owner:?}") } else { self.shown(owner) };
        for b in el.all("ParameterBinding") {
            if let Some(t) = b.attr("type") {
                if t != "application/x-ssp-parameter-set" {
                    return Err(self.err(format!("{whose}: parameter binding type {t:?} is not supported")));
                }
            }
            let (set, from) = match (b.attr("source"), b.child("ParameterValues")) {
                (Some(src), _) => (
                    self.read_document(src, b.attr("sourceBase"), &format!("{whose}: parameter file"), "ParameterSet")?,
                    src.to_string(),
                ),
                (None, Some(values)) => (
                    values
                        .child("ParameterSet")
                        .cloned()
                        .ok_or_else(|| self.err(format!("{whose}: ParameterValues without ParameterSet")))?,
                    "inline values".to_string(),
                ),
                (None, None) => return Err(self.err(format!("{whose}: ParameterBinding without source or values"))),
            };
            let values = parameters::parameter_set(&set).map_err(|why| self.err(format!("{whose}: {from}: {why}")))?;
            let prefix = b.attr("prefix").unwrap_or("");
            // the prefix is prepended to every name of the set (SSP 1.0, ParameterBinding)
            let values: Vec<(String, ParameterValue)> =
                values.into_iter().map(|(n, v)| (format!("{prefix}{n}"), v)).collect();
            let mut applied: Vec<(String, Bound)> = Vec::new();
            match b.child("ParameterMapping") {
                None => {
                    for (n, v) in values {
                        let origin = format!("{whose}, {from}");
                        applied.push((
                            n,
                            Bound { value: v, transformation: None, suppress_unit_conversion: false, origin },
                        ));
                    }
                }
                Some(m) => {
                    if let Some(t) = m.attr("type") {
                        if t != "application/x-ssp-parameter-mapping" {
                            return Err(self.err(format!("{whose}: parameter mapping type {t:?} is not supported")));
                        }
                    }
                    let (mapping, mfrom) = match m.attr("source") {
                        Some(src) => (
                            self.read_document(
                                src,
                                m.attr("sourceBase"),
                                &format!("{whose}: parameter mapping"),
                                "ParameterMapping",
                            )?,
                            src.to_string(),
                        ),
                        None => (
                            m.child("ParameterMapping").cloned().ok_or_else(|| {
                                self.err(format!("{whose}: ParameterMapping without source or ssm:ParameterMapping"))
                            })?,
                            "inline mapping".to_string(),
                        ),
                    };
                    let entries = parameters::mapping_entries(&mapping)
                        .map_err(|why| self.err(format!("{whose}: {mfrom}: {why}")))?;
                    // only the mapped values apply, under their mapped names
                    let by_name: HashMap<&str, &ParameterValue> = values.iter().map(|(n, v)| (n.as_str(), v)).collect();
                    let mut unmapped = 0;
                    for e in &entries {
                        let Some(v) = by_name.get(e.source.as_str()) else {
                            unmapped += 1;
                            continue;
                        };
                        applied.push((
                            e.target.clone(),
                            Bound {
                                value: (*v).clone(),
                                transformation: e.transformation.clone(),
                                suppress_unit_conversion: e.suppress_unit_conversion,
                                origin: format!("{whose}, {from} mapped by {mfrom}: {}", e.source),
                            },
                        ));
                    }
                    if unmapped > 0 {
                        self.notes.push(format!(
                            "{whose}: {unmapped} of the {} entries of the parameter mapping {mfrom} name no parameter \
                             of {from} (source {:?}...): they apply nothing",
                            entries.len(),
                            entries.iter().find(|e| !by_name.contains_key(e.source.as_str())).map_or("", |e| &e.source)
                        ));
                    }
                }
            }
            let mut ignored: Vec<String> = Vec::new();
            for (name, bound) in applied {
                let target = if is_component {
                    self.resolve_in_component(owner, &name)
                } else {
                    self.resolve_in_system(owner, &name)
                };
                match target {
                    Some(Target::Variable { instance, variable }) => self.bound.push((instance, variable, bound)),
                    Some(Target::Connector { system, connector }) => {
                        self.connector_values.insert((system, connector), bound);
                    }
                    None => ignored.push(name),
                }
            }
            if !ignored.is_empty() {
                let shown: Vec<&str> = ignored.iter().take(5).map(String::as_str).collect();
                self.notes.push(format!(
                    "{whose}, {from}: {} value{} name{} no variable or connector and {} ignored (SSP 1.0): {}{}",
                    ignored.len(),
                    if ignored.len() == 1 { "" } else { "s" },
                    if ignored.len() == 1 { "s" } else { "" },
                    if ignored.len() == 1 { "is" } else { "are" },
                    shown.join(", "),
                    if ignored.len() > 5 { ", ..." } else { "" }
                ));
            }
        }
        Ok(())
    }
}

/// A system connector's source: the node its data comes from (an FMU output, or a
/// system connector nothing feeds) and the composed (factor, offset, suppress unit
/// conversion).
type Trace<'n> = (&'n Node, f64, f64, bool);

type Edge = (Node, Node, f64, f64, bool);

/// A value reaching an FMU variable (instance, variable) from a system connector, with the
/// connection's composed (factor, offset, suppress unit conversion).
type ViaConnector = (String, String, Bound, (f64, f64, bool));

/// Traces `start` back through system connectors to an FMU output or to a system
/// connector nothing feeds: walks back to a variable, an unfed connector or one traced
/// before, then remembers the trace of every connector on the way.
fn trace<'e>(
    start: &'e Node,
    edges: &'e [Edge],
    feeding: &HashMap<&'e Node, usize>,
    traced: &mut HashMap<&'e Node, Trace<'e>>,
) -> std::result::Result<Trace<'e>, String> {
    let mut path: Vec<&Node> = Vec::new();
    let mut node = start;
    let base: Trace = loop {
        if let Node::Variable { .. } = node {
            break (node, 1.0, 0.0, false);
        }
        if let Some(t) = traced.get(node) {
            break *t;
        }
        let Some(&k) = feeding.get(node) else { break (node, 1.0, 0.0, false) };
        if path.len() > edges.len() {
            return Err("connections through system connectors form a cycle".into());
        }
        path.push(node);
        node = &edges[k].0;
    };
    let mut t = base;
    for n in path.into_iter().rev() {
        let (_, _, k2, o2, s2) = &edges[feeding[n]];
        // connector = k2 * source + o2, source = t.1 x + t.2
        t = (t.0, k2 * t.1, k2 * t.2 + o2, t.3 | s2);
        traced.insert(n, t);
    }
    Ok(t)
}

/// Reads an `.ssp` archive or a bare `.ssd` file (FMU sources relative to its folder).
pub fn read_ssp(path: &Path, options: &ImportOptions) -> Result<SspSystem> {
    let is_ssd = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ssd"));
    let root = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let (archive, text) = if is_ssd {
        (None, crate::unpack::read_text_file(path, "SystemStructure.ssd", options.limits.max_xml_bytes)?)
    } else {
        // every header checked first; then only the .ssd, the .ssv files named and the
        // FMUs are read, straight from the archive
        let file = crate::unpack::open_regular(path)?;
        let mut zip = zip::ZipArchive::new(std::io::BufReader::with_capacity(64 * 1024, file)).map_err(|e| {
            Error::Import(crate::ImportError::Archive { path: path.to_path_buf(), reason: e.to_string() })
        })?;
        let entries: HashMap<PathBuf, String> = crate::unpack::check_entries(&mut zip, path, &options.limits)?
            .into_iter()
            .map(|e| (e.rel, e.name))
            .collect();
        let ssd_name = entries.get(Path::new("SystemStructure.ssd")).cloned().ok_or_else(|| Error::Ssp {
            path: path.to_path_buf(),
            reason: "cannot read SystemStructure.ssd: no such entry in the archive".into(),
        })?;
        let text = crate::unpack::read_text_entry(&mut zip, path, &ssd_name, options.limits.max_xml_bytes)?
            .unwrap_or_default();
        (Some((std::cell::RefCell::new(zip), entries)), text)
    };
    let doc = parse_xml(&text, path)?;
    if doc.name != "SystemStructureDescription" {
        return Err(Error::Ssp {
            path: path.to_path_buf(),
            reason: format!("root element is {}, not SystemStructureDescription", doc.name),
        });
    }
    let system_el =
        doc.child("System").ok_or_else(|| Error::Ssp { path: path.to_path_buf(), reason: "no System".into() })?;
    let mut f = Flattener {
        root: &root,
        path,
        archive,
        options,
        fmus: HashMap::new(),
        builder: SystemBuilder::new(),
        root_name: system_el.attr("name").unwrap_or("").to_string(),
        edges: Vec::new(),
        connectors: Default::default(),
        elements: HashMap::new(),
        bound: Vec::new(),
        connector_values: HashMap::new(),
        notes: Vec::new(),
    };
    match doc.attr("version").map(str::trim) {
        Some("1.0") | None => {}
        Some("2.0") => f.notes.push(
            "the SSD says version=\"2.0\" (the SSP 2.0 draft): read as SSP 1.0 (FMI 3.0 connector types such as \
             Float64 and Int64 and clock connectors accepted; array connectors and 2.0's other additions are refused by name)"
                .into(),
        ),
        Some(v) => f.notes.push(format!("the SSD says version={v:?}: read as SSP 1.0")),
    }
    f.system(system_el, "")?;
    // follow connections through system connectors: every edge ending at an FMU variable
    // is traced back to an FMU output (a connection) or to a system connector nothing
    // feeds (its bound value, if any). Each system connector is fed by at most one edge
    // (a map from it to that edge), and a connector's trace is remembered, so the whole is
    // linear in the number of connections.
    let edges = std::mem::take(&mut f.edges);
    let mut feeding: HashMap<&Node, usize> = HashMap::new();
    for (k, (_, to, ..)) in edges.iter().enumerate() {
        if let Node::SystemConnector { system, connector } = to {
            if feeding.insert(to, k).is_some() {
                return Err(f.err(format!("{}: connector {connector:?} is fed by two connections", f.shown(system))));
            }
        }
    }
    let mut traced: HashMap<&Node, Trace> = HashMap::new();
    // values reaching FMU variables from system connectors, applied after the bindings
    let mut from_connectors: Vec<ViaConnector> = Vec::new();
    let mut used_connectors: std::collections::HashSet<(String, String)> = Default::default();
    for (a, b, k, o, s) in &edges {
        let Node::Variable { instance: bi, variable: bv } = b else { continue };
        let (src, factor0, offset0, suppress0) = trace(a, &edges, &feeding, &mut traced).map_err(|r| f.err(r))?;
        // to = k (factor0 x + offset0) + o
        let (factor, offset, suppress) = (k * factor0, k * offset0 + o, suppress0 | s);
        match src {
            Node::Variable { instance: ai, variable: av } => {
                let from = format!("{ai}.{av}");
                let to = format!("{bi}.{bv}");
                let linear = if factor == 1.0 && offset == 0.0 { None } else { Some((factor, offset)) };
                if suppress {
                    f.builder.connect_unconverted(&from, &to, linear)?;
                } else {
                    f.builder.connect_linear(&from, &to, linear)?;
                }
            }
            Node::SystemConnector { system, connector } => {
                let key = (system.clone(), connector.clone());
                match f.connector_values.get(&key) {
                    Some(bound) => {
                        used_connectors.insert(key);
                        from_connectors.push((bi.clone(), bv.clone(), bound.clone(), (factor, offset, suppress)));
                    }
                    None => f.notes.push(format!(
                        "{bi}.{bv} is connected to connector {connector} of {}, which nothing feeds and no value is \
                         bound to: it keeps its start value",
                        f.shown(system)
                    )),
                }
            }
        }
    }
    let mut keys: Vec<&(String, String)> =
        f.connector_values.keys().filter(|k| !used_connectors.contains(*k)).collect();
    keys.sort();
    for key in keys {
        let (system, connector) = key;
        let node = Node::SystemConnector { system: system.clone(), connector: connector.clone() };
        let why = if feeding.contains_key(&node) {
            "is fed by a connection, which decides its value: the bound value is not used"
        } else {
            "reaches no FMU variable: it changes nothing"
        };
        f.notes.push(format!("the value bound to connector {connector} of {} {why}", f.shown(system)));
    }
    // bound values in their order (a higher level and a later binding win), then the
    // values that reach variables through connections from system connectors (the
    // connection decides the value of what it connects)
    let mut applied: Vec<String> = Vec::new();
    let bound = std::mem::take(&mut f.bound);
    let direct = bound.into_iter().map(|(i, v, b)| (i, v, b, (1.0, 0.0, false), None));
    let via = from_connectors.into_iter().map(|(i, v, b, t)| (i, v, b, t, Some(())));
    for (instance, variable, b, then, through) in direct.chain(via) {
        let (value, how) = value_for(f.builder.system(), &instance, &variable, &b, then, &mut f.notes)
            .map_err(|why| f.err(format!("{}: {why}", b.origin)))?;
        let full = format!("{instance}.{variable}");
        let path = f.path.to_path_buf();
        f.builder
            .set(&full, value.clone())
            .map_err(|e| Error::Ssp { path: path.clone(), reason: format!("{}: {e}", b.origin) })?;
        let via = if through.is_some() { " through a system connector" } else { "" };
        applied.push(format!("{full} = {value}{how}  [{}{via}]", b.origin));
    }
    let default_start_stop = doc
        .child("DefaultExperiment")
        .map(|d| {
            (
                d.attr("startTime").and_then(model_description::parse_xs_double),
                d.attr("stopTime").and_then(model_description::parse_xs_double),
            )
        })
        .unwrap_or((None, None));
    let archive = (!is_ssd).then(|| path.to_path_buf());
    let system = f.builder.build();
    Ok(SspSystem { system, default_start_stop, root_name: f.root_name, notes: f.notes, applied, archive })
}
