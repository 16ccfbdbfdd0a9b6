//! The reader: `modelDescription.xml` text to [`ModelDescription`].
//!
//! Tolerant of attribute order, whitespace, comments, processing instructions, unknown
//! attributes and unknown elements (TypeDefinitions are used only to resolve the
//! `unit`/`min`/`max`/`nominal` of a `declaredType`; VendorAnnotations, Annotations,
//! SourceFiles, DisplayUnits, ... are skipped). Strict about what the standard requires
//! (see [`ReadError`]). Never panics.

use std::collections::HashMap;
use std::fmt;

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use crate::types::*;

/// A place in the input: byte offset plus 1-based line and (byte) column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Position {
    /// 0-based byte offset.
    pub byte: usize,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, counted in bytes.
    pub column: usize,
}

impl Position {
    /// The position of byte offset `byte` in `src` (clamped to its length).
    pub fn in_text(src: &str, byte: usize) -> Position {
        let bytes = src.as_bytes();
        let byte = byte.min(bytes.len());
        let before = &bytes[..byte];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
        Position { byte, line, column: byte - line_start + 1 }
    }
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}, column {}", self.line, self.column)
    }
}

/// Why [`ModelDescription::from_xml`] refused a document. `element` names the element
/// (for variables: `ScalarVariable "name"`, for their type element:
/// `Real of ScalarVariable "name"`), `position` points at its start tag (for
/// [`ReadError::Xml`], at the offending markup).
#[derive(Clone, Debug, PartialEq)]
pub enum ReadError {
    /// Not well-formed XML (syntax error, mismatched end tag, bad escape, duplicate
    /// attribute, second root element, ...).
    Xml {
        /// quick-xml's description of the problem.
        message: String,
        /// Where it is.
        position: Position,
    },
    /// The document ended inside `element`.
    UnexpectedEof {
        /// The innermost element still open.
        element: String,
        /// Its start tag.
        position: Position,
    },
    /// No root element, or the root is not `<fmiModelDescription>`.
    NotAModelDescription {
        /// The root element found, if any.
        found: Option<String>,
        /// Its start tag (or the end of the input).
        position: Position,
    },
    /// A required attribute is absent.
    MissingAttribute {
        /// The element lacking it.
        element: String,
        /// The attribute's name.
        attribute: String,
        /// The element's start tag.
        position: Position,
    },
    /// An attribute that must be a number (or a list of numbers) is not.
    BadNumber {
        /// The element.
        element: String,
        /// The attribute's name.
        attribute: String,
        /// The offending value (for lists: the offending item).
        value: String,
        /// The element's start tag.
        position: Position,
    },
    /// An enumerated attribute (causality, variability, initial, dependenciesKind,
    /// a boolean) has a value outside its enumeration.
    UnknownEnumValue {
        /// The element.
        element: String,
        /// The attribute's name.
        attribute: String,
        /// The offending value (for lists: the offending item).
        value: String,
        /// The element's start tag.
        position: Position,
    },
    /// `fmiVersion` is not the one this reader reads (`"2.0"` for [`ModelDescription::from_xml`],
    /// `"3.x"` for [`crate::fmi3::ModelDescription::from_xml`]).
    UnsupportedFmiVersion {
        /// The value found.
        found: String,
        /// What the reader accepts, e.g. `"2.0"`.
        expected: &'static str,
        /// The root's start tag.
        position: Position,
    },
    /// A ScalarVariable has no `<Real>`, `<Integer>`, `<Boolean>`, `<String>` or
    /// `<Enumeration>` child.
    MissingTypeChild {
        /// The variable's name.
        variable: String,
        /// Its start tag.
        position: Position,
    },
    /// An element the schema does not allow where it is (FMI 3.0: a variable or type
    /// definition element that is not one of the standard's types, a ModelStructure entry
    /// of an unknown kind).
    UnknownElement {
        /// The element's name.
        element: String,
        /// The element it is in.
        parent: String,
        /// Its start tag.
        position: Position,
    },
    /// An element whose attributes contradict each other or the standard (e.g. a
    /// `<Dimension>` with both or neither of `start` and `valueReference`).
    Invalid {
        /// The element.
        element: String,
        /// What is wrong.
        message: String,
        /// Its start tag.
        position: Position,
    },
    /// An element that may occur once occurs again.
    DuplicateElement {
        /// The element's name.
        element: String,
        /// The second occurrence's start tag.
        position: Position,
    },
}

