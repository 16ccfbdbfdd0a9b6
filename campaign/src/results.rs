//! The files of an output folder.
//!
//! - `campaign.json`: the description's hash, path, number of runs, columns and metrics
//!   (an output folder belongs to one description: another is refused).
//! - `results.csv`: one row per run, columns `run`, `status`, `message`, each varied
//!   column, each metric. Every field is a number, so that fmpy's `read_csv` reads it
//!   as well as pandas: `status` 0 = ok, 1 = the run failed (the FMU or the master
//!   returned an error, or a value was refused), 2 = the run panicked, 3 = an FMU ended
//!   the run before the stop time (metrics over the points it had), 4 = the run's worker
//!   process crashed or exited, 5 = the run passed the description's `timeout`, 6 = the run
//!   completed and failed one of the description's `[checks]`; `message` 1 when
//!   the run left a message in `messages.csv` (columns `run`, `status`, `message`, text),
//!   else 0; a case column holds the case's index (its names are in `campaign.json`);
//!   Booleans are 0 / 1; numbers in Rust's shortest round-trip form (`NaN` for a metric a
//!   failed run has not got). Rows are appended as runs finish (flushed each time) and
//!   sorted by run when the invocation completes.
//! - `shards/I-of-N.csv`, `shards/I-of-N.messages.csv`, `shards/I-of-N.json` (the hash,
//!   I, N and the block of runs): the same for shard `I` of `N`.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use serde_json::json;

use crate::spec::{Domain, Spec};
use crate::Error;

/// Status of a run that completed.
pub const STATUS_OK: u8 = 0;
/// Status of a run that returned an error.
pub const STATUS_FAILED: u8 = 1;
/// Status of a run that panicked.
pub const STATUS_PANICKED: u8 = 2;
/// Status of a run an FMU ended before the stop time (its metrics cover the points up to
/// then).
pub const STATUS_ENDED: u8 = 3;
/// Status of a run whose worker process ended during it: killed by a signal (an FMU's
/// segfault, abort, stack overflow) or exited (an FMU called `exit`).
pub const STATUS_CRASHED: u8 = 4;
/// Status of a run past the description's `timeout`: stopped by the master between two
/// steps, or its worker process killed while a call did not return.
pub const STATUS_TIMEOUT: u8 = 5;

/// Status of a run that completed and failed one of the description's `[checks]` (its
/// metrics are those of the whole run; the message names the checks that failed).
pub const STATUS_CHECK_FAILED: u8 = 6;

/// The status in words.
pub fn status_name(status: u8) -> &'static str {
    match status {
        STATUS_OK => "ok",
        STATUS_FAILED => "failed",
        STATUS_PANICKED => "panicked",
        STATUS_ENDED => "ended by an FMU before the stop time",
        STATUS_CRASHED => "crashed",
        STATUS_TIMEOUT => "timed out",
        STATUS_CHECK_FAILED => "failed a check",
        _ => "unknown",
    }
}

/// The one-line account of the runs that did not complete (`None` when every run did):
/// `N runs, M failed: ` then the first few by run with their status and message.
pub fn failure_summary(rows: &[Row]) -> Option<String> {
    let mut bad: Vec<&Row> = rows.iter().filter(|r| r.status != STATUS_OK).collect();
    if bad.is_empty() {
        return None;
    }
    bad.sort_by_key(|r| r.run);
    let shown = 3;
    let mut parts: Vec<String> = bad
        .iter()
        .take(shown)
        .map(|r| {
            let m: String = r.message.chars().take(160).collect();
            let cut = if m.len() < r.message.len() { "..." } else { "" };
            format!("run {} {} ({m}{cut})", r.run, status_name(r.status))
        })
        .collect();
    if bad.len() > shown {
        parts.push(format!("and {} more", bad.len() - shown));
    }
    let mut by_status = std::collections::BTreeMap::new();
    for r in &bad {
        *by_status.entry(status_name(r.status)).or_insert(0u64) += 1;
    }
    let counts: Vec<String> = by_status.iter().map(|(s, n)| format!("{n} {s}")).collect();
    Some(format!("{} runs, {} failed ({}): {}", rows.len(), bad.len(), counts.join(", "), parts.join("; ")))
}

/// One result row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The run's number.
    pub run: u64,
    /// [`STATUS_OK`], [`STATUS_FAILED`], [`STATUS_PANICKED`], [`STATUS_ENDED`],
    /// [`STATUS_CRASHED`], [`STATUS_TIMEOUT`] or [`STATUS_CHECK_FAILED`].
    pub status: u8,
    /// What went wrong (empty when ok).
    pub message: String,
    /// The varied columns, then the metrics.
    pub values: Vec<f64>,
}

