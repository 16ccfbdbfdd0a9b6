//! `modelDescription.xml` of FMI 2.0 (the crate root) and FMI 3.0 ([`fmi3`]): types, writer, reader, validation, content GUID.
//!
//! - [`ModelDescription::to_xml`] writes the XML (element order of the XSD, deterministic).
//! - [`ModelDescription::from_xml`] reads it back (or another tool's), refusing with a
//!   typed [`ReadError`].
//! - [`ModelDescription::validate`] lists the [`Problem`]s importers would complain about.
//! - [`ModelDescription::content_guid`] / [`ModelDescription::with_content_guid`] derive
//!   the GUID from the content.
//!
//! All indices (`derivative`, `Unknown::index`, `dependencies`, [`ModelDescription::index_of`],
//! [`ModelDescription::states`]) are 1-based indices into `model_variables`.
//!
//! ```
//! use model_description::ModelDescription;
//!
//! let xml = r#"<fmiModelDescription fmiVersion="2.0" modelName="m" guid="{0}">
//!   <CoSimulation modelIdentifier="m"/>
//!   <ModelVariables>
//!     <ScalarVariable name="k" valueReference="0" causality="parameter" variability="fixed">
//!       <Real start="2"/>
//!     </ScalarVariable>
//!   </ModelVariables>
//!   <ModelStructure/>
//! </fmiModelDescription>"#;
//! let md = ModelDescription::from_xml(xml)?.with_content_guid();
//! assert!(md.validate().is_empty());
//! assert_eq!(md.index_of("k"), Some(1));
//! assert_eq!(ModelDescription::from_xml(&md.to_xml())?, md);
//! # Ok::<(), model_description::ReadError>(())
//! ```

#![warn(missing_docs)]

pub mod fmi3;
pub mod types;
pub use types::*;

mod guid;
mod query;
pub mod read;
pub mod validate;
pub mod write;

pub use read::{parse_xs_double, Position, ReadError};
pub use validate::{is_c_identifier, Problem, Rule};
pub use write::format_f64;
