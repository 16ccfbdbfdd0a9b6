//! Safe unpacking of `.fmu` / `.ssp` archives into a private temporary folder.
//!
//! A run unpacks of an FMU only what it uses ([`unpack_fmu`]: `modelDescription.xml`,
//! `binaries/linux64/`, `resources/`), so that the libraries of other platforms cost
//! nothing; an FMU inside an `.ssp` is read straight from it ([`ArchiveSource::Nested`]:
//! in place when stored, as `write_ssp` stores them, else inflated into memory), never
//! written to disk as a whole. Every header of every archive is checked as below first.
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
    let io = |source| Error::Io { path: path.to_path_buf(), source };
    let not_regular = |kind: &str| Error::NotRegularFile { path: path.to_path_buf(), kind: kind.to_string() };
    let kind = |m: &std::fs::Metadata| {
        let t = m.file_type();
        #[cfg(unix)]
        {
            use std::os::unix::fs::FileTypeExt;
            if t.is_fifo() {
                return "a FIFO (named pipe)";
            } else if t.is_socket() {
                return "a socket";
            } else if t.is_block_device() || t.is_char_device() {
                return "a device";
            }
        }
        if t.is_dir() {
            "a folder"
        } else {
            "not a regular file"
        }
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(kind(&meta)));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(kind(&meta)));
    }
    Ok(file)
}

/// `Ok` when `size` (of `entry`) is within `limit` (the limit called `limit_name`), else
/// the error that says so.
fn within_limit(entry: &str, size: u64, limit: u64, limit_name: &'static str) -> Result<()> {
    if size > limit {
        return Err(Error::ArchiveLimit { entry: entry.to_string(), size, limit, limit_name });
    }
    Ok(())
}

/// Reads the text file `path` (a regular file of at most `limit` bytes, checked
/// before reading); `shown` names it in errors.
pub fn read_text_file(path: &Path, shown: &str, limit: u64) -> Result<String> {
    use std::io::Read;
    let file = open_regular(path)?;
    let size = file.metadata().map_err(|source| Error::Io { path: path.to_path_buf(), source })?.len();
    within_limit(shown, size, limit, "max_xml_bytes")?;
    let mut bytes = Vec::with_capacity(size as usize);
    // `take`: a file grown since the check is still held to the limit
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    within_limit(shown, bytes.len() as u64, limit, "max_xml_bytes")?;
    String::from_utf8(bytes).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidData, format!("{shown} is not UTF-8 text: {e}")),
    })
}

/// Unpacks `archive` into a fresh private temporary folder (removed when dropped, or by
/// [`remove_on_signals`] when the process is interrupted).
pub fn unpack(archive: &Path, limits: &UnpackLimits) -> Result<tempfile::TempDir> {
    let dir = fresh_dir()?;
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
    crate::janitor::watch(dir);
}

/// Removes the temporary folders this process made, without waiting: when another
/// thread holds the list (it is adding one), nothing is removed. For a process that ends
/// without unwinding (`_exit`).
pub fn remove_temporary_folders_now() {
    if let Ok(made) = MADE.try_lock() {
        for dir in made.iter() {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
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
    on_signals(move |signal| {
        let made = MADE.lock().unwrap_or_else(|e| e.into_inner()).clone();
        for dir in made {
            let _ = std::fs::remove_dir_all(dir);
        }
        eprintln!("{program}: stopped by {}; temporary folders removed", crate::error::signal_name(signal));
        // host processes end with the master (PR_SET_PDEATHSIG)
    });
}

/// The signal that asked the program to stop ([`remove_on_signals_after_stop`]), 0 before one.
static STOPPED_BY: std::sync::atomic::AtomicI32 = std::sync::atomic::AtomicI32::new(0);

fn program_name() -> String {
    std::env::args_os()
        .next()
        .map(std::path::PathBuf::from)
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "cosim".to_string())
}

/// Blocks SIGINT, SIGTERM and SIGHUP in the calling thread (and so in every thread started
/// after it); the set, for `sigwait`, or `None` when they could not be blocked.
#[cfg(unix)]
fn block_stop_signals() -> Option<libc::sigset_t> {
    // SAFETY: plain libc calls on a local signal set.
    unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            libc::sigaddset(&mut set, s);
        }
        (libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) == 0).then_some(set)
    }
}

