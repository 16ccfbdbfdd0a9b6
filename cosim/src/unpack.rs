//! Safe unpacking of `.fmu` / `.ssp` archives into a private temporary folder.
//!
//! Refused: names that escape the folder (`..`, absolute paths, drive letters, NUL),
//! symbolic links, duplicate names, and archive bombs: too many entries, an entry or the
//! total larger than the limits, an entry that inflates more than `max_ratio` times its
//! compressed size. Every limit is checked on the sizes the headers declare before
//! anything is written; while inflating, an entry that yields more bytes than its header
//! declares is refused at once (so a lying header gets at most one buffer of 64 KiB past
//! its declared size written). On any error the partly written folder is removed.

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
    /// Largest ratio of uncompressed to compressed size of an entry, for entries larger
    /// than [`UnpackLimits::RATIO_FREE_BYTES`] (below that a high ratio costs nothing).
    pub max_ratio: u64,
    /// Largest `modelDescription.xml` (or `SystemStructure.ssd`, `.ssv`) read, bytes:
    /// reading holds the text and its element tree in memory, about 12 times its size.
    pub max_xml_bytes: u64,
}

impl UnpackLimits {
    /// Entries up to this uncompressed size are not checked for their ratio (1 MiB).
    pub const RATIO_FREE_BYTES: u64 = 1 << 20;
}

impl Default for UnpackLimits {
    /// 10,000 entries, 256 MiB per entry, 1 GiB in all, ratio 100, XML 64 MiB. FMUs are
    /// far below these: our plant is 1.0 MB in 3 entries at ratios 2.4 (the library) to
    /// 8.6 (the XML); text compresses about 10:1, machine code 2-3:1, while a zip bomb of
    /// zeros compresses 1000:1.
    fn default() -> Self {
        UnpackLimits {
            max_entries: 10_000,
            max_entry_bytes: 256 << 20,
            max_total_bytes: 1 << 30,
            max_ratio: 100,
            max_xml_bytes: 64 << 20,
        }
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

/// Opens `path` for reading if it is a regular file (a FIFO, device or folder is refused
/// without opening it: opening a FIFO would wait for a writer). Non-blocking open, so
/// that a file swapped for a FIFO after the check does not block either.
pub fn open_regular(path: &Path) -> Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    let io = |source| Error::Io { path: path.to_path_buf(), source };
    let not_regular = |kind: &str| Error::NotRegularFile { path: path.to_path_buf(), kind: kind.to_string() };
    let kind = |m: &std::fs::Metadata| {
        use std::os::unix::fs::FileTypeExt;
        let t = m.file_type();
        if t.is_dir() {
            "a folder"
        } else if t.is_fifo() {
            "a FIFO (named pipe)"
        } else if t.is_socket() {
            "a socket"
        } else if t.is_block_device() || t.is_char_device() {
            "a device"
        } else {
            "not a regular file"
        }
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(kind(&meta)));
    }
    const O_NONBLOCK: i32 = 0o4000; // Linux
    let file = std::fs::OpenOptions::new().read(true).custom_flags(O_NONBLOCK).open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(kind(&meta)));
    }
    Ok(file)
}

/// Reads the text file `path` (a regular file of at most `limit` bytes, checked
/// before reading); `shown` names it in errors.
pub fn read_text_file(path: &Path, shown: &str, limit: u64) -> Result<String> {
    use std::io::Read;
    let file = open_regular(path)?;
    let size = file.metadata().map_err(|source| Error::Io { path: path.to_path_buf(), source })?.len();
    if size > limit {
        return Err(Error::ArchiveLimit { entry: shown.to_string(), size, limit, limit_name: "max_xml_bytes" });
    }
    let mut bytes = Vec::with_capacity(size as usize);
    // `take`: a file grown since the check is still held to the limit
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    if bytes.len() as u64 > limit {
        return Err(Error::ArchiveLimit {
            entry: shown.to_string(),
            size: bytes.len() as u64,
            limit,
            limit_name: "max_xml_bytes",
        });
    }
    String::from_utf8(bytes).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidData, format!("{shown} is not UTF-8 text: {e}")),
    })
}

