//! A labelled scan set on disk, as `forkbench dataset` writes it: the scans as a ROS 2 bag (with its rosbag2 metadata), their labels as JSON and, when asked, both as NumPy arrays, streamed scan by scan and each file appearing only when complete.

use std::collections::BTreeMap;
use std::path::Path;

use forkbench_core::files::AtomicWriter;
use forkbench_sensors::dataset::{DatasetSpec, Sample, sample};
use forkbench_sensors::scan::ScannerConfig;
use forkbench_trial::Scenario;
use serde_json::json;

use crate::LogError;
use crate::ros2::scan_bag::ScanBag;

/// The scans' frame and topic in the bag.
pub const FRAME: &str = "laser";
pub const TOPIC: &str = "/scan";
/// Time between the scans' stamps (s).
const STAMP_STEP_S: f64 = 0.1;

/// Why a folder cannot take a set.
#[derive(Debug, thiserror::Error)]
pub enum SetDirError {
    #[error("{0}: exists and is not a directory")]
    NotADirectory(String),
    #[error("{path}: cannot {what} it: {reason}")]
    Io {
        path: String,
        what: &'static str,
        reason: String,
    },
    #[error(
        "{0}: holds files but no dataset forkbench wrote (no labels.json of `forkbench \
         dataset`); give an empty or new folder"
    )]
    NotASet(String),
    #[error(
        "{path}: holds {files} of an earlier set, which this run (without --npy) would leave \
         beside labels that do not match them; add --npy, or give another folder"
    )]
    Stale { path: String, files: String },
}

/// `out` made if missing. Something else than a directory there is refused, and so is a
/// folder with files but no set of forkbench's (its `labels.json` is replaced only when
/// forkbench wrote it), or with an earlier set's arrays this run would leave stale.
pub fn prepare_dir(out: &Path, npy: bool) -> Result<(), SetDirError> {
    let shown = out.display().to_string();
    let io = |what, e: std::io::Error| SetDirError::Io {
        path: shown.clone(),
        what,
        reason: e.to_string(),
    };
    match std::fs::symlink_metadata(out) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => return Err(SetDirError::NotADirectory(shown)),
        Err(_) => return std::fs::create_dir_all(out).map_err(|e| io("create", e)),
    }
    let empty = std::fs::read_dir(out)
        .map_err(|e| io("list", e))?
        .next()
        .is_none();
    if empty {
        return Ok(());
    }
    if !holds_a_set(&out.join("labels.json")) {
        return Err(SetDirError::NotASet(shown));
    }
    let stale: Vec<&str> = set_files(true)
        .iter()
        .filter(|f| !set_files(npy).contains(f) && out.join(f).exists())
        .copied()
        .collect();
    if !stale.is_empty() {
        return Err(SetDirError::Stale {
            path: shown,
            files: stale.join(" and "),
        });
    }
    Ok(())
}

/// Draws `spec`'s scans of `scn`'s pallet with `scanner` and writes the set into `out`
/// scan by scan (memory holds one scan, its label, and the writers' buffers); each file
/// appears when all are written, the labels last. Returns how many scans hold a pallet.
pub fn write_set(
    out: &Path,
    spec: &DatasetSpec,
    (scn, scanner): (&Scenario, &ScannerConfig),
    npy: bool,
) -> Result<usize, LogError> {
    let labels_path = out.join("labels.json");
    let spec_json = serde_json::to_string(spec).map_err(|e| LogError::Io {
        path: labels_path.display().to_string(),
        message: e.to_string(),
    })?;
    let meta: BTreeMap<String, String> = [
        ("dataset".to_owned(), spec_json),
        ("pallet".to_owned(), scn.pallet_kind.clone()),
    ]
    .into();
    let mut bag = ScanBag::create(&out.join("scans.mcap"), TOPIC, FRAME, meta)?;
    let mut labels = AtomicWriter::create(&labels_path)?;
    let head = json!({"dataset": spec, "frame": FRAME, "files": set_files(npy)});
    let head = head.to_string();
    labels.write(format!("{}, \"scans\": [\n", &head[..head.len() - 1]).as_bytes())?;
    let mut arrays: Option<(AtomicWriter, AtomicWriter)> = None;
    let mut present = 0;
    for i in 0..spec.scans {
        let s = sample(spec, &scn.pallet, scanner, i);
        bag.write(s.index as f64 * STAMP_STEP_S, &s.scan)?;
        let sep = if i + 1 < spec.scans { ",\n" } else { "\n" };
        labels.write(format!("{}{sep}", label(&scn.pallet_kind, &s)).as_bytes())?;
        present += usize::from(s.face.is_some());
        if npy {
            let (ranges, rows) = match &mut arrays {
                Some(w) => w,
                None => arrays.insert(npy_writers(out, spec.scans, s.scan.ranges_m.len())?),
            };
            npy_row(ranges, rows, &s)?;
        }
    }
    labels.write(b"]}\n")?;
    if let Some((ranges, rows)) = arrays {
        ranges.commit()?;
        rows.commit()?;
    }
    let metadata = bag.rosbag2_metadata("scans.mcap");
    bag.finish()?;
    forkbench_core::files::write_atomic(&out.join("metadata.yaml"), metadata.as_bytes())?;
    labels.commit()?;
    Ok(present)
}