impl ReadError {
    /// Where in the input the problem is.
    pub fn position(&self) -> Position {
        match self {
            ReadError::Xml { position, .. }
            | ReadError::UnexpectedEof { position, .. }
            | ReadError::NotAModelDescription { position, .. }
            | ReadError::MissingAttribute { position, .. }
            | ReadError::BadNumber { position, .. }
            | ReadError::UnknownEnumValue { position, .. }
            | ReadError::UnsupportedFmiVersion { position, .. }
            | ReadError::MissingTypeChild { position, .. }
            | ReadError::UnknownElement { position, .. }
            | ReadError::Invalid { position, .. }
            | ReadError::DuplicateElement { position, .. } => *position,
        }
    }
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReadError::Xml { message, position } => {
                write!(f, "malformed XML at {position}: {message}")
            }
            ReadError::UnexpectedEof { element, position } => {
                write!(f, "document ends inside <{element}> (opened at {position})")
            }
            ReadError::NotAModelDescription { found: Some(name), position } => write!(
                f,
                "root element is <{name}> at {position}, expected <fmiModelDescription>"
            ),
            ReadError::NotAModelDescription { found: None, position } => {
                write!(f, "no root element (expected <fmiModelDescription>), at {position}")
            }
            ReadError::MissingAttribute { element, attribute, position } => {
                write!(f, "{element} at {position}: missing required attribute {attribute}")
            }
            ReadError::BadNumber { element, attribute, value, position } => write!(
                f,
                "{element} at {position}: attribute {attribute}=\"{value}\" is not a valid number"
            ),
            ReadError::UnknownEnumValue { element, attribute, value, position } => write!(
                f,
                "{element} at {position}: attribute {attribute} has unknown value \"{value}\""
            ),
            // FMI 1.0 (and anything but 2.0 and 3.x) is read by neither reader of this crate:
            // the message names both versions that are
            ReadError::UnsupportedFmiVersion { found, expected, position }
                if !found.trim().starts_with("2.") && !found.trim().starts_with("3.") =>
            {
                write!(
                    f,
                    "fmiModelDescription at {position}: fmiVersion=\"{found}\" is not supported \
                     (FMI 2.0 and FMI 3.0 are; this reader reads \"{expected}\")"
                )
            }
            ReadError::UnsupportedFmiVersion { found, expected, position } => {
                // the FMI 3.0 reader takes the revisions and later minor versions too
                let also = if expected.starts_with('3') {
                    ", a revision such as \"3.0.2\" or a later minor version such as \"3.1\", read as FMI 3.0"
                } else {
                    ""
                };
                write!(
                    f,
                    "fmiModelDescription at {position}: fmiVersion=\"{found}\" is not supported (only \"{expected}\"{also})"
                )
            }
            ReadError::MissingTypeChild { variable, position } => write!(
                f,
                "ScalarVariable \"{variable}\" at {position}: no type element (<Real>, <Integer>, <Boolean>, <String> or <Enumeration>)"
            ),
            ReadError::UnknownElement { element, parent, position } => {
                write!(f, "unknown element <{element}> in <{parent}> at {position}")
            }
            ReadError::Invalid { element, message, position } => write!(f, "{element} at {position}: {message}"),
            ReadError::DuplicateElement { element, position } => {
                write!(f, "duplicate <{element}> at {position}")
            }
        }
    }
}

impl std::error::Error for ReadError {}

// ---------------------------------------------------------------------------------------
// A tiny element tree (depth-limited: nothing of FMI 2.0 we read is deeper than 5,
// the enumeration items of TypeDefinitions/SimpleType/Enumeration/Item).

const MAX_DEPTH: usize = 5;

pub(crate) struct Node {
    pub(crate) name: String,
    pub(crate) attrs: Vec<(String, String)>,
    pub(crate) pos: usize,
    pub(crate) children: Vec<Node>,
}

impl Node {
    pub(crate) fn get(&self, key: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }
}

fn xml_err(src: &str, e: impl fmt::Display, pos: u64) -> ReadError {
    ReadError::Xml { message: e.to_string(), position: Position::in_text(src, pos as usize) }
}

/// Start of the tag that begins at or after `from` (the first `<`).
fn tag_start(src: &str, from: usize) -> usize {
    let bytes = src.as_bytes();
    let from = from.min(bytes.len());
    bytes[from..].iter().position(|&b| b == b'<').map_or(from, |p| from + p)
}