/// Unpacks `archive` into a fresh private temporary folder (removed when dropped, or by
/// [`remove_on_signals`] when the process is interrupted).
pub fn unpack(archive: &Path, limits: &UnpackLimits) -> Result<tempfile::TempDir> {
    let dir = tempfile::Builder::new()
        .prefix("nigel-cosim-")
        .tempdir()
        .map_err(|source| Error::Io { path: std::env::temp_dir(), source })?;
    register(dir.path());
    unpack_into(archive, dir.path(), limits)?; // on error `dir` is dropped, so removed
    Ok(dir)
}

/// The temporary folders this process made (those already removed are pruned as new
/// ones come).
static MADE: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

fn register(dir: &Path) {
    let mut made = MADE.lock().unwrap_or_else(|e| e.into_inner());
    made.retain(|p| p.exists());
    made.push(dir.to_path_buf());
}

/// Removes the temporary folders of this process when it gets SIGINT, SIGTERM or SIGHUP,
/// then exits with 128 + the signal's number (as a shell reports it). Call it first in
/// `main`, before any thread starts: it blocks those signals in the calling thread (and so
/// in every thread and child started after) and waits for them in a thread of its own.
pub fn remove_on_signals() {
    // the message names the program that stops (cosim, campaign, table3, a user's own)
    let program = std::env::args_os()
        .next()
        .map(std::path::PathBuf::from)
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "cosim".to_string());
    // SAFETY: plain libc calls on a local signal set.
    unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            libc::sigaddset(&mut set, s);
        }
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
            return;
        }
        let _ = std::thread::Builder::new().name("signals".into()).spawn(move || {
            let mut signal: libc::c_int = 0;
            if libc::sigwait(&set, &mut signal) == 0 {
                let made = MADE.lock().unwrap_or_else(|e| e.into_inner()).clone();
                for dir in made {
                    let _ = std::fs::remove_dir_all(dir);
                }
                eprintln!("{program}: stopped by {}; temporary folders removed", crate::error::signal_name(signal));
                // host processes end with the master (PR_SET_PDEATHSIG)
                libc::_exit(128 + signal);
            }
        });
    }
}

fn unpack_into(archive: &Path, dest: &Path, limits: &UnpackLimits) -> Result<()> {
    let file = open_regular(archive)?;
    let bad = |e: zip::result::ZipError| Error::Archive { path: archive.to_path_buf(), reason: e.to_string() };
    let mut zip = zip::ZipArchive::new(std::io::BufReader::with_capacity(64 * 1024, file)).map_err(bad)?;
    let count = zip.len() as u64;
    if count > limits.max_entries {
        return Err(Error::ArchiveLimit {
            entry: "<number of entries>".into(),
            size: count,
            limit: limits.max_entries,
            limit_name: "max_entries",
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
            return Err(Error::ArchiveLimit {
                entry: name,
                size: entry.size(),
                limit: limits.max_entry_bytes,
                limit_name: "max_entry_bytes",
            });
        }
        if entry.size() > UnpackLimits::RATIO_FREE_BYTES
            && entry.size() / entry.compressed_size().max(1) >= limits.max_ratio
        {
            return Err(Error::ArchiveLimit {
                entry: name,
                size: entry.size() / entry.compressed_size().max(1),
                limit: limits.max_ratio,
                limit_name: "max_ratio",
            });
        }
        declared_total = declared_total.saturating_add(entry.size());
        if declared_total > limits.max_total_bytes {
            return Err(Error::ArchiveLimit {
                entry: "<total>".into(),
                size: declared_total,
                limit: limits.max_total_bytes,
                limit_name: "max_total_bytes",
            });
        }
    }
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
        let declared = entry.size();
        let mut written = 0u64;
        loop {
            let n = entry
                .read(&mut buffer)
                .map_err(|e| Error::Archive { path: archive.to_path_buf(), reason: format!("entry {name:?}: {e}") })?;
            if n == 0 {
                break;
            }
            written += n as u64;
            // the declared sizes passed every limit above: holding each entry to its
            // declared size holds the archive to all of them
            if written > declared {
                return Err(Error::ArchiveLimit {
                    entry: name,
                    size: written,
                    limit: declared,
                    limit_name: "the size its header declares",
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
