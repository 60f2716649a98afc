//! `forkbench baseline`, `regress` and `compare`: the regression gate and A/B comparisons on common random numbers.

use std::path::{Path, PathBuf};

use anyhow::bail;
use forkbench_batch::stats::Correction;
use forkbench_batch::{self as batch, Baseline, CompareOptions, GateOptions};

/// How rows tested together are corrected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CorrectionArg {
    /// Holm's step-down (family-wise error ≤ α).
    Holm,
    /// Benjamini–Hochberg (false discovery rate ≤ α).
    Bh,
    /// None: each row at α on its own.
    None,
}

impl From<CorrectionArg> for Correction {
    fn from(c: CorrectionArg) -> Self {
        match c {
            CorrectionArg::Holm => Correction::Holm,
            CorrectionArg::Bh => Correction::BenjaminiHochberg,
            CorrectionArg::None => Correction::None,
        }
    }
}

/// `forkbench regress`.
#[derive(Debug, Clone, clap::Args)]
pub struct RegressArgs {
    #[arg(long)]
    pub baseline: PathBuf,
    pub results: PathBuf,
    /// Level of the whole gate (all rows together, after --correction).
    #[arg(long, default_value_t = batch::DEFAULT_ALPHA)]
    pub alpha: f64,
    /// Multiplicity correction over the rows.
    #[arg(long, value_enum, default_value_t = CorrectionArg::Holm)]
    pub correction: CorrectionArg,
    /// Absolute floor on every row's success rate (0–1).
    #[arg(long)]
    pub floor: Option<f64>,
    /// Fail on rows the baseline does not have (default: listed as new, unchecked).
    #[arg(long)]
    pub fail_on_new: bool,
    /// The drop (0–1, e.g. 0.05) the gate must see with 80 % power: each row says how
    /// many trials that needs, and rows with fewer fail as underpowered.
    #[arg(long)]
    pub min_detectable_drop: Option<f64>,
    /// A gate file (TOML) setting measures' margins and directions: `[measure.NAME]`
    /// with `margin` (in the measure's unit), `worse = "higher"|"lower"` and
    /// `gate = false` (see the gate chapter).
    #[arg(long, value_name = "FILE")]
    pub gate: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
    /// Also write the verdicts as JUnit XML to FILE (a failing case per failed row).
    #[arg(long)]
    pub junit: Option<PathBuf>,
    /// Gate the results' planner or tracker CANDIDATE as the baseline's SHIPPED
    /// (`--as mypp=pure_pursuit`, repeatable): its trials pair with the shipped one's at
    /// the same seeds, and what else changed is listed.
    #[arg(long = "as", value_name = "CANDIDATE=SHIPPED")]
    pub mappings: Vec<batch::Mapping>,
}

/// `forkbench compare`.
#[derive(Debug, Clone, clap::Args)]
pub struct CompareArgs {
    /// A batch directory that ran both components (e.g. `batch --planner A B`).
    pub results: PathBuf,
    /// Planner or tracker A, by name.
    #[arg(long)]
    pub a: String,
    /// Planner or tracker B, by name.
    #[arg(long)]
    pub b: String,
    /// Take B's trials from this batch directory instead (your candidate run apart from
    /// what you ship): the two batches pair trial by trial when their seed and seed
    /// scheme match, and are refused otherwise.
    #[arg(long, value_name = "DIR")]
    pub b_from: Option<PathBuf>,
    #[arg(long, default_value_t = batch::DEFAULT_ALPHA)]
    pub alpha: f64,
    #[arg(long, value_enum, default_value_t = CorrectionArg::Holm)]
    pub correction: CorrectionArg,
    #[arg(long)]
    pub json: bool,
}

/// `forkbench baseline`: success counts and every trial's outcome, written atomically.
pub fn baseline(dir: &Path, out: &Path, description: Option<String>) -> anyhow::Result<()> {
    forkbench_core::files::check_not_input(out, &batch::batch_files(dir))?;
    let (s, records, _) = batch::load_batch(dir)?;
    let description =
        description.unwrap_or_else(|| format!("success counts from {}", dir.display()));
    let b = Baseline::from_results(&s, &records, description);
    b.write(out)?;
    let said = format!(
        "baseline with {} rows and {} trials written to {}\n",
        b.rows.len(),
        b.trials.len(),
        out.display()
    );
    if forkbench_core::files::is_stdout(out) {
        // The baseline itself went to standard output.
        eprint!("{}", forkbench_trial::text::visible(&said));
        Ok(())
    } else {
        crate::emit(&said)
    }
}