fn make_node(src: &str, reader: &Reader<&[u8]>, e: &BytesStart<'_>, pos: usize) -> Result<Node, ReadError> {
    let name = std::str::from_utf8(e.name().as_ref()).map_err(|err| xml_err(src, err, pos as u64))?.to_string();
    let mut attrs = Vec::new();
    // quick-xml's own duplicate check compares each attribute with all before it
    // (quadratic: 160,000 attributes took 21 s); a hash set does it in linear time
    let mut keys = std::collections::HashSet::new();
    for a in e.attributes().with_checks(false) {
        let a = a.map_err(|err| xml_err(src, err, pos as u64))?;
        let key = std::str::from_utf8(a.key.as_ref()).map_err(|err| xml_err(src, err, pos as u64))?;
        if !keys.insert(key.to_string()) {
            return Err(xml_err(src, format!("attribute {key} repeated in <{name}>"), pos as u64));
        }
        let value = a
            .decode_and_unescape_value(reader.decoder())
            .map_err(|err| xml_err(src, format!("attribute {key} of <{name}>: {err}"), pos as u64))?;
        attrs.push((key.to_string(), value.into_owned()));
    }
    Ok(Node { name, attrs, pos, children: Vec::new() })
}

pub(crate) fn parse_tree(src: &str) -> Result<Node, ReadError> {
    let mut reader = Reader::from_str(src);
    reader.config_mut().trim_text(true);
    // Open elements: the stored ones (depth <= MAX_DEPTH), and name and position of
    // deeper ones (kept only for the end-of-input message).
    let mut stack: Vec<Node> = Vec::new();
    let mut deeper: Vec<(String, usize)> = Vec::new();
    let mut root: Option<Node> = None;
    loop {
        let before = reader.buffer_position() as usize;
        let ev = reader.read_event().map_err(|e| xml_err(src, e, reader.error_position()))?;
        match ev {
            Event::Start(_) | Event::Empty(_) if root.is_some() && stack.is_empty() => {
                let pos = tag_start(src, before);
                return Err(ReadError::Xml {
                    message: "a second root element".to_string(),
                    position: Position::in_text(src, pos),
                });
            }
            Event::Start(e) => {
                let pos = tag_start(src, before);
                if stack.len() < MAX_DEPTH && deeper.is_empty() {
                    stack.push(make_node(src, &reader, &e, pos)?);
                } else {
                    // Still check its attributes for well-formedness.
                    let node = make_node(src, &reader, &e, pos)?;
                    deeper.push((node.name, pos));
                }
            }
            Event::Empty(e) => {
                let pos = tag_start(src, before);
                let node = make_node(src, &reader, &e, pos)?;
                if stack.len() < MAX_DEPTH && deeper.is_empty() {
                    match stack.last_mut() {
                        Some(parent) => parent.children.push(node),
                        None => root = Some(node),
                    }
                }
            }
            Event::End(_) if deeper.pop().is_some() => {}
            Event::End(_) => {
                if let Some(node) = stack.pop() {
                    match stack.last_mut() {
                        Some(parent) => parent.children.push(node),
                        None => root = Some(node),
                    }
                } else {
                    // check_end_names makes quick-xml report this itself; be safe anyway.
                    return Err(ReadError::Xml {
                        message: "end tag without start tag".to_string(),
                        position: Position::in_text(src, tag_start(src, before)),
                    });
                }
            }
            Event::Eof => {
                if let Some((name, pos)) = deeper.pop() {
                    return Err(ReadError::UnexpectedEof { element: name, position: Position::in_text(src, pos) });
                }
                if let Some(open) = stack.last() {
                    return Err(ReadError::UnexpectedEof {
                        element: open.name.clone(),
                        position: Position::in_text(src, open.pos),
                    });
                }
                return root.ok_or(ReadError::NotAModelDescription {
                    found: None,
                    position: Position::in_text(src, src.len()),
                });
            }
            // Text, CDATA, comments, declarations, processing instructions, DOCTYPE.
            _ => {}
        }
    }
}

// ---------------------------------------------------------------------------------------
// Attribute access with typed errors.

pub(crate) struct Ctx<'a> {
    pub(crate) src: &'a str,
}

