//! FMI 2.0 `modelDescription.xml`: types, writer, reader, validation, content GUID.
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
