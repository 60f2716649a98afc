//! `forkbench dataset`: labelled scans on demand, a ROS 2 bag of randomised scenes (a pallet or none, clutter) and the labels `detect --labels` reads, optionally as NumPy arrays.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, bail};
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
    prepare_dir(&a.out)?;
    let samples: Vec<Sample> = (0..spec.scans)
        .map(|i| sample(&spec, &scn.pallet, &scanner, i))
        .collect();
    let scans: Vec<(f64, forkbench_core::signal::Scan)> = samples
        .iter()
        .map(|s| (s.index as f64 * STAMP_STEP_S, s.scan.clone()))
        .collect();
    let meta: BTreeMap<String, String> = [
        ("dataset".to_owned(), serde_json::to_string(&spec)?),
        ("pallet".to_owned(), scn.pallet_kind.clone()),
    ]
    .into();
    let bag = a.out.join("scans.mcap");
    forkbench_log::ros2::scan_bag::write_scan_bag(&bag, TOPIC, FRAME, &scans, meta)?;
    let labels = labels_json(&spec, &scn.pallet_kind, &samples);
    let labels_path = a.out.join("labels.json");
    forkbench_core::files::write_atomic(&labels_path, format!("{labels:#}\n").as_bytes())?;
    if a.npy {
        write_npy(&a.out, &samples)?;
    }
    let present = samples.iter().filter(|s| s.face.is_some()).count();
    crate::emit(&format!(
        "wrote {} ({} scans on {TOPIC}, frame {FRAME}; {present} with a pallet ({}), {} without) and {}\n\
         score a detector on it: forkbench detect {} --labels {} --scenario {}\n",
        bag.display(),
        samples.len(),
        scn.pallet_kind,
        samples.len() - present,
        labels_path.display(),
        bag.display(),
        labels_path.display(),
        scenario.display(),
    ))
}

/// `out` made if missing; something else than a directory there is refused.
fn prepare_dir(out: &Path) -> anyhow::Result<()> {
    match std::fs::symlink_metadata(out) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => bail!("--out {}: exists and is not a directory", out.display()),
        Err(_) => std::fs::create_dir_all(out)
            .with_context(|| format!("--out {}: cannot create it", out.display())),
    }
}

fn labels_json(spec: &DatasetSpec, kind: &str, samples: &[Sample]) -> serde_json::Value {
    let scans: Vec<serde_json::Value> = samples
        .iter()
        .map(|s| {
            let mut v =
                json!({"index": s.index, "present": s.face.is_some(), "clutter": s.clutter});
            if let Some(f) = s.face {
                v["face"] =
                    json!({"x_m": f.x_m, "y_m": f.y_m, "heading_deg": f.heading_rad.to_degrees()});
                v["kind"] = json!(kind);
            }
            v
        })
        .collect();
    json!({"dataset": spec, "frame": FRAME, "scans": scans})
}

/// A NumPy .npy (format 1.0) of little-endian float32 rows.
fn npy(shape: (usize, usize), values: impl Iterator<Item = f32>) -> Vec<u8> {
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
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

fn write_npy(out: &Path, samples: &[Sample]) -> anyhow::Result<()> {
    let beams = samples.first().map_or(0, |s| s.scan.ranges_m.len());
    let ranges = npy(
        (samples.len(), beams),
        samples
            .iter()
            .flat_map(|s| s.scan.ranges_m.iter().map(|r| *r as f32)),
    );
    forkbench_core::files::write_atomic(&out.join("scans.npy"), &ranges)?;
    let labels = npy(
        (samples.len(), 4),
        samples.iter().flat_map(|s| {
            let f = s.face;
            [
                f32::from(u8::from(f.is_some())),
                f.map_or(f32::NAN, |f| f.x_m as f32),
                f.map_or(f32::NAN, |f| f.y_m as f32),
                f.map_or(f32::NAN, |f| f.heading_rad as f32),
            ]
        }),
    );
    forkbench_core::files::write_atomic(&out.join("labels.npy"), &labels)?;
    Ok(())
}
