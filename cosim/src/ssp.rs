//! SSP 1.0 import (`.ssp` archives and bare `.ssd` files) into a [`System`], and export of
//! a [`System`] built in Rust as an `.ssp` that fmpy, ecos and libcosim can run.
//!
//! Supported: Components of type `application/x-fmu-sharedlibrary`, their Connectors,
//! Connections with `LinearTransformation` (factor defaults to 1, offset to 0),
//! `suppressUnitConversion`, ParameterBindings inline or from `.ssv` files (with
//! `prefix`), nested Systems (flattened: instance names are the element paths joined
//! with `.`; connections through system connectors are followed), DefaultExperiment.
//! Refused by name: signal dictionaries, parameter mappings, other transformations,
//! other component types. Geometry, annotations and graphical elements are ignored.

use crate::error::{Error, Result};
use crate::fmu::{Fmu, ImportOptions};
use crate::system::{BaseType, System, SystemBuilder, Value};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A small element tree of an XML document (local names, namespaces dropped).
#[derive(Debug, Clone, Default)]
struct Element {
    name: String,
    attributes: Vec<(String, String)>,
    children: Vec<Element>,
}

impl Element {
    fn attr(&self, name: &str) -> Option<&str> {
        self.attributes.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }
    fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }
    fn all<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
}

fn parse_xml(text: &str, path: &Path) -> Result<Element> {
    use quick_xml::events::Event;
    let err = |reason: String| Error::Ssp { path: path.to_path_buf(), reason };
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut stack: Vec<Element> = vec![Element::default()];
    let open = |e: &quick_xml::events::BytesStart| -> Result<Element> {
        let mut el =
            Element { name: String::from_utf8_lossy(e.local_name().as_ref()).into_owned(), ..Element::default() };
        // a hash set for duplicates: quick-xml's own check is quadratic in the attributes
        let mut keys = std::collections::HashSet::new();
        for a in e.attributes().with_checks(false) {
            let a = a.map_err(|x| err(format!("malformed XML attribute: {x}")))?;
            if !keys.insert(a.key.as_ref().to_vec()) {
                return Err(err(format!(
                    "attribute {} repeated in <{}>",
                    String::from_utf8_lossy(a.key.as_ref()),
                    el.name
                )));
            }
            let v = a.unescape_value().map_err(|x| err(format!("malformed XML attribute value: {x}")))?;
            el.attributes.push((String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned(), v.into_owned()));
        }
        Ok(el)
    };
    loop {
        let pos = reader.buffer_position();
        match reader.read_event() {
            Ok(Event::Start(e)) => {
                if stack.len() > 64 {
                    return Err(err("XML nested deeper than 64 elements".into()));
                }
                stack.push(open(&e)?)
            }
            Ok(Event::Empty(e)) => {
                let el = open(&e)?;
                if let Some(p) = stack.last_mut() {
                    p.children.push(el);
                }
            }
            Ok(Event::End(_)) => {
                let el = stack.pop().ok_or_else(|| err("unbalanced XML".into()))?;
                match stack.last_mut() {
                    Some(p) => p.children.push(el),
                    None => return Err(err("unbalanced XML".into())),
                }
            }
            Ok(Event::Eof) => break,
            Ok(_) => {}
            Err(e) => return Err(err(format!("malformed XML at byte {pos}: {e}"))),
        }
    }
    if stack.len() != 1 {
        return Err(err("XML ends inside an element".into()));
    }
    let mut root = stack.pop().unwrap_or_default();
    root.children.pop().ok_or_else(|| err("empty XML document".into()))
}

