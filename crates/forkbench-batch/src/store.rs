//! The batch directory on disk: trial records (torn lines, duplicates), finished results, and merging shards.

use std::collections::{BTreeMap, HashSet};
use std::fs::File;
use std::io::{BufRead, BufReader, Read as _};
use std::path::{Path, PathBuf};

use super::{
    BatchError, DirLock, Manifest, Summary, TrialRecord, io, summarize_with, write_summary,
};

/// Reads `trials.jsonl`. A torn last line (a crash mid-write) is skipped; any other bad
/// line is an error naming the file and line.
pub fn read_records(path: &Path) -> Result<Vec<TrialRecord>, BatchError> {
    read_records_torn(path).map(|(records, _)| records)
}

/// [`read_records`], each record with its 1-based line in the file (for `replay --line`).
pub fn read_numbered(path: &Path) -> Result<Vec<(usize, TrialRecord)>, BatchError> {
    read_numbered_torn(path).map(|(records, _)| records)
}

/// [`read_records`], also saying whether a torn last line was skipped.
pub(super) fn read_records_torn(path: &Path) -> Result<(Vec<TrialRecord>, bool), BatchError> {
    let (numbered, torn) = read_numbered_torn(path)?;
    Ok((numbered.into_iter().map(|(_, r)| r).collect(), torn))
}

fn read_numbered_torn(path: &Path) -> Result<(Vec<(usize, TrialRecord)>, bool), BatchError> {
    read_jsonl(path, contradiction)
}

/// The JSON lines of `path`, each with its 1-based line and checked by `check`, and
/// whether a torn last line was skipped.
pub(crate) fn read_jsonl<T: serde::de::DeserializeOwned>(
    path: &Path,
    check: impl Fn(&T) -> Option<String>,
) -> Result<(Vec<(usize, T)>, bool), BatchError> {
    let file = match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok((Vec::new(), false)),
        Err(e) => return Err(io(path)(e)),
        Ok(m) if !m.is_file() => {
            return Err(BatchError::Content(format!(
                "{}: not a regular file",
                path.display()
            )));
        }
        // Every reader of records (regress, baseline, merge, resume, replay) holds them all
        // in memory: the file's size bounds that, not its line count.
        Ok(m) if m.len() > super::MAX_RECORDS_BYTES => {
            return Err(BatchError::Content(format!(
                "{}: {} bytes, more than the {} bytes of trial records read at once; shard \
                 the batch (--shard I/N) and gate the shards, or lower --trials",
                path.display(),
                m.len(),
                super::MAX_RECORDS_BYTES
            )));
        }
        Ok(_) => File::open(path).map_err(io(path))?,
    };
    let lines = capped_lines(BufReader::new(file), path)?;
    let mut out = Vec::with_capacity(lines.len());
    let last = lines.iter().rposition(|l| !l.trim().is_empty());
    let mut torn = false;
    for (i, line) in lines.iter().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<T>(line) {
            Ok(r) => {
                if let Some(why) = check(&r) {
                    return Err(BatchError::Record {
                        path: path.display().to_string(),
                        line: i + 1,
                        message: why,
                    });
                }
                out.push((i + 1, r));
            }
            Err(_) if Some(i) == last => torn = true, // torn or corrupt final write
            Err(e) => {
                return Err(BatchError::Record {
                    path: path.display().to_string(),
                    line: i + 1,
                    message: e.to_string(),
                });
            }
        }
    }
    Ok((out, torn))
}

/// Why a parsed record contradicts itself (an edited or foreign file), if it does: a
/// success has no failure, a failure names one.
pub(crate) fn contradiction(r: &TrialRecord) -> Option<String> {
    match (r.outcome.success, &r.outcome.failure) {
        (true, Some(f)) => Some(format!(
            "success is true but failure is {:?}: a record is one or the other",
            f.name()
        )),
        (false, None) => Some("success is false but no failure is named".to_owned()),
        _ => None,
    }
}

/// Longest line of `trials.jsonl` read: a record is a few kilobytes.
pub const MAX_RECORD_LINE_BYTES: u64 = 16 << 20;

