//! `forkbench detect`: a pallet detector on recorded scans (a ROS 2 bag or a forkbench MCAP), a JSON line per scan, a summary, and with labels precision, recall and pose errors.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, bail};
use forkbench_batch::detect_curve::{
    ByPlace, ClutterScore, CurvePoint, by_clutter, by_place, curve,
};
use forkbench_batch::detect_eval::{Gate, Label, Scores, label_problems, parse_labels, score};
use forkbench_core::Pose2;
use forkbench_core::files::AtomicWriter;
use forkbench_log::bag::BagSummary;
use forkbench_log::detect::{DetectOptions, DetectRunError, ScanResult, detect_bag};
use forkbench_trial::{ComponentSpec, Role};
use serde_json::json;

/// Labels files are small: one line of JSON per scan.
const MAX_LABELS_BYTES: u64 = 256 << 20;

#[derive(Debug, clap::Args)]
pub struct DetectArgs {
    /// A ROS 2 bag in MCAP storage (sensor_msgs/msg/LaserScan, CDR) or an MCAP written by
    /// forkbench (foxglove.LaserScan).
    bag: PathBuf,
    /// Laser-scan topic to read (repeatable; default: every one in the file).
    #[arg(long)]
    topic: Vec<String>,
    /// Scenario (file or embedded name) whose pallet and detector are used.
    #[arg(long, default_value = "field-test")]
    scenario: PathBuf,
    /// A detector instead of the scenario's, to compare detectors on the same bag: one a
    /// components file defines by name, or a registered kind with its default settings
    /// (`pockets`, `face_fit`).
    #[arg(long)]
    detector: Option<String>,
    /// Least evidence score (0–1) a located face needs to count as a pallet: its parts
    /// return at the face, the beams through its pockets go deeper, nothing stands in
    /// front. 0 reports every located face.
    #[arg(long, default_value_t = forkbench_log::detect::DEFAULT_MIN_SCORE)]
    min_score: f64,
    /// Detectors (and planners, trackers) defined by name (`[[detector]]` tables).
    #[arg(long, value_name = "FILE")]
    components: Option<PathBuf>,
    /// Give faces in FRAME (e.g. map), placing each scan through the file's /tf and
    /// /tf_static; default: each scan's own frame_id.
    #[arg(long)]
    frame: Option<String>,
    /// Where the pallet should be, `x,y,heading_deg` in that frame (heading into the
    /// pallet), for every scan; without it each scan's prior from --labels (as `forkbench
    /// dataset` writes them), else none: the detector searches the whole scan.
    #[arg(long, value_parser = crate::parse_pose, allow_hyphen_values = true)]
    prior: Option<Pose2>,
    /// Labels (JSON: {"scans": [{"index": 0, "present": true, "face": {"x_m": …, "y_m": …,
    /// "heading_deg": …}}]}): precision, recall and the face-pose errors.
    #[arg(long)]
    labels: Option<PathBuf>,
    /// A detection farther than this from the labelled face (m) is a false one.
    #[arg(long, default_value_t = 0.25)]
    match_m: f64,
    /// … or turned more than this (degrees).
    #[arg(long, default_value_t = 10.0)]
    match_deg: f64,
    /// Write one JSON line per scan to FILE.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
    /// Draw the labelled scans' errors to FILE (.svg or .png; needs --labels).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Draw precision, recall and false positives over the score threshold, and the
    /// precision-recall curve, to FILE (.svg or .png; needs --labels).
    #[arg(long)]
    curve: Option<PathBuf>,
}