/// An SSP system, imported: the flattened [`System`] and its default experiment. The
/// FMUs of an `.ssp` are read from it in place (each unpacks only what a run uses).
pub struct SspSystem {
    /// The flattened system.
    pub system: System,
    /// `DefaultExperiment` start and stop time, if given.
    pub default_start_stop: (Option<f64>, Option<f64>),
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

struct Flattener<'a> {
    root: &'a Path,
    path: &'a Path,
    /// The `.ssp` and its checked entries (relative path -> entry name); `None` for an `.ssd`.
    archive: Option<(std::cell::RefCell<Zip>, HashMap<PathBuf, String>)>,
    options: &'a ImportOptions,
    fmus: HashMap<PathBuf, Arc<Fmu>>,
    builder: SystemBuilder,
    /// edges (from, to, factor, offset, suppress_unit_conversion)
    edges: Vec<Edge>,
    /// declared system connectors: (system path, connector name)
    connectors: std::collections::HashSet<(String, String)>,
    parameters: Vec<(String, String, String)>, // (instance.variable, type, value text)
}

const FMU_TYPE: &str = "application/x-fmu-sharedlibrary";

impl Flattener<'_> {
    fn err(&self, reason: String) -> Error {
        Error::Ssp { path: self.path.to_path_buf(), reason }
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

    fn system(&mut self, el: &Element, prefix: &str) -> Result<()> {
        let here = |name: &str| if prefix.is_empty() { name.to_string() } else { format!("{prefix}.{name}") };
        for unsupported in ["SignalDictionaries"] {
            if el.child(unsupported).is_some() {
                return Err(self.err(format!("system {prefix:?}: {unsupported} are not supported")));
            }
        }
        if let Some(connectors) = el.child("Connectors") {
            for c in connectors.all("Connector") {
                let name = c.attr("name").unwrap_or("");
                if !self.connectors.insert((prefix.to_string(), name.to_string())) {
                    return Err(self.err(format!("system {prefix:?}: connector {name:?} is declared twice")));
                }
            }
        }
        // element name -> whether it is a nested system
        let mut elements: HashMap<&str, bool> = HashMap::new();
        if let Some(list) = el.child("Elements") {
            for e in &list.children {
                let name = e.attr("name").ok_or_else(|| self.err(format!("an element {} without name", e.name)))?;
                if name.contains('.') || name.is_empty() || elements.contains_key(name) {
                    return Err(self.err(format!("element name {name:?}: empty, containing '.' or repeated")));
                }
                elements.insert(name, e.name == "System");
                match e.name.as_str() {
                    "Component" => self.component(e, &here(name))?,
                    "System" => self.system(e, &here(name))?,
                    other => return Err(self.err(format!("element {name:?}: {other} is not supported"))),
                }
            }
        }
        if let Some(bindings) = el.child("ParameterBindings") {
            self.bindings(bindings, prefix, true)?;
        }
        if let Some(connections) = el.child("Connections") {
            for c in connections.all("Connection") {
                let start =
                    c.attr("startConnector").ok_or_else(|| self.err("Connection without startConnector".into()))?;
                let end = c.attr("endConnector").ok_or_else(|| self.err("Connection without endConnector".into()))?;
                let shown = |element: Option<&str>, connector: &str| match element {
                    Some(e) => format!("{e}.{connector}"),
                    None => connector.to_string(),
                };
                let what = format!(
                    "connection {} -> {} of system {prefix:?}",
                    shown(c.attr("startElement"), start),
                    shown(c.attr("endElement"), end)
                );
                // a component's variable, or a connector of this system or of a nested one
                let node = |element: Option<&str>, connector: &str| -> Result<Node> {
                    let system = match element {
                        None => prefix.to_string(),
                        Some(e) => match elements.get(e) {
                            None => {
                                let mut known: Vec<&str> = elements.keys().copied().collect();
                                known.sort_unstable();
                                return Err(self.err(format!(
                                    "{what}: names an unknown element {e:?}{}",
                                    crate::suggest::did_you_mean(e, known.iter().copied(), "elements")
                                )));
                            }
                            Some(false) => {
                                return Ok(Node::Variable { instance: here(e), variable: connector.to_string() })
                            }
                            Some(true) => here(e),
                        },
                    };
                    if !self.connectors.contains(&(system.clone(), connector.to_string())) {
                        let mut declared: Vec<&str> =
                            self.connectors.iter().filter(|(s, _)| *s == system).map(|(_, c)| c.as_str()).collect();
                        declared.sort_unstable();
                        return Err(self.err(format!(
                            "{what}: system {system:?} declares no connector {connector:?}{}",
                            crate::suggest::did_you_mean(connector, declared.iter().copied(), "its connectors")
                        )));
                    }
                    Ok(Node::SystemConnector { system, connector: connector.to_string() })
                };
                let (from, to) = (node(c.attr("startElement"), start)?, node(c.attr("endElement"), end)?);
                let (mut factor, mut offset) = (1.0, 0.0);
                for t in &c.children {
                    match t.name.as_str() {
                        "LinearTransformation" => {
                            let num = |a: &str, d: f64| -> Result<f64> {
                                t.attr(a).map_or(Ok(d), |v| {
                                    model_description::parse_xs_double(v).filter(|x| x.is_finite()).ok_or_else(|| {
                                        self.err(format!("LinearTransformation {a}={v:?} is not a finite number"))
                                    })
                                })
                            };
                            factor = num("factor", 1.0)?;
                            offset = num("offset", 0.0)?;
                        }
                        "ConnectionGeometry" | "Annotations" => {}
                        other => return Err(self.err(format!("{what}: {other} is not supported"))),
                    }
                }
                let suppress = c.attr("suppressUnitConversion") == Some("true");
                self.edges.push((from, to, factor, offset, suppress));
            }
        }
        Ok(())
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
                let v = fmu.description().variable(cname).ok_or_else(|| {
                    self.err(format!(
                        "component {name:?}: connector {cname:?} is not a variable of {}",
                        fmu.source().display()
                    ))
                })?;
                if let Some(t) = c.children.iter().find(|t| {
                    ["Real", "Integer", "Boolean", "String", "Enumeration", "Binary"].contains(&t.name.as_str())
                }) {
                    let declared = match t.name.as_str() {
                        "Enumeration" => "Integer",
                        n => n,
                    };
                    if declared != BaseType::of(v).as_str() {
                        return Err(self.err(format!(
                            "component {name:?}: connector {cname:?} is declared {declared} but the variable is {}",
                            BaseType::of(v).as_str()
                        )));
                    }
                }
            }
        }
        if let Some(bindings) = el.child("ParameterBindings") {
            self.bindings(bindings, name, false)?;
        }
        Ok(())
    }

    fn bindings(&mut self, el: &Element, owner: &str, is_system: bool) -> Result<()> {
        for b in el.all("ParameterBinding") {
            if b.child("ParameterMapping").is_some() {
                return Err(self.err(format!("{owner:?}: ParameterMapping is not supported")));
            }
            if let Some(t) = b.attr("type") {
                if t != "application/x-ssp-parameter-set" {
                    return Err(self.err(format!("{owner:?}: parameter binding type {t:?} is not supported")));
                }
            }
            let set = match (b.attr("source"), b.child("ParameterValues")) {
                (Some(src), _) => {
                    let rel = self.resource(src)?;
                    let text = self.read_text(&rel, &format!("{owner:?}: parameter file"), src)?;
                    let set = parse_xml(&text, &self.path.join(&rel))?;
                    if set.name != "ParameterSet" {
                        return Err(self.err(format!(
                            "{owner:?}: parameter file {src:?} has the root element <{}>, not <ParameterSet> \
                             (an SSP 1.0 .ssv file)",
                            set.name
                        )));
                    }
                    set
                }
                (None, Some(values)) => values
                    .child("ParameterSet")
                    .cloned()
                    .ok_or_else(|| self.err(format!("{owner:?}: ParameterValues without ParameterSet")))?,
                (None, None) => return Err(self.err(format!("{owner:?}: ParameterBinding without source or values"))),
            };
            let prefix = b.attr("prefix").unwrap_or("");
            let Some(params) = set.child("Parameters") else { continue };
            for p in params.all("Parameter") {
                let pname = p.attr("name").unwrap_or("");
                let Some(rest) = pname.strip_prefix(prefix) else { continue };
                // a component's binding names its variables; a system's names
                // `element.variable` relative to the system: both are prefixed with the owner
                let _ = is_system;
                let target = if owner.is_empty() { rest.to_string() } else { format!("{owner}.{rest}") };
                let v = p
                    .children
                    .iter()
                    .find(|c| c.name != "Annotations")
                    .ok_or_else(|| self.err(format!("parameter {pname:?} has no value")))?;
                let value = v.attr("value").ok_or_else(|| self.err(format!("parameter {pname:?} has no value")))?;
                if v.attr("unit").is_some() {
                    // values in another unit than the variable's would need the ssv's unit
                    // definitions; refused rather than guessed
                    let unit = v.attr("unit").unwrap_or("");
                    self.parameters.push((target.clone(), format!("unit:{unit}"), value.to_string()));
                    continue;
                }
                self.parameters.push((target, v.name.clone(), value.to_string()));
            }
        }
        Ok(())
    }
}