/// As [`remove_on_signals`], but the first SIGINT, SIGTERM or SIGHUP only calls `stop` (which
/// asks the program to end by itself, e.g. by setting a run's cancel flag, so that it writes
/// what it computed, then calls [`finish_stopped`]) and gives it `grace` to do so; a second
/// signal, or the end of the grace, removes the temporary folders and exits with 128 + the
/// signal's number as [`remove_on_signals`] does. Call it first in `main`.
#[cfg(unix)]
pub fn remove_on_signals_after_stop(stop: impl FnOnce(libc::c_int) + Send + 'static, grace: std::time::Duration) {
    // SAFETY: plain libc calls on a local signal set and a local timespec.
    unsafe {
        let Some(set) = block_stop_signals() else { return };
        let _ = std::thread::Builder::new().name("signals".into()).spawn(move || {
            let mut first: libc::c_int = 0;
            if libc::sigwait(&set, &mut first) != 0 {
                return;
            }
            STOPPED_BY.store(first, std::sync::atomic::Ordering::SeqCst);
            stop(first);
            let second = wait_for_signal(&set, grace);
            if second > 0 {
                STOPPED_BY.store(second, std::sync::atomic::Ordering::SeqCst);
            }
            finish_stopped();
        });
    }
}

/// Waits up to `grace` for one of the blocked signals of `set` and returns it (0 when none came).
#[cfg(target_os = "linux")]
unsafe fn wait_for_signal(set: &libc::sigset_t, grace: std::time::Duration) -> libc::c_int {
    let timeout =
        libc::timespec { tv_sec: grace.as_secs() as libc::time_t, tv_nsec: grace.subsec_nanos() as libc::c_long };
    // SAFETY: `set` and `timeout` are valid for the call.
    unsafe { libc::sigtimedwait(set, std::ptr::null_mut(), &timeout) }
}