/// The files of a set: the bag and labels, and with `npy` the arrays.
fn set_files(npy: bool) -> &'static [&'static str] {
    if npy {
        &[
            "scans.mcap",
            "metadata.yaml",
            "labels.json",
            "scans.npy",
            "labels.npy",
        ]
    } else {
        &["scans.mcap", "metadata.yaml", "labels.json"]
    }
}

/// Whether `labels` is a labels file `forkbench dataset` wrote: a regular file whose head
/// (the set's settings come first) names the dataset and its frame.
fn holds_a_set(labels: &Path) -> bool {
    use std::io::Read as _;
    let regular = std::fs::symlink_metadata(labels).is_ok_and(|m| m.is_file());
    let mut head = Vec::new();
    let read = regular
        && std::fs::File::open(labels)
            .and_then(|f| f.take(64 << 10).read_to_end(&mut head))
            .is_ok();
    let head = String::from_utf8_lossy(&head);
    read && head.trim_start().starts_with("{")
        && head.contains("\"dataset\"")
        && head.contains("\"frame\"")
}

/// One scan's label as JSON.
fn label(kind: &str, s: &Sample) -> serde_json::Value {
    let p = &s.prior;
    let prior = json!({"x_m": p.x_m, "y_m": p.y_m, "heading_deg": p.heading_rad.to_degrees()});
    let mut v = json!({"index": s.index, "present": s.face.is_some(), "clutter": s.clutter, "prior": prior});
    if let Some(f) = s.face {
        v["face"] = json!({"x_m": f.x_m, "y_m": f.y_m, "heading_deg": f.heading_rad.to_degrees()});
        v["kind"] = json!(kind);
    }
    v
}

/// A NumPy .npy (format 1.0) header for little-endian float32 rows of `shape`.
fn npy_header(shape: (usize, usize)) -> Vec<u8> {
    let dict = format!(
        "{{'descr': '<f4', 'fortran_order': False, 'shape': ({}, {}), }}",
        shape.0, shape.1
    );
    // Magic, version, header length, then the header padded so the data starts on 64 bytes.
    let unpadded = 10 + dict.len() + 1;
    let pad = (64 - unpadded % 64) % 64;
    let header = format!("{dict}{}\n", " ".repeat(pad));
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(
        &u16::try_from(header.len())
            .unwrap_or(u16::MAX)
            .to_le_bytes(),
    );
    out.extend_from_slice(header.as_bytes());
    out
}

/// The ranges' (N × beams) and the labels' (N × 4) arrays, headers written.
fn npy_writers(
    out: &Path,
    scans: usize,
    beams: usize,
) -> Result<(AtomicWriter, AtomicWriter), LogError> {
    let mut ranges = AtomicWriter::create(&out.join("scans.npy"))?;
    ranges.write(&npy_header((scans, beams)))?;
    let mut rows = AtomicWriter::create(&out.join("labels.npy"))?;
    rows.write(&npy_header((scans, 4)))?;
    Ok((ranges, rows))
}

/// One scan's row of each array: its ranges (NaN for no return), and present, x_m, y_m,
/// heading_rad (NaN without a pallet).
fn npy_row(ranges: &mut AtomicWriter, rows: &mut AtomicWriter, s: &Sample) -> Result<(), LogError> {
    let bytes: Vec<u8> = s
        .scan
        .ranges_m
        .iter()
        .flat_map(|r| (*r as f32).to_le_bytes())
        .collect();
    ranges.write(&bytes)?;
    let f = s.face;
    let row: Vec<u8> = [
        f32::from(u8::from(f.is_some())),
        f.map_or(f32::NAN, |f| f.x_m as f32),
        f.map_or(f32::NAN, |f| f.y_m as f32),
        f.map_or(f32::NAN, |f| f.heading_rad as f32),
    ]
    .iter()
    .flat_map(|v| v.to_le_bytes())
    .collect();
    rows.write(&row)?;
    Ok(())
}