impl Ctx<'_> {
    pub(crate) fn pos(&self, n: &Node) -> Position {
        Position::in_text(self.src, n.pos)
    }

    pub(crate) fn req<'n>(&self, n: &'n Node, label: &str, key: &str) -> Result<&'n str, ReadError> {
        n.get(key).ok_or_else(|| ReadError::MissingAttribute {
            element: label.to_string(),
            attribute: key.to_string(),
            position: self.pos(n),
        })
    }

    pub(crate) fn bad_number(&self, n: &Node, label: &str, key: &str, value: &str) -> ReadError {
        ReadError::BadNumber {
            element: label.to_string(),
            attribute: key.to_string(),
            value: value.to_string(),
            position: self.pos(n),
        }
    }

    pub(crate) fn bad_enum(&self, n: &Node, label: &str, key: &str, value: &str) -> ReadError {
        ReadError::UnknownEnumValue {
            element: label.to_string(),
            attribute: key.to_string(),
            value: value.to_string(),
            position: self.pos(n),
        }
    }

    pub(crate) fn f64_of(&self, n: &Node, label: &str, key: &str, value: &str) -> Result<f64, ReadError> {
        parse_xs_double(value).ok_or_else(|| self.bad_number(n, label, key, value))
    }

    pub(crate) fn opt_f64(&self, n: &Node, label: &str, key: &str) -> Result<Option<f64>, ReadError> {
        n.get(key).map(|v| self.f64_of(n, label, key, v)).transpose()
    }

    pub(crate) fn opt_u32(&self, n: &Node, label: &str, key: &str) -> Result<Option<u32>, ReadError> {
        n.get(key).map(|v| v.trim().parse::<u32>().map_err(|_| self.bad_number(n, label, key, v))).transpose()
    }

    pub(crate) fn req_u32(&self, n: &Node, label: &str, key: &str) -> Result<u32, ReadError> {
        let v = self.req(n, label, key)?;
        v.trim().parse::<u32>().map_err(|_| self.bad_number(n, label, key, v))
    }

    pub(crate) fn opt_i32(&self, n: &Node, label: &str, key: &str) -> Result<Option<i32>, ReadError> {
        n.get(key).map(|v| v.trim().parse::<i32>().map_err(|_| self.bad_number(n, label, key, v))).transpose()
    }

    pub(crate) fn opt_bool(&self, n: &Node, label: &str, key: &str) -> Result<Option<bool>, ReadError> {
        n.get(key)
            .map(|v| match v.trim() {
                "true" | "1" => Ok(true),
                "false" | "0" => Ok(false),
                _ => Err(self.bad_enum(n, label, key, v)),
            })
            .transpose()
    }

    pub(crate) fn flag(&self, n: &Node, label: &str, key: &str) -> Result<bool, ReadError> {
        Ok(self.opt_bool(n, label, key)?.unwrap_or(false))
    }

    pub(crate) fn opt_enum<T>(
        &self,
        n: &Node,
        label: &str,
        key: &str,
        parse: fn(&str) -> Option<T>,
    ) -> Result<Option<T>, ReadError> {
        n.get(key).map(|v| parse(v.trim()).ok_or_else(|| self.bad_enum(n, label, key, v))).transpose()
    }

    pub(crate) fn opt_string(n: &Node, key: &str) -> Option<String> {
        n.get(key).map(str::to_string)
    }

    /// A whitespace-separated list of `u32` (`dependencies`, `clocks`), `None` when absent.
    pub(crate) fn u32_list(&self, n: &Node, label: &str, key: &str) -> Result<Option<Vec<u32>>, ReadError> {
        n.get(key)
            .map(|s| {
                s.split_ascii_whitespace()
                    .map(|tok| tok.parse::<u32>().map_err(|_| self.bad_number(n, label, key, tok)))
                    .collect::<Result<Vec<u32>, ReadError>>()
            })
            .transpose()
    }

    /// `dependenciesKind`: a whitespace-separated list of [`DependencyKind`]s, `None` when absent.
    pub(crate) fn dependency_kinds(&self, n: &Node, label: &str) -> Result<Option<Vec<DependencyKind>>, ReadError> {
        n.get("dependenciesKind")
            .map(|s| {
                s.split_ascii_whitespace()
                    .map(|tok| {
                        DependencyKind::parse(tok).ok_or_else(|| self.bad_enum(n, label, "dependenciesKind", tok))
                    })
                    .collect::<Result<Vec<DependencyKind>, ReadError>>()
            })
            .transpose()
    }
}

/// Parses an `xs:double` (surrounding whitespace allowed; `INF`, `+INF`, `-INF`, `NaN`,
/// and whatever Rust's `f64` parser accepts).
pub fn parse_xs_double(s: &str) -> Option<f64> {
    let t = s.trim_matches(|c| matches!(c, ' ' | '\t' | '\n' | '\r'));
    match t {
        "INF" | "+INF" => Some(f64::INFINITY),
        "-INF" => Some(f64::NEG_INFINITY),
        "NaN" => Some(f64::NAN),
        _ => t.parse::<f64>().ok(),
    }
}

/// Attributes a `<SimpleType>` passes on to variables declaring it as `declaredType`.
#[derive(Default, Clone)]
struct TypeDefaults {
    unit: Option<String>,
    min: Option<String>,
    max: Option<String>,
    nominal: Option<String>,
}

