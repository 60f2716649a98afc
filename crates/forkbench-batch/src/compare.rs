//! A/B in one batch: two planners, two trackers, or planning once against replanning, on the same trials and seeds, compared pair by pair per scenario.

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};

use super::{BatchError, TrialRecord};
use crate::stats::{Correction, mcnemar_two_sided_p};

/// How the comparison decides.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareOptions {
    pub alpha: f64,
    pub correction: Correction,
}

/// One scenario × the other component × mode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompareRow {
    pub scenario: String,
    /// The component held fixed (the tracker when planners are compared, and vice versa).
    pub other: String,
    pub replan: bool,
    pub pairs: u64,
    pub a_successes: u64,
    pub b_successes: u64,
    /// Pairs A passed and B failed, and the reverse.
    pub a_only: u64,
    pub b_only: u64,
    /// McNemar's exact two-sided test, and after the multiplicity correction.
    pub p_value: f64,
    pub p_adjusted: f64,
    pub significant: bool,
}

/// One trial A and B ended differently: enough to replay either.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Discordant {
    pub scenario: String,
    pub case: String,
    pub other: String,
    pub replan: bool,
    pub trial: u64,
    pub seed: u64,
    /// Which of the two succeeded, the other's first failed criterion.
    pub winner: String,
    pub loser_failure: Option<String>,
    /// 1-based lines of the two trials in `trials.jsonl` (`forkbench replay --line`).
    pub a_line: usize,
    pub b_line: usize,
}

/// The whole comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompareReport {
    /// "planner", "tracker" or "mode".
    pub kind: String,
    pub a: String,
    pub b: String,
    pub alpha: f64,
    pub correction: Correction,
    pub rows: Vec<CompareRow>,
    pub discordant: Vec<Discordant>,
    /// Trials of A or B with no partner at the same seed.
    pub unpaired: u64,
}

type PairKey = (String, String, bool, String, u64);

/// What two sides of a comparison differ in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Axis {
    Planner,
    Tracker,
    /// Planning once against replanning (`plan_once`, `replan`).
    Mode,
}

/// The replanning mode a comparison side names, if it names one.
fn mode_of(name: &str) -> Option<bool> {
    match name {
        "plan_once" | "plan-once" | "plan once" | "once" => Some(false),
        "replan" => Some(true),
        _ => None,
    }
}

/// Records with their 1-based lines in `trials.jsonl`.
type Numbered<'a> = &'a [(usize, TrialRecord)];

/// The trials of one side, keyed by everything but what the sides differ in.
fn side<'a>(
    records: &'a [(usize, TrialRecord)],
    name: &str,
    axis: Axis,
) -> BTreeMap<PairKey, (usize, &'a TrialRecord)> {
    records
        .iter()
        .filter(|(_, r)| match axis {
            Axis::Planner => r.outcome.planner == name,
            Axis::Tracker => r.outcome.tracker == name,
            Axis::Mode => mode_of(name) == Some(r.replan.unwrap_or(false)),
        })
        .map(|(line, r)| {
            let (other, mode) = match axis {
                Axis::Planner => (r.outcome.tracker.clone(), r.replan.unwrap_or(false)),
                Axis::Tracker => (r.outcome.planner.clone(), r.replan.unwrap_or(false)),
                Axis::Mode => (
                    format!("{} / {}", r.outcome.planner, r.outcome.tracker),
                    false,
                ),
            };
            let key = (
                r.outcome.scenario.clone(),
                other,
                mode,
                r.outcome.case.clone(),
                r.trial,
            );
            (key, (*line, r))
        })
        .collect()
}

/// What A and B are of these batches: planners, trackers, or the two replanning modes.
fn kind_of((ra, rb): (Numbered<'_>, Numbered<'_>), a: &str, b: &str) -> Result<Axis, BatchError> {
    let planners: BTreeSet<&str> = ra
        .iter()
        .chain(rb)
        .map(|(_, r)| r.outcome.planner.as_str())
        .collect();
    let trackers: BTreeSet<&str> = ra
        .iter()
        .chain(rb)
        .map(|(_, r)| r.outcome.tracker.as_str())
        .collect();
    if a == b {
        return Err(BatchError::Setting(format!("A and B are both {a:?}")));
    }
    if planners.contains(a) && planners.contains(b) {
        Ok(Axis::Planner)
    } else if trackers.contains(a) && trackers.contains(b) {
        Ok(Axis::Tracker)
    } else if mode_of(a).is_some() && mode_of(b).is_some() && mode_of(a) != mode_of(b) {
        Ok(Axis::Mode)
    } else {
        let list = |s: &BTreeSet<&str>| s.iter().copied().collect::<Vec<_>>().join(", ");
        Err(BatchError::Setting(format!(
            "{a:?} and {b:?} are not two planners, two trackers or the two modes (plan_once, \
             replan) of this batch (planners: {}; trackers: {})",
            list(&planners),
            list(&trackers)
        )))
    }
}

/// Per row (scenario, other component, mode): pairs, A's and B's successes, A only,
/// B only; then the discordant trials and the number of pairs.
type Tally = (
    BTreeMap<(String, String, bool), [u64; 5]>,
    Vec<Discordant>,
    u64,
);