/// A system connector's source: the FMU output (or None: an unconnected system input)
/// and the composed (factor, offset, suppress unit conversion).
type Trace<'n> = (Option<&'n Node>, f64, f64, bool);

type Edge = (Node, Node, f64, f64, bool);

/// Traces `start` back through system connectors to an FMU output: walks back to a
/// variable, an unfed connector or one traced before, then remembers the trace of every
/// connector on the way.
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
            break (Some(node), 1.0, 0.0, false);
        }
        if let Some(t) = traced.get(node) {
            break *t;
        }
        let Some(&k) = feeding.get(node) else { break (None, 1.0, 0.0, false) };
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
    let mut f = Flattener {
        root: &root,
        path,
        archive,
        options,
        fmus: HashMap::new(),
        builder: SystemBuilder::new(),
        edges: Vec::new(),
        connectors: Default::default(),
        parameters: Vec::new(),
    };
    let system_el = doc.child("System").ok_or_else(|| f.err("no System".into()))?;
    f.system(system_el, "")?;
    // follow connections through system connectors: every edge ending at an FMU input
    // is traced back to an FMU output, composing the linear transformations. Each system
    // connector is fed by at most one edge (a map from it to that edge), and a connector's
    // trace is remembered, so the whole is linear in the number of connections.
    let edges = std::mem::take(&mut f.edges);
    let mut feeding: HashMap<&Node, usize> = HashMap::new();
    for (k, (_, to, ..)) in edges.iter().enumerate() {
        if let Node::SystemConnector { system, connector } = to {
            if feeding.insert(to, k).is_some() {
                return Err(f.err(format!("system {system:?}: connector {connector:?} is fed by two connections")));
            }
        }
    }
    let mut traced: HashMap<&Node, Trace> = HashMap::new();
    for (a, b, k, o, s) in &edges {
        let Node::Variable { instance: bi, variable: bv } = b else { continue };
        let (src, factor0, offset0, suppress0) =
            trace(a, &edges, &feeding, &mut traced).map_err(|reason| f.err(reason))?;
        let Some(Node::Variable { instance: ai, variable: av }) = src else {
            continue; // fed by an unconnected system input: left at its start value
        };
        // to = k (factor0 x + offset0) + o
        let (factor, offset, suppress) = (k * factor0, k * offset0 + o, suppress0 | s);
        let from = format!("{ai}.{av}");
        let to = format!("{bi}.{bv}");
        let linear = if factor == 1.0 && offset == 0.0 { None } else { Some((factor, offset)) };
        if suppress {
            f.builder.connect_unconverted(&from, &to, linear)?;
        } else {
            f.builder.connect_linear(&from, &to, linear)?;
        }
    }
    let parameters = std::mem::take(&mut f.parameters);
    for (target, kind, value) in parameters {
        if let Some(unit) = kind.strip_prefix("unit:") {
            let r = f.builder.system().resolve(&target)?;
            let declared = f.builder.system().variable(&r).variable_type.unit().unwrap_or("").to_string();
            if unit != declared {
                return Err(f.err(format!(
                    "parameter {target}: value in unit {unit:?}, the variable is in {declared:?} (conversion of parameter values is not supported)"
                )));
            }
        }
        f.builder.set_text(&target, &value)?;
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
    Ok(SspSystem { system: f.builder.build(), default_start_stop, archive })
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn num(v: f64) -> String {
    let mut s = String::new();
    crate::simulate::push_number(&mut s, v);
    s
}

/// The name of the ParameterSet that holds the start values in an SSP written by [`write_ssp`].
pub const SSP_PARAMETER_SET: &str = "initialValues";

/// Writes `system` as an SSP 1.0 archive: `SystemStructure.ssd` plus each FMU archive
/// under `resources/` (one copy per distinct FMU), start values as inline parameter
/// bindings, connections with their linear transformations.
///
/// Every component's bindings are one ParameterSet named [`SSP_PARAMETER_SET`]: libcosim
/// applies each component's first set by default, ecos applies the sets of the one name
/// given to its `init` (and none without a name), so one name serves both.
pub fn write_ssp(system: &System, name: &str, stop_time: Option<f64>, path: &Path) -> Result<()> {
    let io = |source| Error::Import(crate::ImportError::Io { path: path.to_path_buf(), source });
    // FMU files, one per distinct source
    let mut files: Vec<(PathBuf, String)> = Vec::new();
    for spec in &system.instances {
        let src = spec.fmu.source().to_path_buf();
        if !files.iter().any(|(p, _)| *p == src) {
            let stem = src.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "fmu".into());
            let mut file = format!("resources/{stem}.fmu");
            let mut k = 1;
            while files.iter().any(|(_, f)| *f == file) {
                file = format!("resources/{stem}_{k}.fmu");
                k += 1;
            }
            files.push((src, file));
        }
    }
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str("<ssd:SystemStructureDescription xmlns:ssc=\"http://ssp-standard.org/SSP1/SystemStructureCommon\" xmlns:ssd=\"http://ssp-standard.org/SSP1/SystemStructureDescription\" xmlns:ssv=\"http://ssp-standard.org/SSP1/SystemStructureParameterValues\" version=\"1.0\"");
    x.push_str(&format!(" name=\"{}\" generationTool=\"nigel-cosim\">\n", esc(name)));
    x.push_str(&format!("  <ssd:System name=\"{}\">\n    <ssd:Elements>\n", esc(name)));
    for (i, spec) in system.instances.iter().enumerate() {
        let md = spec.fmu.description();
        let file = &files.iter().find(|(p, _)| p == spec.fmu.source()).map(|(_, f)| f.clone()).unwrap_or_default();
        x.push_str(&format!(
            "      <ssd:Component name=\"{}\" type=\"application/x-fmu-sharedlibrary\" source=\"{}\">\n",
            esc(&spec.name),
            esc(file)
        ));
        // connectors: every output, and the inputs that are connected (an unconnected
        // input connector would be driven with 0 by fmpy's simulate_ssp, not left at its start)
        let vars: Vec<_> = md
            .model_variables
            .iter()
            .enumerate()
            .filter(|(index, v)| match v.causality {
                model_description::Causality::Output => true,
                model_description::Causality::Input => {
                    system.connections.iter().any(|c| c.to.instance == i && c.to.index == *index)
                }
                _ => false,
            })
            .map(|(_, v)| v)
            .collect();
        if !vars.is_empty() {
            x.push_str("        <ssd:Connectors>\n");
            for v in vars {
                x.push_str(&format!(
                    "          <ssd:Connector name=\"{}\" kind=\"{}\"><ssc:{}/></ssd:Connector>\n",
                    esc(&v.name),
                    v.causality.as_str(),
                    BaseType::of(v).as_str()
                ));
            }
            x.push_str("        </ssd:Connectors>\n");
        }
        if !spec.start_values.is_empty() {
            x.push_str("        <ssd:ParameterBindings>\n          <ssd:ParameterBinding>\n            <ssd:ParameterValues>\n");
            x.push_str(&format!(
                "              <ssv:ParameterSet version=\"1.0\" name=\"{}\">\n                <ssv:Parameters>\n",
                SSP_PARAMETER_SET
            ));
            for (index, value) in &spec.start_values {
                let vname = &md.model_variables[*index].name;
                let v = match value {
                    Value::Real(r) => format!("<ssv:Real value=\"{}\"/>", num(*r)),
                    Value::Integer(k) => format!("<ssv:Integer value=\"{k}\"/>"),
                    Value::Boolean(b) => format!("<ssv:Boolean value=\"{b}\"/>"),
                    Value::String(s) => format!("<ssv:String value=\"{}\"/>", esc(s)),
                };
                x.push_str(&format!("                  <ssv:Parameter name=\"{}\">{v}</ssv:Parameter>\n", esc(vname)));
            }
            x.push_str("                </ssv:Parameters>\n              </ssv:ParameterSet>\n            </ssd:ParameterValues>\n          </ssd:ParameterBinding>\n        </ssd:ParameterBindings>\n");
        }
        x.push_str("      </ssd:Component>\n");
    }
    x.push_str("    </ssd:Elements>\n");
    if !system.connections.is_empty() {
        x.push_str("    <ssd:Connections>\n");
        for c in &system.connections {
            let (fi, ti) = (&system.instances[c.from.instance].name, &system.instances[c.to.instance].name);
            let (fv, tv) = (&system.variable(&c.from).name, &system.variable(&c.to).name);
            x.push_str(&format!(
                "      <ssd:Connection startElement=\"{}\" startConnector=\"{}\" endElement=\"{}\" endConnector=\"{}\"",
                esc(fi),
                esc(fv),
                esc(ti),
                esc(tv)
            ));
            match c.linear_transformation {
                Some((f, o)) => x.push_str(&format!(
                    "><ssc:LinearTransformation factor=\"{}\" offset=\"{}\"/></ssd:Connection>\n",
                    num(f),
                    num(o)
                )),
                None => x.push_str("/>\n"),
            }
        }
        x.push_str("    </ssd:Connections>\n");
    }
    x.push_str("  </ssd:System>\n");
    if let Some(stop) = stop_time {
        x.push_str(&format!("  <ssd:DefaultExperiment startTime=\"0\" stopTime=\"{}\"/>\n", num(stop)));
    }
    x.push_str("</ssd:SystemStructureDescription>\n");

    let file = std::fs::File::create(path).map_err(io)?;
    let mut zip = zip::ZipWriter::new(file);
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    let zerr = |e: zip::result::ZipError| {
        Error::Import(crate::ImportError::Archive { path: path.to_path_buf(), reason: e.to_string() })
    };
    zip.start_file("SystemStructure.ssd", options).map_err(zerr)?;
    zip.write_all(x.as_bytes()).map_err(io)?;
    // the FMUs stored, not deflated: they are compressed archives already (deflate gains
    // under 1 %), and a stored FMU is read in place by importers that seek (see `unpack`)
    let stored = options.compression_method(zip::CompressionMethod::Stored);
    for (src, file) in &files {
        let fmu = system.instances.iter().find(|i| i.fmu.source() == src.as_path()).map(|i| &i.fmu);
        let bytes = match fmu {
            Some(fmu) => fmu.archive_bytes()?,
            None => std::fs::read(src)
                .map_err(|source| Error::Import(crate::ImportError::Io { path: src.clone(), source }))?,
        };
        zip.start_file(file.as_str(), stored).map_err(zerr)?;
        zip.write_all(&bytes).map_err(io)?;
    }
    zip.finish().map_err(zerr)?;
    Ok(())
}