/// As on Linux, for the Unixes without `sigtimedwait` (macOS): polls the pending signals every
/// 10 ms and takes a pending one with `sigwait`.
#[cfg(all(unix, not(target_os = "linux")))]
unsafe fn wait_for_signal(set: &libc::sigset_t, grace: std::time::Duration) -> libc::c_int {
    let end = std::time::Instant::now() + grace;
    while std::time::Instant::now() < end {
        // SAFETY: plain libc calls on local signal sets.
        unsafe {
            let mut pending: libc::sigset_t = std::mem::zeroed();
            if libc::sigpending(&mut pending) == 0 {
                for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
                    let mut signal = 0;
                    if libc::sigismember(&pending, s) == 1 && libc::sigwait(set, &mut signal) == 0 {
                        return signal;
                    }
                }
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    0
}

/// The signal [`remove_on_signals_after_stop`] received, if any (the program then stops by
/// itself and ends with [`finish_stopped`]).
pub fn stopped_by() -> Option<libc::c_int> {
    Some(STOPPED_BY.load(std::sync::atomic::Ordering::SeqCst)).filter(|&s| s != 0)
}

/// Ends a program that a signal asked to stop: removes the temporary folders and exits with
/// 128 + the signal's number (as a shell reports it), saying so on stderr.
pub fn finish_stopped() -> ! {
    let signal = stopped_by().unwrap_or(libc::SIGINT);
    let made = MADE.lock().unwrap_or_else(|e| e.into_inner()).clone();
    for dir in made {
        let _ = std::fs::remove_dir_all(dir);
    }
    eprintln!("{}: stopped by {}; temporary folders removed", program_name(), crate::error::signal_name(signal));
    // SAFETY: ends the process without running other threads' code further.
    unsafe { libc::_exit(128 + signal) }
}

/// Blocks SIGINT, SIGTERM and SIGHUP in the calling thread (and so in every thread and child
/// started after it; call it first in `main`) and waits for them in a thread of its own,
/// which runs `cleanup` with the signal and exits with 128 + its number. The one signal
/// waiter of the master's programs ([`remove_on_signals`], a campaign's worker processes).
#[cfg(unix)]
pub fn on_signals(cleanup: impl FnOnce(libc::c_int) + Send + 'static) {
    // SAFETY: plain libc calls on a local signal set.
    unsafe {
        let Some(set) = block_stop_signals() else { return };
        let _ = std::thread::Builder::new().name("signals".into()).spawn(move || {
            let mut signal: libc::c_int = 0;
            if libc::sigwait(&set, &mut signal) == 0 {
                cleanup(signal);
                libc::_exit(128 + signal);
            }
        });
    }
}

/// Windows has no SIGINT, SIGTERM, SIGHUP to wait for: Ctrl+C ends the process at once, and
/// the temporary folders of the run stay in %TEMP%.
#[cfg(not(unix))]
pub fn on_signals(_cleanup: impl FnOnce(libc::c_int) + Send + 'static) {}

/// As [`on_signals`] on Windows: nothing to wait for.
#[cfg(not(unix))]
pub fn remove_on_signals_after_stop(_stop: impl FnOnce(libc::c_int) + Send + 'static, _grace: std::time::Duration) {}

/// Where an archive is: a file, or an entry of an `.ssp` (an FMU in `resources/`), read
/// straight from the outer archive without writing it to disk.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ArchiveSource {
    /// An archive file.
    File(PathBuf),
    /// The archive stored as entry `entry` of the `.ssp` file `outer`.
    Nested {
        /// The `.ssp` file.
        outer: PathBuf,
        /// The entry's name in it (`resources/x.fmu`).
        entry: String,
    },
}

impl ArchiveSource {
    /// The path errors name: the file, or `<outer>/<entry>` (the `.ssp` and the place in it).
    pub fn shown(&self) -> PathBuf {
        match self {
            ArchiveSource::File(p) => p.clone(),
            ArchiveSource::Nested { outer, entry } => outer.join(entry),
        }
    }

    /// The archive's bytes (the file, or the entry read out of the outer archive).
    pub fn read_bytes(&self, limits: &UnpackLimits) -> Result<Vec<u8>> {
        let mut bytes = Vec::new();
        match self.open(limits)? {
            Reader::File(mut f) => f.read_to_end(&mut bytes),
            Reader::Window(mut w) => w.read_to_end(&mut bytes),
            Reader::Memory(c) => return Ok(c.into_inner()),
        }
        .map_err(|source| Error::Io { path: self.shown(), source })?;
        Ok(bytes)
    }

    fn open(&self, limits: &UnpackLimits) -> Result<Reader> {
        match self {
            ArchiveSource::File(p) => Ok(Reader::File(std::io::BufReader::with_capacity(64 * 1024, open_regular(p)?))),
            ArchiveSource::Nested { outer, entry } => {
                let mut zip = open_zip(outer)?;
                let index = zip.index_for_name(entry).ok_or_else(|| Error::Archive {
                    path: outer.clone(),
                    reason: format!("no entry {entry:?} in the archive"),
                })?;
                let bad = |e: zip::result::ZipError| Error::Archive {
                    path: outer.clone(),
                    reason: format!("entry {entry:?}: {e}"),
                };
                let raw = zip.by_index_raw(index).map_err(bad)?;
                within_limit(entry, raw.size(), limits.max_entry_bytes, "max_entry_bytes")?;
                if raw.compression() == zip::CompressionMethod::Stored && !raw.encrypted() {
                    // stored (as `write_ssp` writes FMUs): read in place, seeking in the outer file
                    let (start, len) = (raw.data_start(), raw.size());
                    drop(raw);
                    let file = zip.into_inner();
                    return Ok(Reader::Window(Window { file, start, len, pos: 0, at: None }));
                }
                drop(raw);
                // compressed: inflated into memory, held to its declared size
                let mut e = zip.by_index(index).map_err(bad)?;
                let declared = e.size();
                let mut bytes = Vec::with_capacity(declared as usize);
                (&mut e)
                    .take(declared + 1)
                    .read_to_end(&mut bytes)
                    .map_err(|err| Error::Archive { path: outer.clone(), reason: format!("entry {entry:?}: {err}") })?;
                within_limit(entry, bytes.len() as u64, declared, "the size its header declares")?;
                Ok(Reader::Memory(std::io::Cursor::new(bytes)))
            }
        }
    }
}

/// An archive opened for reading.
enum Reader {
    File(std::io::BufReader<std::fs::File>),
    Window(Window),
    Memory(std::io::Cursor<Vec<u8>>),
}

/// Bytes `start .. start + len` of a file, as a file of their own.
struct Window {
    file: std::io::BufReader<std::fs::File>,
    start: u64,
    len: u64,
    pos: u64,
    /// Where the file is (`None`: unknown); a read there needs no seek, which would
    /// drop the buffer.
    at: Option<u64>,
}

impl Read for Window {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        use std::io::{Seek, SeekFrom};
        let left = self.len.saturating_sub(self.pos);
        if left == 0 {
            return Ok(0);
        }
        let n = (buf.len() as u64).min(left) as usize;
        let want = self.start + self.pos;
        if self.at != Some(want) {
            self.at = None;
            self.file.seek(SeekFrom::Start(want))?;
        }
        let got = self.file.read(&mut buf[..n])?;
        self.pos += got as u64;
        self.at = Some(want + got as u64);
        Ok(got)
    }
}

impl std::io::Seek for Window {
    fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
        use std::io::SeekFrom;
        let pos = match to {
            SeekFrom::Start(p) => p as i128,
            SeekFrom::End(d) => self.len as i128 + d as i128,
            SeekFrom::Current(d) => self.pos as i128 + d as i128,
        };
        if pos < 0 {
            return Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, "seek before the start"));
        }
        self.pos = pos as u64;
        Ok(self.pos)
    }
}