/// Pairs A's trials with B's (same key and seed) and counts them per row.
fn tally(
    sa: &BTreeMap<PairKey, (usize, &TrialRecord)>,
    sb: &BTreeMap<PairKey, (usize, &TrialRecord)>,
    (a, b): (&str, &str),
) -> Tally {
    let mut counts: BTreeMap<(String, String, bool), [u64; 5]> = BTreeMap::new();
    let mut discordant = Vec::new();
    let mut paired = 0_u64;
    for (key, (la, ra)) in sa {
        let Some((lb, rb)) = sb
            .get(key)
            .filter(|(_, rb)| rb.outcome.seed == ra.outcome.seed)
        else {
            continue;
        };
        paired += 1;
        let (ok_a, ok_b) = (ra.outcome.success, rb.outcome.success);
        let c = counts
            .entry((key.0.clone(), key.1.clone(), key.2))
            .or_default();
        *c = [
            c[0] + 1,
            c[1] + u64::from(ok_a),
            c[2] + u64::from(ok_b),
            c[3] + u64::from(ok_a && !ok_b),
            c[4] + u64::from(ok_b && !ok_a),
        ];
        if ok_a != ok_b {
            let loser = if ok_a { rb } else { ra };
            discordant.push(Discordant {
                scenario: key.0.clone(),
                case: key.3.clone(),
                other: key.1.clone(),
                replan: key.2,
                trial: key.4,
                seed: ra.outcome.seed,
                winner: if ok_a { a } else { b }.to_owned(),
                loser_failure: loser.outcome.failure.as_ref().map(|f| f.name().to_owned()),
                a_line: *la,
                b_line: *lb,
            });
        }
    }
    (counts, discordant, paired)
}

/// Compares A with B over the trials they share (same key and seed).
pub fn compare(
    records: &[(usize, TrialRecord)],
    a: &str,
    b: &str,
    o: &CompareOptions,
) -> Result<CompareReport, BatchError> {
    compare_apart((records, records), a, b, o)
}

/// [`compare`] with A's trials taken from `ra` and B's from `rb`: two batches of one
/// batch seed and seed scheme (a candidate run apart from what is shipped) run the same
/// trials at the same keys.
pub fn compare_apart(
    (ra, rb): (Numbered<'_>, Numbered<'_>),
    a: &str,
    b: &str,
    o: &CompareOptions,
) -> Result<CompareReport, BatchError> {
    crate::check_alpha(o.alpha)?;
    let axis = kind_of((ra, rb), a, b)?;
    let (sa, sb) = (side(ra, a, axis), side(rb, b, axis));
    let (counts, discordant, paired) = tally(&sa, &sb, (a, b));
    let kind = match axis {
        Axis::Planner => "planner",
        Axis::Tracker => "tracker",
        Axis::Mode => "mode",
    };
    if paired == 0 {
        let how = match axis {
            Axis::Mode => "`--modes both`".to_owned(),
            _ => format!("`--{kind} {a} {b}`"),
        };
        return Err(BatchError::Content(format!(
            "{a} and {b} share no trial at the same seed: run them in one batch ({how}) by a \
             forkbench whose seeds leave the components and the mode out"
        )));
    }
    let p: Vec<f64> = counts
        .values()
        .map(|c| mcnemar_two_sided_p(c[3], c[4]))
        .collect();
    let adjusted = o.correction.adjust(&p);
    let rows = counts
        .into_iter()
        .zip(p.iter().zip(adjusted))
        .map(|((k, c), (&p, adj))| CompareRow {
            scenario: k.0,
            other: k.1,
            replan: k.2,
            pairs: c[0],
            a_successes: c[1],
            b_successes: c[2],
            a_only: c[3],
            b_only: c[4],
            p_value: p,
            p_adjusted: adj,
            significant: adj < o.alpha,
        })
        .collect();
    Ok(CompareReport {
        kind: kind.to_owned(),
        a: a.to_owned(),
        b: b.to_owned(),
        alpha: o.alpha,
        correction: o.correction,
        rows,
        discordant,
        unpaired: (sa.len() + sb.len()) as u64 - 2 * paired,
    })
}

impl CompareReport {
    /// The comparison as Markdown, with every discordant trial and its replay lines.
    pub fn markdown(&self, trials_file: &str) -> String {
        use forkbench_trial::text::md_cell;
        let mut s = format!(
            "{} {} (A) against {} (B), paired trial by trial on shared seeds; McNemar's exact \
             two-sided test per row, {} correction at α = {}.\n\n| scenario | {} | mode | pairs | A | B | A only | B only | p | p adjusted | |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
            self.kind,
            md_cell(&self.a),
            md_cell(&self.b),
            self.correction.name(),
            self.alpha,
            match self.kind.as_str() {
                "planner" => "tracker",
                "tracker" => "planner",
                _ => "planner / tracker",
            }
        );
        let mode = |replan: bool| {
            if self.kind == "mode" {
                "–"
            } else {
                super::mode_name(replan)
            }
        };
        for r in &self.rows {
            let pct = |k: u64| format!("{:.1} %", 100.0 * k as f64 / r.pairs.max(1) as f64);
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {} |\n",
                md_cell(&r.scenario),
                md_cell(&r.other),
                mode(r.replan),
                r.pairs,
                pct(r.a_successes),
                pct(r.b_successes),
                r.a_only,
                r.b_only,
                r.p_value,
                r.p_adjusted,
                if r.significant { "differ" } else { "" }
            ));
        }
        if self.unpaired > 0 {
            s.push_str(&format!(
                "\n{} trials had no partner at the same seed and were left out.\n",
                self.unpaired
            ));
        }
        s.push_str(&format!("\nDiscordant trials ({}): replay with `forkbench replay {trials_file} --line N`\n\n| scenario | case | mode | trial | seed | succeeded | the other failed on | line A | line B |\n|---|---|---|---|---|---|---|---|---|\n", self.discordant.len()));
        for d in &self.discordant {
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                md_cell(&d.scenario),
                md_cell(&d.case),
                mode(d.replan),
                d.trial,
                d.seed,
                md_cell(&d.winner),
                d.loser_failure.as_deref().unwrap_or("–"),
                d.a_line,
                d.b_line
            ));
        }
        s
    }
}
