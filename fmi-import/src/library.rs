//! Loading an FMU's shared library: checked first ([`crate::elf`]), loaded once per
//! distinct binary for the life of the process.

use std::path::Path;
use std::sync::{Arc, Mutex};

use crate::error::{Error, Result};

/// Libraries loaded so far, by the SHA-256 of their bytes. A binary loaded once stays
/// loaded for the life of the process and later imports of the same binary share it:
/// the dynamic loader cannot unload libraries that registered thread-local destructors
/// (every Rust cdylib using std's thread locals), so loading a fresh copy from each new
/// temporary folder would map it again and again (about 90 KiB of resident memory per
/// import of our plant). The cost is bounded by the number of distinct binaries.
static LIBRARIES: std::sync::OnceLock<Mutex<std::collections::HashMap<[u8; 32], Arc<libloading::Library>>>> =
    std::sync::OnceLock::new();

/// Loads the library `so` (errors name `shown`, the library inside the archive, and the
/// loader's message names `relative` instead of the temporary copy).
pub(crate) fn load_library(so: &Path, shown: &Path, relative: &str) -> Result<Arc<libloading::Library>> {
    use sha2::Digest;
    let bytes = std::fs::read(so).map_err(|source| Error::Io { path: shown.to_path_buf(), source })?;
    let key: [u8; 32] = sha2::Sha256::digest(&bytes).into();
    let cache = LIBRARIES.get_or_init(Default::default);
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(lib) = cache.get(&key) {
        return Ok(lib.clone());
    }
    crate::platform::check_library(&bytes)
        .map_err(|reason| Error::LoadLibrary { path: shown.to_path_buf(), reason })?;
    // SAFETY: loading runs the library's initializers; that is what importing an FMU means.
    let library = unsafe { libloading::Library::new(so) }.map_err(|e| Error::LoadLibrary {
        path: shown.to_path_buf(),
        reason: e.to_string().replace(&so.display().to_string(), relative),
    })?;
    let library = Arc::new(library);
    cache.insert(key, library.clone());
    Ok(library)
}

/// Resolves the fmi2 functions of `lib`; a missing required one is an error naming it and
/// `path`.
///
/// # Safety
/// `lib` must be an FMI 2.0 library whose symbols have these C signatures.
pub(crate) unsafe fn load_functions(lib: &libloading::Library, path: &Path) -> Result<crate::c_types::Functions> {
    crate::c_types::Functions::load(lib)
        .map_err(|missing| Error::MissingSymbol { path: path.to_path_buf(), symbol: missing.0 })
}
