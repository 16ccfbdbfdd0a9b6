//! Joining the shards of an output folder into `results.csv`: every run of the
//! description exactly once, every shard of this description.

use std::path::Path;

use crate::results::{self, short, Row, Target};
use crate::spec::Spec;
use crate::Error;

/// A shard's record file `shards/I-of-N.json`.
struct Record {
    index: u64,
    count: u64,
    hash: String,
}

fn records(dir: &Path) -> Result<Vec<(std::path::PathBuf, Record)>, Error> {
    let shards = dir.join("shards");
    let Ok(entries) = std::fs::read_dir(&shards) else { return Ok(Vec::new()) };
    let mut out = Vec::new();
    for e in entries.flatten() {
        let p = e.path();
        if p.extension().and_then(|x| x.to_str()) != Some("json") {
            continue;
        }
        let text = std::fs::read_to_string(&p).map_err(|e| Error::Io(format!("{}: {e}", p.display())))?;
        let v: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| Error::Merge(format!("{}: not a shard record ({e})", p.display())))?;
        let (Some(index), Some(count), Some(hash)) = (v["shard"].as_u64(), v["of"].as_u64(), v["hash"].as_str()) else {
            return Err(Error::Merge(format!("{}: not a shard record (no shard, of, hash)", p.display())));
        };
        out.push((p, Record { index, count, hash: hash.to_string() }));
    }
    out.sort_by_key(|(_, r)| (r.count, r.index));
    Ok(out)
}

/// The rows of every shard in `dir` of this description (a foreign shard is an error;
/// a shard CSV without its record too).
pub fn shard_rows(dir: &Path, spec: &Spec) -> Result<Vec<Row>, Error> {
    let mut rows = Vec::new();
    let recs = records(dir)?;
    if let Ok(entries) = std::fs::read_dir(dir.join("shards")) {
        for e in entries.flatten() {
            let p = e.path();
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("").to_string();
            if name.ends_with(".csv") && !name.ends_with(".messages.csv") && !p.with_extension("json").exists() {
                return Err(Error::Merge(format!(
                    "{}: a shard without its record {}",
                    p.display(),
                    p.with_extension("json").display()
                )));
            }
        }
    }
    for (path, r) in &recs {
        if r.hash != spec.hash {
            return Err(Error::Merge(format!(
                "{} is a shard of another description (hash {}, this one {}): refused",
                path.display(),
                short(&r.hash),
                short(&spec.hash)
            )));
        }
        let target = Target::shard(dir, r.index, r.count);
        let mut got = results::read_rows(&target, spec, false)?;
        let block = spec.shard_range(r.index, r.count);
        if let Some(x) = got.iter().find(|x| !block.contains(&x.run)) {
            return Err(Error::Merge(format!(
                "{}: run {} is outside shard {}/{}'s block {}..{}",
                target.rows.display(),
                x.run,
                r.index,
                r.count,
                block.start,
                block.end
            )));
        }
        rows.append(&mut got);
    }
    Ok(rows)
}

/// What [`merge`] wrote.
#[derive(Debug)]
pub struct Merged {
    /// Shards read.
    pub shards: usize,
    /// Runs written.
    pub runs: u64,
    /// Of those failed.
    pub failed: u64,
}

/// Checks that the shards of `dir` hold every run of `spec` exactly once and writes the
/// merged `results.csv` (the bytes a local run of all writes).
pub fn merge(dir: &Path, spec: &Spec) -> Result<Merged, Error> {
    let recs = records(dir)?;
    if recs.is_empty() {
        return Err(Error::Merge(format!("{}: no shards (shards/I-of-N.json) to merge", dir.display())));
    }
    results::claim(dir, spec)?;
    let mut rows = shard_rows(dir, spec)?;
    rows.sort_by_key(|r| r.run);
    for w in rows.windows(2) {
        if w[0].run == w[1].run {
            return Err(Error::Merge(format!("run {} is in two shards of {}", w[0].run, dir.display())));
        }
    }
    let n = spec.runs();
    if rows.len() as u64 != n {
        let mut missing = Vec::new();
        let mut k = 0;
        for i in 0..n {
            if rows.get(k).is_some_and(|r| r.run == i) {
                k += 1;
            } else {
                missing.push(i);
            }
        }
        let counts: std::collections::BTreeSet<u64> = recs.iter().map(|(_, r)| r.count).collect();
        let hint = match counts.iter().next() {
            Some(&c) if counts.len() == 1 => {
                let shards: std::collections::BTreeSet<u64> = missing
                    .iter()
                    .map(|&i| (0..c).find(|&s| spec.shard_range(s, c).contains(&i)).unwrap_or(0))
                    .collect();
                let list: Vec<String> = shards.iter().map(|s| format!("{s}/{c}")).collect();
                format!(
                    " (shard {}; complete with: campaign run {} --out {} --shard {} --resume{})",
                    list.join(", "),
                    spec.path.display(),
                    dir.display(),
                    list[0],
                    if list.len() > 1 { ", and likewise for the others" } else { "" }
                )
            }
            _ => String::new(),
        };
        let shown: Vec<String> = missing.iter().take(8).map(|i| i.to_string()).collect();
        return Err(Error::Merge(format!(
            "{} of {n} runs missing: {}{}{hint}",
            missing.len(),
            shown.join(", "),
            if missing.len() > 8 { ", ..." } else { "" }
        )));
    }
    let failed = rows.iter().filter(|r| r.status != results::STATUS_OK).count() as u64;
    results::write_sorted(&Target::whole(dir), spec, &mut rows)?;
    Ok(Merged { shards: recs.len(), runs: n, failed })
}
