//! Safe unpacking of `.fmu` / `.ssp` archives into a private temporary folder.
//!
//! Refused: names that escape the folder (`..`, absolute paths, drive letters, NUL),
//! symbolic links, duplicate names, and archive bombs (too many entries, an entry or
//! the total larger than the limits; the actual bytes are counted too, so a lying
//! header does not help). On any error the partly written folder is removed.

use crate::error::{Error, Result};
use std::io::{Read, Write};
use std::path::{Component, Path, PathBuf};

/// Limits of an unpack; raise them for unusually large FMUs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnpackLimits {
    /// Most entries (files and folders).
    pub max_entries: u64,
    /// Largest uncompressed size of one entry, bytes.
    pub max_entry_bytes: u64,
    /// Largest uncompressed size of all entries together, bytes.
    pub max_total_bytes: u64,
}

impl Default for UnpackLimits {
    /// 10,000 entries, 1 GiB per entry, 4 GiB in all.
    fn default() -> Self {
        UnpackLimits { max_entries: 10_000, max_entry_bytes: 1 << 30, max_total_bytes: 4 << 30 }
    }
}

/// The relative path an entry name stands for, or why it is refused.
pub fn safe_relative_path(name: &str) -> std::result::Result<PathBuf, &'static str> {
    if name.contains('\0') {
        return Err("NUL in name");
    }
    if name.starts_with('/') || name.starts_with('\\') {
        return Err("absolute path");
    }
    let bytes = name.as_bytes();
    if bytes.len() >= 2 && bytes[1] == b':' && bytes[0].is_ascii_alphabetic() {
        return Err("absolute path (drive letter)");
    }
    let mut out = PathBuf::new();
    for part in name.split(['/', '\\']) {
        match part {
            "" | "." => {}
            ".." => return Err("path escapes the folder (..)"),
            p => {
                // one plain component each, nothing the OS would reinterpret
                let mut comps = Path::new(p).components();
                match (comps.next(), comps.next()) {
                    (Some(Component::Normal(c)), None) => out.push(c),
                    _ => return Err("unusual path component"),
                }
            }
        }
    }
    if out.as_os_str().is_empty() {
        return Err("empty name");
    }
    Ok(out)
}

/// Unpacks `archive` into a fresh private temporary folder (removed when dropped).
pub fn unpack(archive: &Path, limits: &UnpackLimits) -> Result<tempfile::TempDir> {
    let dir = tempfile::Builder::new()
        .prefix("nigel-cosim-")
        .tempdir()
        .map_err(|source| Error::Io { path: std::env::temp_dir(), source })?;
    unpack_into(archive, dir.path(), limits)?; // on error `dir` is dropped, so removed
    Ok(dir)
}

fn unpack_into(archive: &Path, dest: &Path, limits: &UnpackLimits) -> Result<()> {
    let file = std::fs::File::open(archive).map_err(|source| Error::Io { path: archive.to_path_buf(), source })?;
    let bad = |e: zip::result::ZipError| Error::Archive { path: archive.to_path_buf(), reason: e.to_string() };
    let mut zip = zip::ZipArchive::new(std::io::BufReader::with_capacity(64 * 1024, file)).map_err(bad)?;
    let count = zip.len() as u64;
    if count > limits.max_entries {
        return Err(Error::ArchiveLimit {
            entry: "<number of entries>".into(),
            size: count,
            limit: limits.max_entries,
        });
    }
    // check every header before writing anything
    let mut declared_total = 0u64;
    for i in 0..zip.len() {
        let entry = zip.by_index_raw(i).map_err(bad)?;
        let name = entry.name().to_string();
        safe_relative_path(&name).map_err(|reason| Error::UnsafeEntry { entry: name.clone(), reason })?;
        if let Some(mode) = entry.unix_mode() {
            if mode & 0o170000 == 0o120000 {
                return Err(Error::UnsafeEntry { entry: name, reason: "symbolic link" });
            }
        }
        if entry.size() > limits.max_entry_bytes {
            return Err(Error::ArchiveLimit { entry: name, size: entry.size(), limit: limits.max_entry_bytes });
        }
        declared_total = declared_total.saturating_add(entry.size());
        if declared_total > limits.max_total_bytes {
            return Err(Error::ArchiveLimit {
                entry: "<total>".into(),
                size: declared_total,
                limit: limits.max_total_bytes,
            });
        }
    }
    let mut total = 0u64;
    let mut buffer = vec![0u8; 64 * 1024];
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).map_err(bad)?;
        let name = entry.name().to_string();
        let rel = safe_relative_path(&name).map_err(|reason| Error::UnsafeEntry { entry: name.clone(), reason })?;
        let target = dest.join(&rel);
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| Error::Io { path, source }
        };
        if entry.is_dir() || name.ends_with('/') {
            std::fs::create_dir_all(&target).map_err(io(&target))?;
            continue;
        }
        if let Some(parent) = target.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent))?;
        }
        let mut out = std::fs::OpenOptions::new().write(true).create_new(true).open(&target).map_err(|source| {
            match source.kind() {
                std::io::ErrorKind::AlreadyExists => {
                    Error::UnsafeEntry { entry: name.clone(), reason: "duplicate name in the archive" }
                }
                _ => Error::Io { path: target.clone(), source },
            }
        })?;
        let mut written = 0u64;
        loop {
            let n = entry
                .read(&mut buffer)
                .map_err(|e| Error::Archive { path: archive.to_path_buf(), reason: format!("entry {name:?}: {e}") })?;
            if n == 0 {
                break;
            }
            written += n as u64;
            total += n as u64;
            if written > limits.max_entry_bytes {
                return Err(Error::ArchiveLimit { entry: name, size: written, limit: limits.max_entry_bytes });
            }
            if total > limits.max_total_bytes {
                return Err(Error::ArchiveLimit {
                    entry: "<total>".into(),
                    size: total,
                    limit: limits.max_total_bytes,
                });
            }
            out.write_all(&buffer[..n]).map_err(io(&target))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_names() {
        assert_eq!(safe_relative_path("binaries/linux64/a.so"), Ok(PathBuf::from("binaries/linux64/a.so")));
        assert_eq!(safe_relative_path("./a//b"), Ok(PathBuf::from("a/b")));
        assert_eq!(safe_relative_path("../evil"), Err("path escapes the folder (..)"));
        assert_eq!(safe_relative_path("a/../../evil"), Err("path escapes the folder (..)"));
        assert_eq!(safe_relative_path("/etc/passwd"), Err("absolute path"));
        assert_eq!(safe_relative_path("C:/x"), Err("absolute path (drive letter)"));
        assert_eq!(safe_relative_path("a\\..\\b"), Err("path escapes the folder (..)"));
        assert!(safe_relative_path("").is_err());
    }
}
