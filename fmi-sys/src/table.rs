//! What both generations' function tables share: the macro that makes, from one list of
//! rows (field, C type name, symbol, part of the standard, signature), the C function
//! types, the table of function pointers, the list of symbols with their parts, the
//! loader and the lookup by name (also as [`FunctionTable`]); the error of a missing
//! required symbol; and the macro
//! of a C status enum with its classifier of raw values.

/// A symbol the loader required and the library does not export.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MissingSymbol(pub &'static str);

impl std::fmt::Display for MissingSymbol {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the library does not export {}", self.0)
    }
}

impl std::error::Error for MissingSymbol {}

/// What both generations' function tables answer alike (for code generic over the
/// generation).
pub trait FunctionTable {
    /// Whether the library exports `symbol`; false for a name that is not a function of
    /// the table's generation.
    fn has(&self, symbol: &str) -> bool;
}

/// One generation's function table: `core` rows are plain function pointers the loader
/// requires, `optional` rows are `Option`s (`None`: the library does not export it).
/// `$types_doc` documents the module of C types, `$table_doc` the table.
macro_rules! function_table {
    ($(#[$types_doc:meta])* mod types;
     $(#[$table_doc:meta])* pub struct $table:ident: $part:ident, $count:literal symbols of $gen:literal;
     core { $($cf:ident : $cs:ident = $cn:literal, $cp:ident => fn($($ca:ty),*) $(-> $cr:ty)?;)* }
     optional { $($of:ident : $os:ident = $on:literal, $op:ident => fn($($oa:ty),*) $(-> $or:ty)?;)* }) => {
        $(#[$types_doc])*
        pub mod types {
            use super::*;
            $(#[doc = concat!("`", stringify!($cs), "`.")]
              pub type $cs = unsafe extern "C" fn($($ca),*) $(-> $cr)?;)*
            $(#[doc = concat!("`", stringify!($os), "`.")]
              pub type $os = unsafe extern "C" fn($($oa),*) $(-> $or)?;)*
        }

        $(#[$table_doc])*
        #[derive(Clone, Copy, Debug)]
        pub struct $table {
            $(#[doc = concat!("`", $cn, "`.")] pub $cf: types::$cs,)*
            $(#[doc = concat!("`", $on, "`.")] pub $of: Option<types::$os>,)*
        }

        #[doc = concat!("Every symbol of ", $gen, " with the part it belongs to, in the order ",
                        "of the table: the core ones first.")]
        pub const SYMBOLS: [(&str, $part); $count] = [
            $(($cn, $part::$cp),)*
            $(($on, $part::$op),)*
        ];

        impl $table {
            /// Resolves the symbols in `library`: the core ones must be there (the first
            /// absent one is the error), the others are `None` when absent.
            ///
            /// # Safety
            #[doc = concat!("`library` must be an ", $gen, " library: each exported symbol of ",
                            "the table has the C signature of the ", $gen, " headers. The ",
                            "pointers are valid while the library stays loaded.")]
            #[cfg(feature = "import")]
            pub unsafe fn load(library: &libloading::Library) -> Result<$table, MissingSymbol> {
                Ok($table {
                    $($cf: *library
                        .get::<types::$cs>(concat!($cn, "\0").as_bytes())
                        .map_err(|_| MissingSymbol($cn))?,)*
                    $($of: library
                        .get::<types::$os>(concat!($on, "\0").as_bytes())
                        .ok()
                        .map(|s| *s),)*
                })
            }

            #[doc = concat!("Whether the library exports `symbol`; false for a name that is ",
                            "not an ", $gen, " function.")]
            pub fn has(&self, symbol: &str) -> bool {
                match symbol {
                    $($cn => true,)*
                    $($on => self.$of.is_some(),)*
                    _ => false,
                }
            }
        }

        impl crate::table::FunctionTable for $table {
            fn has(&self, symbol: &str) -> bool {
                $table::has(self, symbol)
            }
        }

        #[doc = concat!("The symbols of one part of ", $gen, ".")]
        pub fn symbols_of(part: $part) -> impl Iterator<Item = &'static str> {
            SYMBOLS.iter().filter(move |(_, p)| *p == part).map(|(s, _)| *s)
        }

        #[cfg(test)]
        mod table_tests {
            use super::*;

            #[test]
            fn every_symbol_is_listed_once() {
                let mut names: Vec<&str> = SYMBOLS.iter().map(|(s, _)| *s).collect();
                names.sort();
                names.dedup();
                assert_eq!(names.len(), $count);
            }

            /// A shared library that is no FMU: the first core symbol is the error.
            #[cfg(feature = "import")]
            #[test]
            fn a_library_without_the_core_functions_is_refused_naming_the_first() {
                // SAFETY: the C library's initializers already ran in this process.
                let libc = unsafe { libloading::Library::new("libc.so.6") }.unwrap();
                let e = unsafe { $table::load(&libc) }.unwrap_err();
                let first = [$($cn),*][0];
                assert_eq!(e, MissingSymbol(first));
                assert_eq!(e.to_string(), format!("the library does not export {first}"));
            }
        }
    };
}

/// A status enum as an FMU returns it (same ABI as the C enum, an `int`) with
/// `from_raw`, the classifier of the raw `int` an importer receives.
macro_rules! status_enum {
    ($(#[$doc:meta])* $name:ident, $raw:ident { $($variant:ident = $value:literal,)* }) => {
        $(#[$doc])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
        pub enum $name {
            $($variant = $value,)*
        }

        impl $name {
            #[doc = concat!("The status a raw value stands for; `None` for a value outside `",
                            stringify!($raw), "`.")]
            pub fn from_raw(raw: $raw) -> Option<$name> {
                Some(match raw {
                    $($value => $name::$variant,)*
                    _ => return None,
                })
            }
        }
    };
}

pub(crate) use function_table;
pub(crate) use status_enum;