impl DetectArgs {
    fn check(&self) -> anyhow::Result<(Gate, Option<BTreeMap<usize, Label>>)> {
        if !(self.match_m > 0.0 && self.match_m <= 10.0) {
            bail!("--match-m {}: from 0 (excluded) to 10 m", self.match_m);
        }
        if !(self.match_deg > 0.0 && self.match_deg <= 180.0) {
            bail!("--match-deg {}: from 0 (excluded) to 180°", self.match_deg);
        }
        if !(0.0..=1.0).contains(&self.min_score) {
            bail!("--min-score {}: from 0 to 1", self.min_score);
        }
        if let Some(p) = &self.prior {
            let lim = forkbench_trial::scenario::MAX_WORLD_EXTENT_M;
            if !(p.x_m.abs() <= lim && p.y_m.abs() <= lim && p.heading_rad.is_finite()) {
                bail!("--prior ({}, {}) m: must lie within ±{lim} m", p.x_m, p.y_m);
            }
        }
        if (self.plot.is_some() || self.curve.is_some()) && self.labels.is_none() {
            bail!("--plot and --curve draw against the labels: give --labels too");
        }
        let labels = match &self.labels {
            Some(f) => {
                let text = forkbench_core::files::read_text(f, MAX_LABELS_BYTES)?;
                Some(parse_labels(&text, &f.display().to_string())?)
            }
            None => None,
        };
        let per_scan = labels
            .as_ref()
            .is_some_and(|l| l.values().any(|l| l.prior.is_some()));
        if self.prior.is_some() && per_scan {
            bail!(
                "--prior gives every scan one prior, and {} gives each scan its own: drop \
                 one (the labels' priors are what the set was drawn with)",
                self.labels
                    .as_deref()
                    .map_or(String::new(), |f| f.display().to_string())
            );
        }
        let gate = Gate {
            position_m: self.match_m,
            heading_rad: self.match_deg.to_radians(),
        };
        Ok((gate, labels))
    }
}

/// The labelled scans' scores: at the threshold asked for, over every threshold, and by
/// the labelled face's range and bearing.
struct Scored {
    /// What the scores cannot say about the labels (`label_problems`).
    warnings: Vec<String>,
    /// The scans it got wrong (the first `MAX_LISTED`) and how many in all.
    wrong: (Vec<forkbench_batch::detect_wrong::Wrong>, usize),
    at_threshold: Scores,
    curve: Vec<CurvePoint>,
    by_place: ByPlace,
    by_clutter: Vec<ClutterScore>,
}

/// What the run saw, for the summary.
struct Tally {
    results: Vec<Option<Pose2>>,
    /// Each scan's located faces and their scores, for the curve over the threshold.
    candidates: Vec<Vec<(Pose2, f64)>>,
    errors: Vec<String>,
    found: usize,
    /// Located faces the evidence turned down.
    rejected: usize,
    seconds: f64,
}

/// What the detector is run with: the flags, and each scan's prior from the labels.
fn options(a: &DetectArgs, labels: Option<&BTreeMap<usize, Label>>) -> DetectOptions {
    DetectOptions {
        topics: a.topic.clone(),
        frame: a.frame.clone(),
        prior: a.prior,
        priors: labels
            .into_iter()
            .flatten()
            .filter_map(|(i, l)| Some((*i, l.prior.as_ref()?.pose())))
            .collect(),
        min_score: a.min_score,
    }
}