pub(crate) fn once<'a>(ctx: &Ctx, slot: &mut Option<&'a Node>, n: &'a Node) -> Result<(), ReadError> {
    if slot.is_some() {
        return Err(ReadError::DuplicateElement { element: n.name.clone(), position: ctx.pos(n) });
    }
    *slot = Some(n);
    Ok(())
}

/// The children of `<fmiModelDescription>` that FMI 2.0 and 3.0 share, in the schemas' order.
pub(crate) const DOCUMENT_ELEMENTS: [&str; 8] = [
    "ModelExchange",
    "CoSimulation",
    "UnitDefinitions",
    "TypeDefinitions",
    "LogCategories",
    "DefaultExperiment",
    "ModelVariables",
    "ModelStructure",
];

/// The children of `parent` named in `names`, in that order, each at most once (a second
/// one is [`ReadError::DuplicateElement`]); children of other names are skipped.
pub(crate) fn children_once<'n, const N: usize>(
    ctx: &Ctx,
    parent: &'n Node,
    names: [&str; N],
) -> Result<[Option<&'n Node>; N], ReadError> {
    let mut slots = [None; N];
    for c in &parent.children {
        if let Some(i) = names.iter().position(|name| *name == c.name) {
            once(ctx, &mut slots[i], c)?;
        }
    }
    Ok(slots)
}

/// Parses `xml` into its `<fmiModelDescription>` root and returns it with its `fmiVersion`
/// as written, refusing another root, and a version that `accepts` refuses (given without
/// surrounding white space) with [`ReadError::UnsupportedFmiVersion`] naming `expected`.
pub(crate) fn read_root<'x>(
    xml: &'x str,
    expected: &'static str,
    accepts: fn(&str) -> bool,
) -> Result<(Node, Ctx<'x>, String), ReadError> {
    let root = parse_tree(xml)?;
    let ctx = Ctx { src: xml };
    check_root(&ctx, &root)?;
    let fmi_version = ctx.req(&root, "fmiModelDescription", "fmiVersion")?.to_string();
    if !accepts(fmi_version.trim()) {
        return Err(ReadError::UnsupportedFmiVersion { found: fmi_version, expected, position: ctx.pos(&root) });
    }
    Ok((root, ctx, fmi_version))
}

/// The struct literal `$interface { $fields }` of an FMI 2.0 `<ModelExchange>` or
/// `<CoSimulation>` element `$n` (labelled `$l` in errors): the attributes both elements
/// have, read in the schema's order around the element's own `$fields`.
macro_rules! fmi2_interface {
    ($interface:ident, $ctx:expr, $n:expr, $l:expr, { $($fields:tt)* }) => {
        $interface {
            model_identifier: $ctx.req($n, $l, "modelIdentifier")?.to_string(),
            needs_execution_tool: $ctx.flag($n, $l, "needsExecutionTool")?,
            $($fields)*
            can_be_instantiated_only_once_per_process: $ctx.flag($n, $l, "canBeInstantiatedOnlyOncePerProcess")?,
            can_not_use_memory_management_functions: $ctx.flag($n, $l, "canNotUseMemoryManagementFunctions")?,
            can_get_and_set_fmu_state: $ctx.flag($n, $l, "canGetAndSetFMUstate")?,
            can_serialize_fmu_state: $ctx.flag($n, $l, "canSerializeFMUstate")?,
            provides_directional_derivative: $ctx.flag($n, $l, "providesDirectionalDerivative")?,
        }
    };
}

/// The struct literal `$md { $fields }` with the optional attributes of
/// `<fmiModelDescription>` that FMI 2.0 and 3.0 share read from the root `$root` (a macro:
/// the two generations' descriptions are different types with these fields).
macro_rules! with_document_attributes {
    ($md:ident, $root:expr, { $($fields:tt)* }) => {
        $md {
            description: Ctx::opt_string($root, "description"),
            author: Ctx::opt_string($root, "author"),
            version: Ctx::opt_string($root, "version"),
            copyright: Ctx::opt_string($root, "copyright"),
            license: Ctx::opt_string($root, "license"),
            generation_tool: Ctx::opt_string($root, "generationTool"),
            generation_date_and_time: Ctx::opt_string($root, "generationDateAndTime"),
            variable_naming_convention: Ctx::opt_string($root, "variableNamingConvention"),
            $($fields)*
        }
    };
}
pub(crate) use with_document_attributes;

/// Refuses a document whose root is not `<fmiModelDescription>`.
pub(crate) fn check_root(ctx: &Ctx, root: &Node) -> Result<(), ReadError> {
    if root.name != "fmiModelDescription" {
        return Err(ReadError::NotAModelDescription { found: Some(root.name.clone()), position: ctx.pos(root) });
    }
    Ok(())
}