fn push_number(out: &mut String, v: f64) {
    use std::fmt::Write;
    let _ = write!(out, "{v}");
}

impl Row {
    /// The CSV line (with its newline).
    pub fn line(&self) -> String {
        let mut s = format!("{},{},{}", self.run, self.status, u8::from(!self.message.is_empty()));
        for v in &self.values {
            s.push(',');
            push_number(&mut s, *v);
        }
        s.push('\n');
        s
    }

    /// The `messages.csv` line (with its newline).
    pub fn message_line(&self) -> String {
        format!("{},{},{}\n", self.run, self.status, quote(&self.message))
    }
}

/// A CSV text field: quoted, inner quotes doubled, line breaks as spaces.
pub fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\"").replace(['\n', '\r'], " "))
}

/// The header line of `results.csv` (quoted names, as fmpy writes them).
pub fn header_line(spec: &Spec) -> String {
    spec.header().iter().map(|h| quote(h)).collect::<Vec<_>>().join(",") + "\n"
}

const MESSAGES_HEADER: &str = "\"run\",\"status\",\"message\"\n";

/// `campaign.json` of `spec`.
pub fn meta(spec: &Spec) -> serde_json::Value {
    let columns: Vec<serde_json::Value> = spec
        .columns
        .iter()
        .map(|c| {
            let kind = match &c.domain {
                Domain::Grid(_) => "grid",
                Domain::Cases(_) => "cases",
                Domain::Random(_) => "random",
            };
            json!({"name": c.name, "kind": kind, "set": c.targets, "cases": c.case_names()})
        })
        .collect();
    json!({
        "hash": spec.hash,
        "description": std::path::absolute(&spec.path).unwrap_or_else(|_| spec.path.clone()),
        "system": spec.system,
        "runs": spec.runs(),
        "columns": columns,
        "metrics": spec.metrics.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>(),
    })
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::Io(format!("{}: {e}", path.display()))
}

/// Makes `dir` the output folder of `spec`: writes `campaign.json`, or checks that the
/// one there is of the same description.
pub fn claim(dir: &Path, spec: &Spec) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let path = dir.join("campaign.json");
    match std::fs::read_to_string(&path) {
        Ok(text) => {
            let v: serde_json::Value = serde_json::from_str(&text)
                .map_err(|e| Error::Usage(format!("{}: not a campaign record ({e})", path.display())))?;
            let hash = v["hash"].as_str().unwrap_or("");
            if hash != spec.hash {
                return Err(Error::Usage(format!(
                    "{} holds another campaign ({} of description {}, hash {}; this description {} has hash {}): choose another --out",
                    dir.display(),
                    v["runs"],
                    v["description"].as_str().unwrap_or("?"),
                    short(hash),
                    spec.path.display(),
                    short(&spec.hash)
                )));
            }
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if std::fs::read_dir(dir).map_err(io(dir))?.next().is_some() {
                let foreign = ["results.csv", "shards"].iter().any(|f| dir.join(f).exists());
                if foreign {
                    return Err(Error::Usage(format!(
                        "{} holds results without a campaign.json: choose another --out",
                        dir.display()
                    )));
                }
            }
            let text = serde_json::to_string_pretty(&meta(spec)).expect("JSON of plain values");
            std::fs::write(&path, text + "\n").map_err(io(&path))
        }
        Err(e) => Err(io(&path)(e)),
    }
}

/// The first 12 hex digits of a hash.
pub fn short(hash: &str) -> &str {
    &hash[..hash.len().min(12)]
}

/// Where an invocation writes: `results.csv` or a shard's files.
#[derive(Clone, Debug)]
pub struct Target {
    /// The rows.
    pub rows: PathBuf,
    /// The messages.
    pub messages: PathBuf,
    /// A shard's record (`None` for the whole campaign).
    pub record: Option<PathBuf>,
}

impl Target {
    /// The whole campaign's files in `dir`.
    pub fn whole(dir: &Path) -> Target {
        Target { rows: dir.join("results.csv"), messages: dir.join("messages.csv"), record: None }
    }

    /// The files of shard `index` of `count` in `dir`.
    pub fn shard(dir: &Path, index: u64, count: u64) -> Target {
        let d = dir.join("shards");
        Target {
            rows: d.join(format!("{index}-of-{count}.csv")),
            messages: d.join(format!("{index}-of-{count}.messages.csv")),
            record: Some(d.join(format!("{index}-of-{count}.json"))),
        }
    }
}