/// Runs `forkbench detect`: reads, detects, writes the lines, scores, prints.
pub fn run(a: &DetectArgs) -> anyhow::Result<()> {
    let (gate, labels) = a.check()?;
    let scn = crate::with_components(
        forkbench_trial::defaults::load_scenario(&a.scenario)?,
        a.components.as_deref(),
    )?;
    let (name, mut detector) = build_detector(a, &scn)?;
    let opts = options(a, labels.as_ref());
    if let Some(out) = &a.out {
        forkbench_core::files::check_not_input(out, std::slice::from_ref(&a.bag))?;
    }
    let mut lines = a.out.as_deref().map(AtomicWriter::create).transpose()?;
    let mut tally = Tally {
        results: Vec::new(),
        candidates: Vec::new(),
        errors: Vec::new(),
        found: 0,
        rejected: 0,
        seconds: 0.0,
    };
    let mut write_error = None;
    let started = Instant::now();
    let ran = detect_bag(&a.bag, &opts, detector.as_mut(), &scn.pallet, &mut |r| {
        take(r, &mut tally, lines.as_mut(), &mut write_error);
    });
    tally.seconds = started.elapsed().as_secs_f64();
    // What was computed is kept: the lines so far, then the error.
    if let Some(w) = lines {
        w.commit()?;
    }
    if let Some(e) = write_error {
        return Err(e);
    }
    let summary = ran.map_err(|e| match e {
        DetectRunError::Bag(e) => anyhow::anyhow!(e),
        DetectRunError::Detector(e) => anyhow::anyhow!(e),
    });
    let summary = summary.with_context(|| format!("after {} scans", tally.results.len()))?;
    check_topics(a, &summary)?;
    let scores = labels.as_ref().map(|l| Scored {
        warnings: label_problems(l, tally.results.len(), &scn.pallet_kind),
        wrong: forkbench_batch::detect_wrong::wrong_scans(&tally.results, l, gate),
        at_threshold: score(&tally.results, l, gate),
        curve: curve(&tally.candidates, l, gate),
        by_place: by_place(&tally.results, l, gate),
        by_clutter: by_clutter(&tally.results, l, gate),
    });
    if let (Some(file), Some(l)) = (&a.plot, &labels) {
        forkbench_report::detect::draw(file, &tally.results, l)?;
    }
    if let (Some(file), Some(s)) = (&a.curve, &scores) {
        forkbench_report::detect_curve::draw(file, &s.curve, a.min_score)?;
    }
    for w in scores.iter().flat_map(|s| &s.warnings) {
        eprintln!("warning: {}", forkbench_trial::text::visible(w));
    }
    report(a, &name, &summary, &tally, scores.as_ref())?;
    if !tally.errors.is_empty() {
        bail!(
            "{} of {} scans could not be used; the first: {}",
            tally.errors.len(),
            tally.results.len(),
            tally.errors[0]
        );
    }
    if let Some(first) = &summary.first_bad_transform {
        bail!(
            "{} transform messages could not be decoded (scans that needed them found no transform); the first: {first}",
            summary.bad_transforms
        );
    }
    Ok(())
}

/// `--detector KIND` with its default settings, or the scenario's own.
fn build_detector(
    a: &DetectArgs,
    scn: &forkbench_trial::Scenario,
) -> anyhow::Result<(String, Box<dyn forkbench_sensors::detector::PalletDetector>)> {
    Ok(match &a.detector {
        Some(kind) => {
            let spec = scn
                .named()
                .iter()
                .find(|s| s.role == Role::Detector && &s.name == kind)
                .cloned()
                .unwrap_or_else(|| ComponentSpec::of_kind(Role::Detector, kind));
            let d = scn
                .registry
                .detector(&spec)
                .map_err(|e| anyhow::anyhow!("--detector {kind}: {e}"))?;
            (kind.clone(), d)
        }
        None => forkbench_trial::trial::scenario_detector(scn)?,
    })
}