/// The gate over a results directory, and the results' provenance.
pub(crate) fn gate(
    base: &Baseline,
    dir: &Path,
    mappings: &[batch::Mapping],
    o: &GateOptions,
) -> anyhow::Result<(batch::GateReport, Option<batch::Provenance>)> {
    let (s, records, manifest) = batch::load_batch(dir)?;
    let (s, records) = if mappings.is_empty() {
        (s, records)
    } else {
        let shipped = base
            .rows
            .iter()
            .flat_map(|r| [r.planner.as_str(), r.tracker.as_str()])
            .collect();
        let mapped = batch::map_components(&records, mappings, &shipped)?;
        let summary = batch::Summary {
            provenance: s.provenance.clone(),
            ..batch::summarize(&mapped)
        };
        (summary, mapped)
    };
    let report = batch::regress(base, &s, &records, Some(&manifest), o);
    Ok((report, s.provenance))
}

/// Returns whether the gate passed.
pub fn regress(a: &RegressArgs) -> anyhow::Result<bool> {
    let o = GateOptions {
        alpha: a.alpha,
        correction: a.correction.into(),
        floor: a.floor,
        fail_on_new: a.fail_on_new,
        min_detectable_drop: a.min_detectable_drop,
        measures: batch::MeasureSettings::load_or_default(a.gate.as_deref())?,
    };
    o.validate()?;
    if let Some(file) = &a.junit {
        let mut inputs = batch::batch_files(&a.results);
        inputs.push(a.baseline.clone());
        forkbench_core::files::check_not_input(file, &inputs)?;
    }
    let b = Baseline::load(&a.baseline)?;
    let (report, provenance) = gate(&b, &a.results, &a.mappings, &o)?;
    if let batch::Pairing::Unpaired { reason } = &report.pairing {
        eprintln!(
            "warning: compared unpaired: {}",
            forkbench_trial::text::visible(reason)
        );
    }
    if let Some(note) = &report.measures_note {
        eprintln!("warning: {}", forkbench_trial::text::visible(note));
    }
    for c in &report.setting_differences {
        eprintln!(
            "note: changed since the baseline's batch (still paired by seed): {}",
            forkbench_trial::text::visible(c)
        );
    }
    if let Some(file) = &a.junit {
        let cases = batch::junit::regress_cases(&report, a.fail_on_new, &a.mappings);
        let xml = batch::junit::junit_xml("forkbench regress", &cases, provenance.as_ref());
        batch::write_atomic(file, xml.as_bytes())?;
    }
    if a.json {
        crate::emit(&format!("{}\n", serde_json::to_string(&report)?))?;
    } else {
        crate::emit(&report.markdown())?;
    }
    Ok(report.passed)
}

/// `forkbench compare`: A against B in one batch (or B from another), pair by pair.
pub fn compare(a: &CompareArgs) -> anyhow::Result<()> {
    let trials = |dir: &Path| -> anyhow::Result<PathBuf> {
        let file = dir.join("trials.jsonl");
        if !file.is_file() {
            bail!("{}: no trials.jsonl (not a batch directory)", dir.display());
        }
        Ok(file)
    };
    let file = trials(&a.results)?;
    let records = batch::read_numbered(&file)?;
    let o = CompareOptions {
        alpha: a.alpha,
        correction: a.correction.into(),
    };
    let (report, label) = match &a.b_from {
        None => (
            batch::compare(&records, &a.a, &a.b, &o)?,
            file.display().to_string(),
        ),
        Some(other) => {
            let file_b = trials(other)?;
            same_seeds(&a.results, other)?;
            let records_b = batch::read_numbered(&file_b)?;
            let report = batch::compare_apart((&records, &records_b), &a.a, &a.b, &o)?;
            let label = format!(
                "{} (line A) / {} (line B)",
                file.display(),
                file_b.display()
            );
            (report, label)
        }
    };
    if a.json {
        return crate::emit(&format!("{}\n", serde_json::to_string(&report)?));
    }
    crate::emit(&report.markdown(&label))
}

/// Two batches pair trial by trial only when their seeds come from the same batch seed
/// by the same scheme.
fn same_seeds(a: &Path, b: &Path) -> anyhow::Result<()> {
    let read = |d: &Path| -> anyhow::Result<batch::Manifest> {
        batch::Manifest::read(d)?.ok_or_else(|| {
            anyhow::anyhow!("{}: no manifest.json (not a batch directory)", d.display())
        })
    };
    let (ma, mb) = (read(a)?, read(b)?);
    if let Some(why) = ma.seed_difference(&mb, &b.display().to_string()) {
        bail!(
            "{}: {why}; their trials are not the same trials, so they cannot be paired; run \
             both with the same --seed",
            a.display()
        );
    }
    Ok(())
}