fn open_zip(path: &Path) -> Result<zip::ZipArchive<std::io::BufReader<std::fs::File>>> {
    let file = open_regular(path)?;
    zip::ZipArchive::new(std::io::BufReader::with_capacity(64 * 1024, file))
        .map_err(|e| Error::Archive { path: path.to_path_buf(), reason: e.to_string() })
}

/// One entry of a checked archive: its index, name and relative path.
pub struct Entry {
    /// Its index in the archive.
    pub index: usize,
    /// Its name as stored.
    pub name: String,
    /// The name as a safe relative path.
    pub rel: PathBuf,
}

/// Checks every header of `zip` against `limits` (names, symbolic links, duplicates,
/// sizes, ratios, the total) before anything is read; returns the entries.
pub fn check_entries<R: Read + std::io::Seek>(
    zip: &mut zip::ZipArchive<R>,
    shown: &Path,
    limits: &UnpackLimits,
) -> Result<Vec<Entry>> {
    let bad = |e: zip::result::ZipError| Error::Archive { path: shown.to_path_buf(), reason: e.to_string() };
    let count = zip.len() as u64;
    within_limit("<number of entries>", count, limits.max_entries, "max_entries")?;
    let mut declared_total = 0u64;
    let mut seen = std::collections::HashSet::with_capacity(zip.len());
    let mut entries = Vec::with_capacity(zip.len());
    for i in 0..zip.len() {
        let entry = zip.by_index_raw(i).map_err(bad)?;
        let name = entry.name().to_string();
        let rel = safe_relative_path(&name).map_err(|reason| Error::UnsafeEntry { entry: name.clone(), reason })?;
        if let Some(mode) = entry.unix_mode() {
            if mode & 0o170000 == 0o120000 {
                return Err(Error::UnsafeEntry { entry: name, reason: "symbolic link" });
            }
        }
        let is_dir = entry.is_dir() || name.ends_with('/');
        if !is_dir && !seen.insert(rel.clone()) {
            return Err(Error::UnsafeEntry { entry: name, reason: "duplicate name in the archive" });
        }
        within_limit(&name, entry.size(), limits.max_entry_bytes, "max_entry_bytes")?;
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
        within_limit("<total>", declared_total, limits.max_total_bytes, "max_total_bytes")?;
        if !is_dir {
            entries.push(Entry { index: i, name, rel });
        }
    }
    Ok(entries)
}

/// Reads the text entry `name` of a checked archive (at most `limit` bytes); `Ok(None)`
/// if there is no such entry.
pub fn read_text_entry<R: Read + std::io::Seek>(
    zip: &mut zip::ZipArchive<R>,
    shown: &Path,
    name: &str,
    limit: u64,
) -> Result<Option<String>> {
    let Some(index) = zip.index_for_name(name) else { return Ok(None) };
    let bad = |e: String| Error::Archive { path: shown.to_path_buf(), reason: format!("entry {name:?}: {e}") };
    let mut e = zip.by_index(index).map_err(|e| bad(e.to_string()))?;
    within_limit(name, e.size(), limit, "max_xml_bytes")?;
    let mut bytes = Vec::with_capacity(e.size() as usize);
    (&mut e).take(limit + 1).read_to_end(&mut bytes).map_err(|e| bad(e.to_string()))?;
    within_limit(name, bytes.len() as u64, limit, "max_xml_bytes")?;
    String::from_utf8(bytes).map(Some).map_err(|e| bad(format!("not UTF-8 text: {e}")))
}

