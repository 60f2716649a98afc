//! `forkbench dataset`: labelled scans on demand, a ROS 2 bag of randomised scenes (a pallet or none, clutter) and the labels `detect --labels` reads, optionally as NumPy arrays, streamed to disk scan by scan.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, bail};
use forkbench_core::files::AtomicWriter;
use forkbench_log::ros2::scan_bag::ScanBag;
use forkbench_sensors::dataset::{DatasetSpec, Sample, sample};
use serde_json::json;

/// A spec file is a few settings.
const MAX_SPEC_BYTES: u64 = 1 << 20;
/// The scans' frame and topic in the bag.
const FRAME: &str = "laser";
const TOPIC: &str = "/scan";
/// Time between the scans' stamps (s).
const STAMP_STEP_S: f64 = 0.1;

#[derive(Debug, clap::Args)]
pub struct DatasetArgs {
    /// The set's settings (TOML; every key in docs/detection.md); none: the defaults.
    spec: Option<PathBuf>,
    /// Directory for scans.mcap, labels.json (and with --npy scans.npy, labels.npy).
    #[arg(long)]
    out: PathBuf,
    /// Scans, overriding the spec's `scans`.
    #[arg(long)]
    scans: Option<usize>,
    /// Seed, overriding the spec's `seed`.
    #[arg(long)]
    seed: Option<u64>,
    /// Also write the ranges (N × beams, float32, NaN for no return) and the labels
    /// (N × 4: present, x_m, y_m, heading_rad; NaN without a pallet) as .npy.
    #[arg(long)]
    npy: bool,
}

fn read_spec(a: &DatasetArgs) -> anyhow::Result<(DatasetSpec, PathBuf)> {
    let (mut spec, base) = match &a.spec {
        Some(f) => {
            let text = forkbench_core::files::read_text(f, MAX_SPEC_BYTES)?;
            let spec: DatasetSpec =
                toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", f.display()))?;
            let base = f.parent().unwrap_or(Path::new(".")).to_path_buf();
            (spec, base)
        }
        None => (DatasetSpec::default(), PathBuf::from(".")),
    };
    if let Some(n) = a.scans {
        spec.scans = n;
    }
    if let Some(s) = a.seed {
        spec.seed = s;
    }
    let name = a
        .spec
        .as_ref()
        .map_or("the default spec".to_owned(), |f| f.display().to_string());
    spec.validate().with_context(|| name.clone())?;
    Ok((spec, base))
}

pub fn run(a: &DatasetArgs) -> anyhow::Result<()> {
    let (spec, base) = read_spec(a)?;
    // A scenario path is relative to the spec; a name that is no file there is embedded.
    let beside = base.join(&spec.scenario);
    let scenario = if beside.is_file() {
        beside
    } else {
        PathBuf::from(&spec.scenario)
    };
    let scn = forkbench_trial::defaults::load_scenario(&scenario)
        .with_context(|| format!("scenario {:?}", spec.scenario))?;
    let scanner = scn
        .pallet_sensing
        .scanner_or_preset(&spec.scanner)
        .map_err(|e| anyhow::anyhow!("scanner {e}"))?;
    let name = a
        .spec
        .as_ref()
        .map_or("the default spec".to_owned(), |f| f.display().to_string());
    let (spec, clipped) = spec
        .within_view(scanner.range_max_m, scanner.fov_rad)
        .with_context(|| format!("{name}: with scanner {}", spec.scanner))?;
    if clipped {
        eprintln!(
            "note: faces drawn only where the {} sees them: range {:?} m, bearing {:?}°",
            spec.scanner, spec.range_m, spec.bearing_deg
        );
    }
    prepare_dir(&a.out, a.npy)?;
    let present = write_set(a, &spec, (&scn, &scanner))?;
    let (bag, labels_path) = (a.out.join("scans.mcap"), a.out.join("labels.json"));
    crate::emit(&format!(
        "wrote {} ({} scans on {TOPIC}, frame {FRAME}; {present} with a pallet ({}), {} without) and {}\n\
         score a detector on it: forkbench detect {} --labels {} --scenario {}\n",
        bag.display(),
        spec.scans,
        scn.pallet_kind,
        spec.scans - present,
        labels_path.display(),
        bag.display(),
        labels_path.display(),
        scenario.display(),
    ))
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

/// Draws and writes the set scan by scan (memory holds one scan, its label, and the
/// writers' buffers); each file appears when all are written, the labels last. Returns how
/// many scans hold a pallet.
fn write_set(
    a: &DatasetArgs,
    spec: &DatasetSpec,
    (scn, scanner): (
        &forkbench_trial::Scenario,
        &forkbench_sensors::scan::ScannerConfig,
    ),
) -> anyhow::Result<usize> {
    let meta: BTreeMap<String, String> = [
        ("dataset".to_owned(), serde_json::to_string(spec)?),
        ("pallet".to_owned(), scn.pallet_kind.clone()),
    ]
    .into();
    let mut bag = ScanBag::create(&a.out.join("scans.mcap"), TOPIC, FRAME, meta)?;
    let mut labels = AtomicWriter::create(&a.out.join("labels.json"))?;
    let head = json!({"dataset": spec, "frame": FRAME, "files": set_files(a.npy)});
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
        if a.npy {
            let (ranges, rows) = match &mut arrays {
                Some(w) => w,
                None => arrays.insert(npy_writers(&a.out, spec.scans, s.scan.ranges_m.len())?),
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
    forkbench_core::files::write_atomic(&a.out.join("metadata.yaml"), metadata.as_bytes())?;
    labels.commit()?;
    Ok(present)
}

/// `out` made if missing. Something else than a directory there is refused, and so is a
/// folder with files but no set of forkbench's (its `labels.json` is replaced only when
/// forkbench wrote it), or with an earlier set's arrays this run would leave stale.
fn prepare_dir(out: &Path, npy: bool) -> anyhow::Result<()> {
    let shown = out.display();
    match std::fs::symlink_metadata(out) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => bail!("--out {shown}: exists and is not a directory"),
        Err(_) => {
            return std::fs::create_dir_all(out)
                .with_context(|| format!("--out {shown}: cannot create it"));
        }
    }
    let empty = std::fs::read_dir(out)
        .with_context(|| format!("--out {shown}: cannot list it"))?
        .next()
        .is_none();
    if empty {
        return Ok(());
    }
    if !holds_a_set(&out.join("labels.json")) {
        bail!(
            "--out {shown}: holds files but no dataset forkbench wrote (no labels.json of \
             `forkbench dataset`); give an empty or new folder"
        );
    }
    let stale: Vec<&str> = set_files(true)
        .iter()
        .filter(|f| !set_files(npy).contains(f) && out.join(f).exists())
        .copied()
        .collect();
    if !stale.is_empty() {
        bail!(
            "--out {shown}: holds {} of an earlier set, which this run (without --npy) would \
             leave beside labels that do not match them; add --npy, or give another folder",
            stale.join(" and ")
        );
    }
    Ok(())
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
) -> anyhow::Result<(AtomicWriter, AtomicWriter)> {
    let mut ranges = AtomicWriter::create(&out.join("scans.npy"))?;
    ranges.write(&npy_header((scans, beams)))?;
    let mut rows = AtomicWriter::create(&out.join("labels.npy"))?;
    rows.write(&npy_header((scans, 4)))?;
    Ok((ranges, rows))
}

/// One scan's row of each array: its ranges (NaN for no return), and present, x_m, y_m,
/// heading_rad (NaN without a pallet).
fn npy_row(ranges: &mut AtomicWriter, rows: &mut AtomicWriter, s: &Sample) -> anyhow::Result<()> {
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