/// The file's lines, each at most [`MAX_RECORD_LINE_BYTES`].
fn capped_lines(mut r: impl BufRead, path: &Path) -> Result<Vec<String>, BatchError> {
    let mut lines = Vec::new();
    loop {
        let mut buf = Vec::new();
        let n = (&mut r)
            .take(MAX_RECORD_LINE_BYTES + 1)
            .read_until(b'\n', &mut buf)
            .map_err(io(path))?;
        if n == 0 {
            return Ok(lines);
        }
        if n as u64 > MAX_RECORD_LINE_BYTES {
            return Err(BatchError::Record {
                path: path.display().to_string(),
                line: lines.len() + 1,
                message: format!("longer than {MAX_RECORD_LINE_BYTES} bytes; not a trial record"),
            });
        }
        lines.push(
            String::from_utf8_lossy(&buf)
                .trim_end_matches('\n')
                .to_owned(),
        );
    }
}

/// Refuses records that share a trial's key: two writers at once, or a file edited by hand.
pub(super) fn check_unique(records: &[TrialRecord], path: &Path) -> Result<(), BatchError> {
    let mut seen = HashSet::new();
    let dups: Vec<_> = records.iter().filter(|r| !seen.insert(r.key())).collect();
    if let Some(first) = dups.first() {
        return Err(BatchError::Content(format!(
            "{}: {} duplicate trial records (first: {:?}); two processes wrote here at once? \
             Start over with --force-new",
            path.display(),
            dups.len(),
            first.key()
        )));
    }
    Ok(())
}

/// Rewrites `trials.jsonl` with exactly `records` (dropping a torn last line), atomically:
/// a kill mid-rewrite leaves the old file.
pub(super) fn rewrite_records(path: &Path, records: &[TrialRecord]) -> Result<(), BatchError> {
    let mut text = String::new();
    for r in records {
        text.push_str(&serde_json::to_string(r).map_err(|e| BatchError::Internal(e.to_string()))?);
        text.push('\n');
    }
    super::write_atomic(path, text.as_bytes())
}

pub(super) fn remove_if_present(path: &Path) -> Result<(), BatchError> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(io(path)(e)),
        _ => Ok(()),
    }
}

/// The summary of a finished batch directory, derived from its `trials.jsonl` (never
/// from a `summary.json` that may be stale): refuses a directory without a manifest,
/// with duplicate records, or with fewer trials than its manifest names.
pub fn load_results(dir: &Path) -> Result<Summary, BatchError> {
    load_batch(dir).map(|(summary, _, _)| summary)
}

/// [`load_results`] with the records it summarised and the manifest they were checked
/// against, read once.
pub fn load_batch(dir: &Path) -> Result<(Summary, Vec<TrialRecord>, Manifest), BatchError> {
    let m = Manifest::read(dir)?.ok_or_else(|| {
        BatchError::Directory(format!(
            "{}: no manifest.json, so not a forkbench batch directory (or one from an older \
             version: run the batch again)",
            dir.display()
        ))
    })?;
    let records = complete_records(dir, &m)?;
    let mut summary = summarize_with(&records, m.success_run);
    summary.provenance = written_provenance(dir);
    Ok((summary, records, m))
}

/// The provenance the batch wrote into its `summary.json`, if any (informative: the
/// numbers always come from `trials.jsonl`).
fn written_provenance(dir: &Path) -> Option<super::Provenance> {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    let s: Summary = serde_json::from_str(&text).ok()?;
    s.provenance
}

/// The records of `dir`, refused unless they are exactly the trials manifest `m` names
/// (no duplicates, none missing).
fn complete_records(dir: &Path, m: &Manifest) -> Result<Vec<TrialRecord>, BatchError> {
    let path = dir.join("trials.jsonl");
    let records = read_records(&path)?;
    check_unique(&records, &path)?;
    let expected = m.expected_trials();
    if records.len() as u64 > expected {
        return Err(BatchError::Content(format!(
            "{}: holds {} trials, more than the {expected} its manifest names: records were \
             added or the manifest edited; rerun the batch into a new directory",
            dir.display(),
            records.len()
        )));
    }
    if records.len() as u64 != expected || expected == 0 {
        return Err(BatchError::Directory(format!(
            "{}: holds {} of the {expected} trials its manifest names (interrupted?); \
             resume it with the batch's own arguments (its manifest.json says them)",
            dir.display(),
            records.len()
        )));
    }
    // The count alone is not enough: every record must be a trial the manifest names.
    if let Some(keys) = m.expected_keys()
        && let Some(stray) = records.iter().find(|r| !keys.contains(&r.key()))
    {
        return Err(BatchError::Content(format!(
            "{}: holds a trial its manifest does not name ({}); the file was edited or \
             mixed with another batch's",
            path.display(),
            forkbench_trial::text::one_line(&format!("{:?}", stray.key()))
        )));
    }
    Ok(records)
}