/// Parses one results line of `width` fields; `None` if it is not a complete row.
pub(crate) fn parse_line(line: &str, width: usize) -> Option<(u64, u8, bool, Vec<f64>)> {
    let mut it = line.split(',');
    let run = it.next()?.parse().ok()?;
    let status = it.next()?.parse().ok()?;
    let message = match it.next()? {
        "0" => false,
        "1" => true,
        _ => return None,
    };
    let values: Vec<f64> = it.map(|f| f.parse::<f64>().ok()).collect::<Option<_>>()?;
    (values.len() + 3 == width).then_some((run, status, message, values))
}

/// Reads the rows of a results file (and its messages). A last line without its newline
/// (a run killed while writing) is left out; `repair` truncates the file to the complete
/// rows so that appending goes on from there.
pub fn read_rows(target: &Target, spec: &Spec, repair: bool) -> Result<Vec<Row>, Error> {
    let path = &target.rows;
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io(path)(e)),
    };
    let header = header_line(spec);
    if !text.starts_with(&header) {
        let first = text.lines().next().unwrap_or("");
        return Err(Error::Usage(format!(
            "{}: its header {first} is not this description's ({})",
            path.display(),
            header.trim_end()
        )));
    }
    let width = spec.header().len();
    let mut rows = Vec::new();
    let mut good = header.len();
    let body = &text[header.len()..];
    let mut offset = header.len();
    for chunk in body.split_inclusive('\n') {
        offset += chunk.len();
        let Some(line) = chunk.strip_suffix('\n') else { break };
        let (run, status, has_message, values) = parse_line(line, width).ok_or_else(|| {
            Error::Usage(format!("{}: line {:?} is not a row of this description", path.display(), line))
        })?;
        rows.push(Row { run, status, message: if has_message { "?".into() } else { String::new() }, values });
        good = offset;
    }
    if repair && good < text.len() {
        let f = std::fs::OpenOptions::new().write(true).open(path).map_err(io(path))?;
        f.set_len(good as u64).map_err(io(path))?;
    }
    // the messages of the rows that have one
    if let Ok(m) = std::fs::read_to_string(&target.messages) {
        let mut by_run = BTreeMap::new();
        for line in m.lines().skip(1) {
            let mut parts = line.splitn(3, ',');
            if let (Some(run), Some(_), Some(msg)) = (parts.next(), parts.next(), parts.next()) {
                if let Ok(run) = run.parse::<u64>() {
                    let msg =
                        msg.strip_prefix('"').and_then(|s| s.strip_suffix('"')).unwrap_or(msg).replace("\"\"", "\"");
                    by_run.insert(run, msg);
                }
            }
        }
        for r in rows.iter_mut().filter(|r| !r.message.is_empty()) {
            if let Some(m) = by_run.remove(&r.run) {
                r.message = m;
            }
        }
    }
    Ok(rows)
}

/// Appends rows to a target as they come, each flushed.
pub struct Appender {
    rows: std::fs::File,
    messages: std::fs::File,
}

fn open_append(path: &Path, header: &str) -> Result<std::fs::File, Error> {
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d).map_err(io(d))?;
    }
    let new = !path.exists() || std::fs::metadata(path).map_err(io(path))?.len() == 0;
    let mut f = std::fs::OpenOptions::new().create(true).append(true).open(path).map_err(io(path))?;
    if new {
        f.write_all(header.as_bytes()).map_err(io(path))?;
    }
    Ok(f)
}

impl Appender {
    /// Opens (creating with the header) the target's files for appending.
    pub fn open(target: &Target, spec: &Spec) -> Result<Appender, Error> {
        Ok(Appender {
            rows: open_append(&target.rows, &header_line(spec))?,
            messages: open_append(&target.messages, MESSAGES_HEADER)?,
        })
    }

    /// Writes one row (its message first, so that a row never points at a missing one).
    pub fn push(&mut self, row: &Row) -> std::io::Result<()> {
        if !row.message.is_empty() {
            self.messages.write_all(row.message_line().as_bytes())?;
        }
        self.rows.write_all(row.line().as_bytes())
    }
}

/// Writes `rows` (sorted by run) as the target's files, replacing them atomically.
pub fn write_sorted(target: &Target, spec: &Spec, rows: &mut [Row]) -> Result<(), Error> {
    rows.sort_by_key(|r| r.run);
    let mut text = header_line(spec);
    let mut messages = MESSAGES_HEADER.to_string();
    for r in rows.iter() {
        text.push_str(&r.line());
        if !r.message.is_empty() {
            messages.push_str(&r.message_line());
        }
    }
    for (path, content) in [(&target.messages, messages), (&target.rows, text)] {
        let tmp = path.with_extension("csv.tmp");
        std::fs::write(&tmp, content).map_err(io(&tmp))?;
        std::fs::rename(&tmp, path).map_err(io(path))?;
    }
    Ok(())
}