/// A `<Unit>` of `<UnitDefinitions>` with its optional `<BaseUnit>` (at most one;
/// exponents default to 0, `factor` to 1, `offset` to 0), the same in FMI 2.0 and 3.0.
pub(crate) fn read_unit(ctx: &Ctx, u: &Node) -> Result<Unit, ReadError> {
    let name = ctx.req(u, "Unit", "name")?.to_string();
    let ul = format!("Unit \"{name}\"");
    let mut base_node = None;
    for b in u.children.iter().filter(|c| c.name == "BaseUnit") {
        once(ctx, &mut base_node, b)?;
    }
    let base_unit = base_node
        .map(|b| -> Result<BaseUnit, ReadError> {
            let bl = format!("BaseUnit of {ul}");
            let e = |k: &str| -> Result<i32, ReadError> { Ok(ctx.opt_i32(b, &bl, k)?.unwrap_or(0)) };
            Ok(BaseUnit {
                kg: e("kg")?,
                m: e("m")?,
                s: e("s")?,
                a: e("A")?,
                k: e("K")?,
                mol: e("mol")?,
                cd: e("cd")?,
                rad: e("rad")?,
                factor: ctx.opt_f64(b, &bl, "factor")?.unwrap_or(1.0),
                offset: ctx.opt_f64(b, &bl, "offset")?.unwrap_or(0.0),
            })
        })
        .transpose()?;
    Ok(Unit { name, base_unit })
}

/// The `<Unit>`s of `<UnitDefinitions>` (none when the element is absent).
pub(crate) fn read_units(ctx: &Ctx, units: Option<&Node>) -> Result<Vec<Unit>, ReadError> {
    let Some(units) = units else { return Ok(Vec::new()) };
    units.children.iter().filter(|c| c.name == "Unit").map(|u| read_unit(ctx, u)).collect()
}

/// The `<Category>`s of `<LogCategories>` (none when the element is absent).
pub(crate) fn read_log_categories(ctx: &Ctx, logs: Option<&Node>) -> Result<Vec<LogCategory>, ReadError> {
    let Some(logs) = logs else { return Ok(Vec::new()) };
    logs.children
        .iter()
        .filter(|c| c.name == "Category")
        .map(|c| -> Result<LogCategory, ReadError> {
            Ok(LogCategory {
                name: ctx.req(c, "Category", "name")?.to_string(),
                description: Ctx::opt_string(c, "description"),
            })
        })
        .collect()
}

/// `<DefaultExperiment>`, if present.
pub(crate) fn read_default_experiment(ctx: &Ctx, exp: Option<&Node>) -> Result<Option<DefaultExperiment>, ReadError> {
    exp.map(|n| -> Result<DefaultExperiment, ReadError> {
        let l = "DefaultExperiment";
        Ok(DefaultExperiment {
            start_time: ctx.opt_f64(n, l, "startTime")?,
            stop_time: ctx.opt_f64(n, l, "stopTime")?,
            tolerance: ctx.opt_f64(n, l, "tolerance")?,
            step_size: ctx.opt_f64(n, l, "stepSize")?,
        })
    })
    .transpose()
}

