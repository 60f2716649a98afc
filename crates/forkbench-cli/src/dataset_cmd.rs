//! `forkbench dataset`: labelled scans on demand, a ROS 2 bag of randomised scenes (a pallet or none, clutter) and the labels `detect --labels` reads, optionally as NumPy arrays, streamed to disk scan by scan.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use forkbench_log::dataset_set::{FRAME, TOPIC, prepare_dir, write_set};
use forkbench_sensors::dataset::DatasetSpec;

/// A spec file is a few settings.
const MAX_SPEC_BYTES: u64 = 1 << 20;

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
    prepare_dir(&a.out, a.npy).map_err(|e| anyhow::anyhow!("--out {e}"))?;
    let present = write_set(&a.out, &spec, (&scn, &scanner), a.npy)?;
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
