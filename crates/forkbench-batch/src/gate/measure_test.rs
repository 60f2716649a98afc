//! One measure of one row, candidate against baseline: a paired signed-rank test (or a rank-sum test unpaired) of "worse by more than the margin", its Hodges–Lehmann shift and the shift it can detect.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::measures::{Gated, Worse};
use crate::rank_tests::{
    Shift, detectable_shift, paired_shift, rank_sum_p_above, signed_rank_p_above, std_dev,
    unpaired_shift,
};

/// One measure of one row, compared.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasureTest {
    pub measure: String,
    pub worse: Worse,
    /// The worsening allowed, in the measure's unit, and where it comes from.
    pub margin: f64,
    pub margin_source: String,
    pub paired: bool,
    /// Pairs with the measure on both sides (paired), else the results' values.
    pub n: u64,
    /// The baseline's values (unpaired; the pairs when paired).
    pub baseline_n: u64,
    pub baseline_median: Option<f64>,
    pub now_median: Option<f64>,
    /// How much worse the results are (positive: worse, in the measure's unit): the
    /// Hodges–Lehmann shift with its one-sided bounds at the gate's α.
    pub shift: Option<Shift>,
    /// One-sided p of "worse by at most the margin", and after the correction.
    pub p_value: Option<f64>,
    pub p_adjusted: Option<f64>,
    /// The smallest worsening caught with 80 % power at the gate's power level.
    pub detectable: Option<f64>,
    /// Worse beyond the margin after the correction: the row fails.
    pub worse_beyond_margin: bool,
    /// The standard error of the worsening, for the power statement.
    #[serde(skip)]
    pub(super) standard_error: f64,
    /// The pairs (baseline, now), for a paired plot (empty unpaired; not serialised:
    /// the baseline and the records hold them).
    #[serde(skip)]
    pub pairs: Vec<(f64, f64)>,
}

/// A measure's values in one row: pairs (baseline, now) on the same seed, or two samples.
pub(super) enum Sample {
    Paired(Vec<(f64, f64)>),
    Unpaired { base: Vec<f64>, now: Vec<f64> },
}

impl Sample {
    pub(super) fn baseline_values(&self) -> Vec<f64> {
        match self {
            Sample::Paired(p) => p.iter().map(|(b, _)| *b).collect(),
            Sample::Unpaired { base, .. } => base.clone(),
        }
    }

    fn now_values(&self) -> Vec<f64> {
        match self {
            Sample::Paired(p) => p.iter().map(|(_, n)| *n).collect(),
            Sample::Unpaired { now, .. } => now.clone(),
        }
    }
}

/// The median (none of no values).
pub(super) fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    Some(if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    })
}

/// Tests `sample` of `measure` against its margin at one-sided level `alpha` (the
/// bounds' level; the verdict waits for the correction); `base` is the sample's
/// baseline values with their median, which the margin was found from.
pub(super) fn test(
    measure: &str,
    g: &Gated,
    sample: &Sample,
    (base, baseline_median): (&[f64], Option<f64>),
    alpha: f64,
) -> MeasureTest {
    let s = g.worse.sign();
    let now = sample.now_values();
    let (p, shift, se, paired) = match sample {
        Sample::Paired(pairs) => {
            // `+ 0.0` turns an equal pair's −0 into 0.
            let d: Vec<f64> = pairs.iter().map(|(b, n)| s * (n - b) + 0.0).collect();
            let se = std_dev(&d) / (d.len().max(1) as f64).sqrt();
            let p = (!d.is_empty()).then(|| signed_rank_p_above(&d, g.margin));
            (p, paired_shift(&d, alpha), se, true)
        }
        Sample::Unpaired { base, now } => {
            let x: Vec<f64> = now.iter().map(|v| s * v).collect();
            let y: Vec<f64> = base.iter().map(|v| s * v).collect();
            let se = (std_dev(&x).powi(2) / x.len().max(1) as f64
                + std_dev(&y).powi(2) / y.len().max(1) as f64)
                .sqrt();
            // Two values a side at least: a rank-sum test on fewer says nothing.
            let enough = x.len() >= 2 && y.len() >= 2;
            let p = enough.then(|| rank_sum_p_above(&x, &y, g.margin));
            (p, unpaired_shift(&x, &y, alpha), se, false)
        }
    };
    MeasureTest {
        measure: measure.to_owned(),
        worse: g.worse,
        margin: g.margin,
        margin_source: g.source.clone(),
        paired,
        n: now.len() as u64,
        baseline_n: base.len() as u64,
        baseline_median,
        now_median: median(&now),
        shift,
        p_value: p,
        p_adjusted: None,
        detectable: None,
        worse_beyond_margin: false,
        standard_error: se,
        pairs: match sample {
            Sample::Paired(p) => p.clone(),
            Sample::Unpaired { .. } => Vec::new(),
        },
    }
}

impl MeasureTest {
    /// States the power at `level` and gives the verdict at `alpha` once `p_adjusted` is
    /// set.
    pub(super) fn judge(&mut self, level: f64, alpha: f64) {
        self.detectable = detectable_shift(self.margin, self.standard_error, 1.0, level);
        self.worse_beyond_margin = self.p_adjusted.is_some_and(|p| p < alpha);
    }
}

/// Adds `values` under their names to `into`'s samples (unpaired: one side).
pub(super) fn push_side(
    into: &mut BTreeMap<String, (Vec<f64>, Vec<f64>)>,
    values: &BTreeMap<String, f64>,
    now: bool,
) {
    for (k, v) in values {
        let e = into.entry(k.clone()).or_default();
        if now { &mut e.1 } else { &mut e.0 }.push(*v);
    }
}