/// The entries of an FMU a run in this process uses: `modelDescription.xml`, this
/// platform's `binaries/` folders ([`crate::platform`]: `linux64` and `x86_64-linux` on
/// x86-64 Linux) and `resources/` (other platforms' libraries, the documentation and
/// sources are not written).
pub fn used_by_a_run(name: &Path) -> bool {
    let binaries = Path::new("binaries");
    name == Path::new("modelDescription.xml")
        || name.starts_with(binaries.join(crate::platform::FMI2_FOLDER))
        || name.starts_with(binaries.join(crate::platform::FMI3_FOLDER))
        || name.starts_with("resources")
}

/// An FMU unpacked for a run: its private folder and the platforms its archive carries.
pub struct UnpackedFmu {
    /// The private folder (removed when dropped).
    pub dir: tempfile::TempDir,
    /// The folders under `binaries/` in the archive, sorted.
    pub platforms: Vec<String>,
}

/// Unpacks of the FMU `source` only the entries [`used_by_a_run`] into a fresh private
/// temporary folder, after checking every header of the archive as [`unpack`] does.
pub fn unpack_fmu(source: &ArchiveSource, limits: &UnpackLimits) -> Result<UnpackedFmu> {
    let shown = source.shown();
    let dir = fresh_dir()?;
    let mut platforms = std::collections::BTreeSet::new();
    let mut wanted = |e: &Entry| {
        let mut parts = e.rel.components();
        if let (Some(first), Some(second), Some(_)) = (parts.next(), parts.next(), parts.next()) {
            if first.as_os_str() == "binaries" {
                platforms.insert(second.as_os_str().to_string_lossy().into_owned());
            }
        }
        used_by_a_run(&e.rel)
    };
    match source.open(limits)? {
        Reader::File(r) => extract(r, &shown, dir.path(), limits, &mut wanted)?,
        Reader::Window(r) => extract(r, &shown, dir.path(), limits, &mut wanted)?,
        Reader::Memory(r) => extract(r, &shown, dir.path(), limits, &mut wanted)?,
    }
    Ok(UnpackedFmu { dir, platforms: platforms.into_iter().collect() })
}

fn fresh_dir() -> Result<tempfile::TempDir> {
    let dir = tempfile::Builder::new()
        .prefix("nigel-cosim-")
        .tempdir()
        .map_err(|source| Error::Io { path: std::env::temp_dir(), source })?;
    register(dir.path());
    Ok(dir)
}

fn unpack_into(archive: &Path, dest: &Path, limits: &UnpackLimits) -> Result<()> {
    let file = std::io::BufReader::with_capacity(64 * 1024, open_regular(archive)?);
    extract(file, archive, dest, limits, &mut |_| true)
}

/// Checks every header, then writes the entries `wanted` selects into `dest`.
fn extract<R: Read + std::io::Seek>(
    reader: R,
    shown: &Path,
    dest: &Path,
    limits: &UnpackLimits,
    wanted: &mut dyn FnMut(&Entry) -> bool,
) -> Result<()> {
    let bad = |e: zip::result::ZipError| Error::Archive { path: shown.to_path_buf(), reason: e.to_string() };
    let mut zip = zip::ZipArchive::new(reader).map_err(bad)?;
    let entries = check_entries(&mut zip, shown, limits)?;
    let mut buffer = vec![0u8; 64 * 1024];
    for e in entries.iter().filter(|e| wanted(e)) {
        let mut entry = zip.by_index(e.index).map_err(bad)?;
        let name = &e.name;
        let target = dest.join(&e.rel);
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| Error::Io { path, source }
        };
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
                .map_err(|e| Error::Archive { path: shown.to_path_buf(), reason: format!("entry {name:?}: {e}") })?;
            if n == 0 {
                break;
            }
            written += n as u64;
            // the declared sizes passed every limit above: holding each entry to its
            // declared size holds the archive to all of them
            within_limit(name, written, declared, "the size its header declares")?;
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