/// The file had laser scans, and every `--topic` named one of them.
fn check_topics(a: &DetectArgs, summary: &BagSummary) -> anyhow::Result<()> {
    if summary.scan_topics.is_empty() {
        let topics: Vec<String> = summary
            .topics
            .iter()
            .map(|(t, ty)| format!("{t} ({ty})"))
            .collect();
        bail!(
            "{}: no laser-scan topic (sensor_msgs/msg/LaserScan in CDR, or foxglove.LaserScan); its topics: {}",
            a.bag.display(),
            if topics.is_empty() {
                "none".into()
            } else {
                topics.join(", ")
            }
        );
    }
    for t in &a.topic {
        if !summary.scan_topics.contains_key(t) {
            bail!(
                "--topic {t}: not a laser-scan topic of {} (those: {})",
                a.bag.display(),
                summary
                    .scan_topics
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    Ok(())
}

fn take(
    r: &ScanResult,
    tally: &mut Tally,
    lines: Option<&mut AtomicWriter>,
    write_error: &mut Option<anyhow::Error>,
) {
    tally.results.push(r.face);
    tally.candidates.push(r.candidates.clone());
    tally.found += usize::from(r.found);
    tally.rejected += usize::from(r.rejected.is_some());
    if let Some(e) = &r.error {
        tally
            .errors
            .push(format!("scan {} on {}: {e}", r.index, r.topic));
    }
    if let (Some(w), None) = (lines, write_error.as_ref()) {
        let mut text = line(r).to_string();
        text.push('\n');
        if let Err(e) = w.write(text.as_bytes()) {
            *write_error = Some(e.into());
        }
    }
}

/// A scan's JSON line: the face in degrees at the interface.
fn line(r: &ScanResult) -> serde_json::Value {
    json!({
        "index": r.index,
        "topic": r.topic,
        "stamp_s": r.stamp_s.is_finite().then_some(r.stamp_s),
        "frame_id": r.frame_id,
        "beams": r.beams,
        "returns": r.returns,
        "found": r.found,
        "face": r.face.map(|f| json!({"x_m": f.x_m, "y_m": f.y_m, "heading_deg": f.heading_rad.to_degrees()})),
        "points": r.points,
        "rms_m": r.rms_m,
        "stringers": r.stringers,
        "score": r.score,
        "rejected": r.rejected.map(|f| json!({"x_m": f.x_m, "y_m": f.y_m, "heading_deg": f.heading_rad.to_degrees()})),
        "error": r.error,
    })
}

fn report(
    a: &DetectArgs,
    detector: &str,
    summary: &BagSummary,
    t: &Tally,
    scores: Option<&Scored>,
) -> anyhow::Result<()> {
    let n = t.results.len();
    let rate = n as f64 / t.seconds.max(1e-9);
    if a.json {
        let v = json!({
            "bag": a.bag.display().to_string(),
            "detector": detector,
            "frame": a.frame,
            "scan_topics": summary.scan_topics,
            "scans": n,
            "found": t.found,
            "rejected": t.rejected,
            "min_score": a.min_score,
            "unusable": t.errors.len(),
            "bad_transforms": summary.bad_transforms,
            "seconds": t.seconds,
            "scans_per_s": rate,
            "scores": scores.map(|s| &s.at_threshold),
            "curve": scores.map(|s| &s.curve),
            "by_place": scores.map(|s| &s.by_place),
            "by_clutter": scores.map(|s| &s.by_clutter),
            "label_warnings": scores.map(|s| &s.warnings),
            "wrong_scans": scores.map(|s| &s.wrong.0),
            "wrong_total": scores.map(|s| s.wrong.1),
        });
        return crate::emit(&format!("{v}\n"));
    }
    let mut s = format!(
        "detector {detector} on {}: {n} scans ({}), pallet found in {} ({:.1} %), {} unusable; {:.2} s, {rate:.0} scans/s\n",
        a.bag.display(),
        summary
            .scan_topics
            .iter()
            .map(|(k, v)| format!("{k}: {v}"))
            .collect::<Vec<_>>()
            .join(", "),
        t.found,
        100.0 * t.found as f64 / n.max(1) as f64,
        t.errors.len(),
        t.seconds,
    );
    if t.rejected > 0 {
        s += &format!(
            "{} located faces turned down by the scan's evidence (score below {}: parts, pockets or the space in front disagree)\n",
            t.rejected, a.min_score
        );
    }
    if let Some(sc) = scores {
        s += &forkbench_report::detect::scores_text(&sc.at_threshold);
        s += &forkbench_report::detect_curve::curve_text(&sc.curve, a.min_score);
        s += &forkbench_report::detect_curve::by_place_text(&sc.by_place);
        s += &forkbench_report::detect_curve::by_clutter_text(&sc.by_clutter);
        s += &wrong_text(&sc.wrong);
    }
    crate::emit(&s)
}

/// The wrong scans' count and the first few, by index and why (`--json` lists them with
/// their labels and detections).
fn wrong_text((listed, total): &(Vec<forkbench_batch::detect_wrong::Wrong>, usize)) -> String {
    if *total == 0 {
        return String::new();
    }
    let first: Vec<String> = listed
        .iter()
        .take(10)
        .map(|w| format!("{} {}", w.index, w.why))
        .collect();
    format!(
        "wrong scans: {total} (the first: {}); --json lists up to {} with their labels and detections\n",
        first.join(", "),
        forkbench_batch::detect_wrong::MAX_LISTED
    )
}