impl ModelDescription {
    /// Reads a `modelDescription.xml`. See [`ReadError`] for what is refused; unknown
    /// elements and attributes are skipped. `<Enumeration>` variables are read as
    /// `Integer`; a `declaredType`'s `unit`, `min`, `max` and `nominal` are copied onto
    /// variables that do not set them.
    pub fn from_xml(xml: &str) -> Result<ModelDescription, ReadError> {
        let (root, ctx, fmi_version) = read_root(xml, "2.0", |v| v == "2.0")?;
        let label = "fmiModelDescription";
        let model_name = ctx.req(&root, label, "modelName")?.to_string();
        let guid = ctx.req(&root, label, "guid")?.to_string();
        let number_of_event_indicators = ctx.opt_u32(&root, label, "numberOfEventIndicators")?.unwrap_or(0);

        // VendorAnnotations and anything unknown are skipped.
        let [me_node, cs_node, units_node, types_node, logs_node, exp_node, vars_node, struct_node] =
            children_once(&ctx, &root, DOCUMENT_ELEMENTS)?;

        let model_exchange = me_node
            .map(|n| -> Result<ModelExchange, ReadError> {
                let l = "ModelExchange";
                Ok(fmi2_interface!(ModelExchange, ctx, n, l, {
                    completed_integrator_step_not_needed: ctx.flag(n, l, "completedIntegratorStepNotNeeded")?,
                }))
            })
            .transpose()?;

        let co_simulation = cs_node
            .map(|n| -> Result<CoSimulation, ReadError> {
                let l = "CoSimulation";
                Ok(fmi2_interface!(CoSimulation, ctx, n, l, {
                    can_handle_variable_communication_step_size: ctx.flag(
                        n,
                        l,
                        "canHandleVariableCommunicationStepSize",
                    )?,
                    can_interpolate_inputs: ctx.flag(n, l, "canInterpolateInputs")?,
                    max_output_derivative_order: ctx.opt_u32(n, l, "maxOutputDerivativeOrder")?.unwrap_or(0),
                    can_run_asynchronuously: ctx.flag(n, l, "canRunAsynchronuously")?,
                }))
            })
            .transpose()?;

        let unit_definitions = read_units(&ctx, units_node)?;

        // declaredType defaults (raw strings, parsed in the variable's context).
        let mut type_defaults: HashMap<String, TypeDefaults> = HashMap::new();
        if let Some(types) = types_node {
            for t in types.children.iter().filter(|c| c.name == "SimpleType") {
                let Some(name) = t.get("name") else { continue };
                if let Some(inner) = t.children.iter().find(|c| c.name == "Real" || c.name == "Integer") {
                    type_defaults.insert(
                        name.to_string(),
                        TypeDefaults {
                            unit: Ctx::opt_string(inner, "unit"),
                            min: Ctx::opt_string(inner, "min"),
                            max: Ctx::opt_string(inner, "max"),
                            nominal: Ctx::opt_string(inner, "nominal"),
                        },
                    );
                }
            }
        }

        let mut type_definitions = Vec::new();
        if let Some(types) = types_node {
            for t in types.children.iter().filter(|c| c.name == "SimpleType") {
                let Some(e) = t.children.iter().find(|c| c.name == "Enumeration") else { continue };
                let tl = "Item of Enumeration";
                let mut items = Vec::new();
                for item in e.children.iter().filter(|c| c.name == "Item") {
                    items.push(EnumerationItem {
                        name: ctx.req(item, tl, "name")?.to_string(),
                        value: {
                            let text = ctx.req(item, tl, "value")?;
                            text.trim().parse::<i32>().map_err(|_| ctx.bad_number(item, tl, "value", text))?
                        },
                        description: Ctx::opt_string(item, "description"),
                    });
                }
                type_definitions.push(EnumerationType {
                    name: ctx.req(t, "SimpleType", "name")?.to_string(),
                    description: Ctx::opt_string(t, "description"),
                    items,
                });
            }
        }

        let log_categories = read_log_categories(&ctx, logs_node)?;
        let default_experiment = read_default_experiment(&ctx, exp_node)?;

        let mut model_variables = Vec::new();
        if let Some(vars) = vars_node {
            for v in vars.children.iter().filter(|c| c.name == "ScalarVariable") {
                model_variables.push(read_variable(&ctx, v, &type_defaults)?);
            }
        }

        let mut model_structure = ModelStructure::default();
        if let Some(ms) = struct_node {
            let [outs, ders, inits] = children_once(&ctx, ms, ["Outputs", "Derivatives", "InitialUnknowns"])?;
            let read_list = |n: Option<&Node>| -> Result<Vec<Unknown>, ReadError> {
                let Some(n) = n else { return Ok(Vec::new()) };
                n.children.iter().filter(|c| c.name == "Unknown").map(|u| read_unknown(&ctx, u, &n.name)).collect()
            };
            model_structure.outputs = read_list(outs)?;
            model_structure.derivatives = read_list(ders)?;
            model_structure.initial_unknowns = read_list(inits)?;
        }

        Ok(with_document_attributes!(ModelDescription, &root, {
            fmi_version,
            model_name,
            guid,
            number_of_event_indicators,
            model_exchange,
            co_simulation,
            unit_definitions,
            type_definitions,
            log_categories,
            default_experiment,
            model_variables,
            model_structure,
        }))
    }
}