/// Shards of one batch state their success runs alike: the trials are the same whatever
/// the statement, and which one the merged summary makes is not the merge's to pick.
fn same_success_run(
    (first, m0): (&Path, &Manifest),
    (d, m): (&Path, &Manifest),
) -> Result<(), BatchError> {
    if m.success_run == m0.success_run {
        return Ok(());
    }
    let said = |t: &crate::success_run::SuccessTarget| {
        format!(
            "confidence {} and reliability {}",
            t.confidence, t.reliability
        )
    };
    Err(BatchError::Directory(format!(
        "{} states its success runs at {}, {} at {}: run the shards with one \
         --success-confidence and --success-reliability",
        first.display(),
        said(&m0.success_run),
        d.display(),
        said(&m.success_run)
    )))
}

/// Merges the shards of one batch into `out` and summarises. Refuses inputs from
/// different batches, duplicate or missing shards, unfinished shards, no inputs, and
/// an `out` that is one of the inputs.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<Summary, BatchError> {
    let first = dirs
        .first()
        .ok_or_else(|| BatchError::Setting("merge needs at least one input directory".into()))?;
    let out_real = std::fs::canonicalize(out).ok();
    let manifests = dirs
        .iter()
        .map(|d| {
            if out_real.is_some() && std::fs::canonicalize(d).ok() == out_real {
                return Err(BatchError::Directory(format!(
                    "{}: is both an input and the output; merge into a new directory",
                    d.display()
                )));
            }
            Manifest::read(d)?.ok_or_else(|| {
                BatchError::Directory(format!(
                    "{}: no manifest.json (not a batch directory?)",
                    d.display()
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let m0 = &manifests[0];
    let n = m0.shard[1];
    let mut by_index: BTreeMap<u64, &PathBuf> = BTreeMap::new();
    for (d, m) in dirs.iter().zip(&manifests) {
        let diff = m0.batch_differences(m);
        if !diff.is_empty() {
            return Err(BatchError::Directory(format!(
                "{} and {} are shards of different batches ({})",
                first.display(),
                d.display(),
                diff.into_iter().take(8).collect::<Vec<_>>().join("; ")
            )));
        }
        same_success_run((first, m0), (d, m))?;
        if let Some(other) = by_index.insert(m.shard[0], d) {
            return Err(BatchError::Directory(format!(
                "shard {}/{n} given twice: {} and {}",
                m.shard[0],
                other.display(),
                d.display()
            )));
        }
    }
    let missing: Vec<String> = (0..n)
        .filter(|i| !by_index.contains_key(i))
        .map(|i| i.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(BatchError::Directory(format!(
            "shards {} of {n} are missing",
            missing.join(", ")
        )));
    }
    let mut all = Vec::new();
    for (d, m) in dirs.iter().zip(&manifests) {
        all.extend(complete_records(d, m)?);
    }
    all.sort_by_key(TrialRecord::key);
    std::fs::create_dir_all(out).map_err(io(out))?;
    let _lock = DirLock::take(out)?;
    let path = out.join("trials.jsonl");
    check_unique(&all, &path)?;
    let mut merged = m0.clone();
    merged.shard = [0, 1];
    // A merge killed from here on leaves no summary of an older merge beside new records.
    remove_if_present(&out.join("summary.json"))?;
    remove_if_present(&out.join("summary.md"))?;
    merged.write(out)?;
    rewrite_records(&path, &all)?;
    let mut summary = summarize_with(&all, merged.success_run);
    // The merge's own provenance (this host, now); each shard's stays in its directory.
    let now = std::time::SystemTime::now();
    summary.provenance = Some(super::Provenance::collect(merged, 1, now));
    write_summary(out, &summary)?;
    Ok(summary)
}