fn read_variable(
    ctx: &Ctx,
    v: &Node,
    type_defaults: &HashMap<String, TypeDefaults>,
) -> Result<ScalarVariable, ReadError> {
    let name = ctx.req(v, "ScalarVariable", "name")?.to_string();
    let l = format!("ScalarVariable \"{name}\"");
    let value_reference = ctx.req_u32(v, &l, "valueReference")?;
    let causality = ctx.opt_enum(v, &l, "causality", Causality::parse)?.unwrap_or(Causality::Local);
    let variability = ctx.opt_enum(v, &l, "variability", Variability::parse)?.unwrap_or(Variability::Continuous);
    let initial = ctx.opt_enum(v, &l, "initial", Initial::parse)?;

    let Some(t) = v
        .children
        .iter()
        .find(|c| matches!(c.name.as_str(), "Real" | "Integer" | "Boolean" | "String" | "Enumeration"))
    else {
        return Err(ReadError::MissingTypeChild { variable: name, position: ctx.pos(v) });
    };
    let tl = format!("{} of {l}", t.name);
    let defaults = t.get("declaredType").and_then(|d| type_defaults.get(d)).cloned().unwrap_or_default();
    // The variable's own attribute, else the declared type's.
    let attr = |key: &str, inherited: &Option<String>| -> Option<String> {
        t.get(key).map(str::to_string).or_else(|| inherited.clone())
    };
    let f64_attr = |key: &str, inherited: &Option<String>| -> Result<Option<f64>, ReadError> {
        attr(key, inherited).map(|s| ctx.f64_of(t, &tl, key, &s)).transpose()
    };
    let i32_attr = |key: &str, inherited: &Option<String>| -> Result<Option<i32>, ReadError> {
        attr(key, inherited).map(|s| s.trim().parse::<i32>().map_err(|_| ctx.bad_number(t, &tl, key, &s))).transpose()
    };

    let variable_type = match t.name.as_str() {
        "Real" => VariableType::Real {
            start: ctx.opt_f64(t, &tl, "start")?,
            unit: attr("unit", &defaults.unit),
            derivative: ctx.opt_u32(t, &tl, "derivative")?,
            min: f64_attr("min", &defaults.min)?,
            max: f64_attr("max", &defaults.max)?,
            nominal: f64_attr("nominal", &defaults.nominal)?,
        },
        "Integer" => VariableType::Integer {
            start: ctx.opt_i32(t, &tl, "start")?,
            min: i32_attr("min", &defaults.min)?,
            max: i32_attr("max", &defaults.max)?,
        },
        "Enumeration" => VariableType::Enumeration {
            declared_type: ctx.req(t, &tl, "declaredType")?.to_string(),
            start: ctx.opt_i32(t, &tl, "start")?,
            min: ctx.opt_i32(t, &tl, "min")?,
            max: ctx.opt_i32(t, &tl, "max")?,
        },
        "Boolean" => VariableType::Boolean { start: ctx.opt_bool(t, &tl, "start")? },
        _ => VariableType::String { start: Ctx::opt_string(t, "start") },
    };

    Ok(ScalarVariable {
        name,
        value_reference,
        description: Ctx::opt_string(v, "description"),
        causality,
        variability,
        initial,
        variable_type,
    })
}

fn read_unknown(ctx: &Ctx, u: &Node, list: &str) -> Result<Unknown, ReadError> {
    let l = format!("Unknown of {list}");
    let index = ctx.req_u32(u, &l, "index")?;
    let dependencies = ctx.u32_list(u, &l, "dependencies")?;
    let dependencies_kind = ctx.dependency_kinds(u, &l)?;
    Ok(Unknown { index, dependencies, dependencies_kind })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_are_one_based_lines_and_columns() {
        let s = "ab\ncd\n\nef";
        assert_eq!(Position::in_text(s, 0), Position { byte: 0, line: 1, column: 1 });
        assert_eq!(Position::in_text(s, 4), Position { byte: 4, line: 2, column: 2 });
        assert_eq!(Position::in_text(s, 7), Position { byte: 7, line: 4, column: 1 });
        assert_eq!(Position::in_text(s, 999).byte, s.len());
        assert_eq!(Position::in_text(s, 4).to_string(), "line 2, column 2");
    }

    #[test]
    fn xs_double_parsing() {
        assert_eq!(parse_xs_double("\n 1e3\t"), Some(1000.0));
        assert_eq!(parse_xs_double("-INF"), Some(f64::NEG_INFINITY));
        assert_eq!(parse_xs_double(""), None);
        assert_eq!(parse_xs_double("1 2"), None);
    }

    #[test]
    fn tree_is_depth_limited() {
        let t = parse_tree("<a><b><c><d><e><f/></e></d></c></b></a>").unwrap();
        let e = &t.children[0].children[0].children[0].children[0];
        assert_eq!(e.name, "e");
        assert!(e.children.is_empty());
    }

    #[test]
    fn control_characters_round_trip_through_char_refs() {
        let mut md =
            ModelDescription::from_xml(r#"<fmiModelDescription fmiVersion="2.0" modelName="m" guid="g"/>"#).unwrap();
        md.description = Some("a\u{1}b\rc\nd\te".into());
        let xml = md.to_xml();
        assert!(xml.contains("a&#1;b&#13;c&#10;d&#9;e"), "{xml}");
        assert_eq!(ModelDescription::from_xml(&xml).unwrap().description, md.description);
    }
}
