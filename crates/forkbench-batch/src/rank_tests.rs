//! Rank tests of a shift against a margin: Wilcoxon's signed-rank test on paired differences and the Mann–Whitney rank-sum test on two samples, with Hodges–Lehmann estimates and intervals.
//!
//! Both tests take the hypothesis "the shift is at most θ" and return the one-sided
//! p-value of the data against it; the Hodges–Lehmann estimate and its interval are found
//! by inverting the same statistic (bisection on θ), so memory stays linear in the sample
//! and the interval agrees with the test. Ties take mid-ranks and the variance's tie
//! correction; zero differences are dropped (Wilcoxon's convention).

use crate::stats::{normal_cdf, normal_quantile};

/// Largest sample (non-zero differences) whose signed-rank p-value is exact; above it the
/// normal approximation with the tie and continuity corrections, whose relative error in
/// the tail shrinks as the sample grows.
const EXACT_MAX: usize = 100;

/// Bisection steps for an estimate or a bound (the range halves each step).
const BISECTIONS: usize = 80;

/// Mid-ranks (1-based) of `v`, and the tie correction Σ (t³ − t) over groups of ties.
fn mid_ranks(v: &[f64]) -> (Vec<f64>, f64) {
    let mut order: Vec<usize> = (0..v.len()).collect();
    order.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut ranks = vec![0.0; v.len()];
    let mut ties = 0.0;
    let mut i = 0;
    while i < order.len() {
        let mut j = i + 1;
        while j < order.len() && v[order[j]] == v[order[i]] {
            j += 1;
        }
        let rank = (i + j + 1) as f64 / 2.0;
        for &k in &order[i..j] {
            ranks[k] = rank;
        }
        let t = (j - i) as f64;
        ties += t * t * t - t;
        i = j;
    }
    (ranks, ties)
}

/// W⁺ of `d − θ` with its ranks: (W⁺, the non-zero count, the ranks, the tie term).
fn signed_rank(d: &[f64], theta: f64) -> (f64, usize, Vec<f64>, f64) {
    let z: Vec<f64> = d.iter().map(|x| x - theta).filter(|z| *z != 0.0).collect();
    let abs: Vec<f64> = z.iter().map(|z| z.abs()).collect();
    let (ranks, ties) = mid_ranks(&abs);
    let w = z
        .iter()
        .zip(&ranks)
        .filter(|(z, _)| **z > 0.0)
        .map(|(_, r)| r)
        .sum();
    (w, z.len(), ranks, ties)
}

/// P(W⁺ ≥ w) under the null, exactly: every rank's sign is a fair coin, over doubled
/// (integer) mid-ranks.
fn exact_upper_tail(ranks: &[f64], w: f64) -> f64 {
    let doubled: Vec<usize> = ranks.iter().map(|r| (2.0 * r).round() as usize).collect();
    let total: usize = doubled.iter().sum();
    let mut p = vec![0.0; total + 1];
    p[0] = 1.0;
    let mut reach = 0;
    for &r in &doubled {
        for s in (0..=reach).rev() {
            let half = 0.5 * p[s];
            p[s] = half;
            p[s + r] += half;
        }
        reach += r;
    }
    let from = (2.0 * w).round() as usize;
    p.get(from..)
        .map_or(0.0, |t| t.iter().sum::<f64>())
        .min(1.0)
}

/// One-sided p-value of the paired differences `d` against "their centre is at most
/// θ" (a small p: the differences sit above θ).
pub fn signed_rank_p_above(d: &[f64], theta: f64) -> f64 {
    let (w, n, ranks, ties) = signed_rank(d, theta);
    if n == 0 {
        return 1.0;
    }
    if n <= EXACT_MAX {
        return exact_upper_tail(&ranks, w);
    }
    let nf = n as f64;
    let mean = nf * (nf + 1.0) / 4.0;
    let var = nf * (nf + 1.0) * (2.0 * nf + 1.0) / 24.0 - ties / 48.0;
    if var <= 0.0 {
        return 1.0;
    }
    1.0 - normal_cdf((w - mean - 0.5) / var.sqrt())
}

/// The same test for "the centre is at least θ" (a small p: the differences sit below).
pub fn signed_rank_p_below(d: &[f64], theta: f64) -> f64 {
    let flipped: Vec<f64> = d.iter().map(|x| -x).collect();
    signed_rank_p_above(&flipped, -theta)
}

/// Mann–Whitney U of `x − θ` against `y`, with its null mean and variance (ties
/// corrected).
fn rank_sum(x: &[f64], y: &[f64], theta: f64) -> (f64, f64, f64) {
    let mut all: Vec<f64> = x.iter().map(|v| v - theta).collect();
    all.extend_from_slice(y);
    let (ranks, ties) = mid_ranks(&all);
    let (nx, ny) = (x.len() as f64, y.len() as f64);
    let n = nx + ny;
    let rx: f64 = ranks[..x.len()].iter().sum();
    let u = rx - nx * (nx + 1.0) / 2.0;
    let var = nx * ny / 12.0 * ((n + 1.0) - ties / (n * (n - 1.0)));
    (u, nx * ny / 2.0, var)
}

/// One-sided p-value of two samples against "`x` exceeds `y` by at most θ" (a small p:
/// `x` sits more than θ above `y`); the normal approximation with continuity and ties
/// corrected.
pub fn rank_sum_p_above(x: &[f64], y: &[f64], theta: f64) -> f64 {
    if x.is_empty() || y.is_empty() {
        return 1.0;
    }
    let (u, mean, var) = rank_sum(x, y, theta);
    if var <= 0.0 {
        return 1.0;
    }
    1.0 - normal_cdf((u - mean - 0.5) / var.sqrt())
}

/// The same test for "`x` exceeds `y` by at least θ".
pub fn rank_sum_p_below(x: &[f64], y: &[f64], theta: f64) -> f64 {
    let fx: Vec<f64> = x.iter().map(|v| -v).collect();
    let fy: Vec<f64> = y.iter().map(|v| -v).collect();
    rank_sum_p_above(&fx, &fy, -theta)
}

/// A shift's Hodges–Lehmann estimate and its two one-sided bounds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Shift {
    pub estimate: f64,
    /// The shift is above `low` and below `high`, each with confidence 1 − a.
    pub low: f64,
    pub high: f64,
}

/// The θ in `[lo, hi]` where `f` (non-increasing in θ) crosses `level`.
fn bisect(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64, level: f64) -> f64 {
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if f(mid) > level {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()).max(1e-300) {
            break;
        }
    }
    0.5 * (lo + hi)
}

fn span(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    let pad = (hi - lo).abs().max(lo.abs()).max(1.0);
    (lo - pad, hi + pad)
}

/// Bisection's last bits as the data's own zero: a θ within 1e-9 of the data's scale
/// of 0 is 0 (all-zero differences shift by exactly nothing).
fn snap(t: f64, scale: f64) -> f64 {
    if t.abs() <= 1e-9 * scale { 0.0 } else { t }
}

/// The paired shift of `d` (Hodges–Lehmann: the centre the signed-rank statistic puts
/// at its null mean) and its bounds at one-sided level `a`; `None` for no data.
pub fn paired_shift(d: &[f64], a: f64) -> Option<Shift> {
    if d.is_empty() || d.iter().any(|x| !x.is_finite()) {
        return None;
    }
    if d.iter().all(|x| *x == d[0]) {
        // One value: the shift is it, and no interval can be narrower.
        return Some(Shift {
            estimate: d[0],
            low: d[0],
            high: d[0],
        });
    }
    let (lo, hi) = span(d.iter().copied());
    let scale = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let centre = |t: f64| {
        let (w, n, _, _) = signed_rank(d, t);
        w - n as f64 * (n as f64 + 1.0) / 4.0
    };
    Some(Shift {
        estimate: snap(bisect(lo, hi, centre, 0.0), scale),
        low: snap(bisect(lo, hi, |t| -signed_rank_p_above(d, t), -a), scale),
        high: snap(bisect(lo, hi, |t| signed_rank_p_below(d, t), a), scale),
    })
}

/// The shift of `x` over `y` (Hodges–Lehmann: the median of all differences, where U
/// meets its null mean) and its bounds at one-sided level `a`.
pub fn unpaired_shift(x: &[f64], y: &[f64], a: f64) -> Option<Shift> {
    if x.is_empty() || y.is_empty() || x.iter().chain(y).any(|v| !v.is_finite()) {
        return None;
    }
    let (lo, hi) = span(x.iter().chain(y).copied());
    let (lo, hi) = (lo - (hi - lo), hi + (hi - lo));
    let scale = x.iter().chain(y).fold(0.0f64, |m, v| m.max(v.abs()));
    let centre = |t: f64| {
        let (u, mean, _) = rank_sum(x, y, t);
        u - mean
    };
    Some(Shift {
        estimate: snap(bisect(lo, hi, centre, 0.0), scale),
        low: snap(bisect(lo, hi, |t| -rank_sum_p_above(x, y, t), -a), scale),
        high: snap(bisect(lo, hi, |t| rank_sum_p_below(x, y, t), a), scale),
    })
}

/// The smallest shift beyond `margin` seen with 80 % power at one-sided `level`: the
/// normal-theory figure for a spread `sd` of the estimate's unit over `n` (use `n` = 1
/// with the standard error), scaled by the rank tests' efficiency against the t-test
/// under normality (3/π).
pub fn detectable_shift(margin: f64, sd: f64, n: f64, level: f64) -> Option<f64> {
    if n <= 0.0 || !(level > 0.0 && level < 1.0) || !sd.is_finite() {
        return None;
    }
    let z = normal_quantile(1.0 - level) + normal_quantile(0.8);
    Some(margin + z * sd * (std::f64::consts::PI / 3.0).sqrt() / n.sqrt())
}

/// The sample standard deviation (0 for fewer than two values).
pub fn std_dev(v: &[f64]) -> f64 {
    if v.len() < 2 {
        return 0.0;
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_signed_rank_tails_match_the_enumeration() {
        // n = 5 distinct ranks: 32 sign patterns; W⁺ ≥ 15 only when all are positive.
        let d = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert!((signed_rank_p_above(&d, 0.0) - 1.0 / 32.0).abs() < 1e-12);
        // W⁺ ≥ 14: {all} and {all but rank 1}.
        let d = [-1.0, 2.0, 3.0, 4.0, 5.0];
        assert!((signed_rank_p_above(&d, 0.0) - 2.0 / 32.0).abs() < 1e-12);
        // Against a margin: the same data minus 10 are all negative, p = 1.
        assert!((signed_rank_p_above(&d, 10.0) - 1.0).abs() < 1e-12);
        // Zeros carry no sign: all-zero differences give no evidence.
        assert_eq!(signed_rank_p_above(&[0.0; 8], 0.0), 1.0);
    }

    #[test]
    fn ties_take_mid_ranks_and_the_exact_tail_still_sums_to_one() {
        let (r, ties) = mid_ranks(&[2.0, 1.0, 2.0, 3.0]);
        assert_eq!(r, vec![2.5, 1.0, 2.5, 4.0]);
        assert_eq!(ties, 6.0);
        let ranks = [1.0, 2.5, 2.5, 4.0];
        assert!((exact_upper_tail(&ranks, 0.0) - 1.0).abs() < 1e-12);
        assert!((exact_upper_tail(&ranks, 10.0) - 1.0 / 16.0).abs() < 1e-12);
    }

    #[test]
    fn the_normal_tail_meets_the_exact_one_where_they_hand_over() {
        let d: Vec<f64> = (0..EXACT_MAX)
            .map(|i| (i as f64 * 0.37).sin() + 0.2)
            .collect();
        let exact = signed_rank_p_above(&d, 0.0);
        let (w, n, _, ties) = signed_rank(&d, 0.0);
        let nf = n as f64;
        let z = (w - nf * (nf + 1.0) / 4.0 - 0.5)
            / (nf * (nf + 1.0) * (2.0 * nf + 1.0) / 24.0 - ties / 48.0).sqrt();
        let normal = 1.0 - normal_cdf(z);
        assert!((exact - normal).abs() < 0.15 * exact, "{exact} vs {normal}");
    }

    #[test]
    fn hodges_lehmann_finds_a_known_shift_and_its_bounds_hold_it() {
        // Differences 0.03 + a spread symmetric about it: the estimate is 0.03.
        let d: Vec<f64> = (0..40)
            .map(|i| 0.03 + 0.01 * ((i as f64) * 1.3).sin())
            .collect();
        let s = paired_shift(&d, 0.05).expect("data");
        assert!((s.estimate - 0.03).abs() < 0.002, "{s:?}");
        assert!(
            s.low < s.estimate && s.estimate < s.high && s.low > 0.02,
            "{s:?}"
        );
        // The test against the margin agrees with the bound: rejected below it.
        assert!(signed_rank_p_above(&d, s.low - 1e-4) < 0.05);
        assert!(signed_rank_p_above(&d, s.low + 1e-4) > 0.05);
        // Two samples shifted by 0.5: the estimate is the shift.
        let y: Vec<f64> = (0..30).map(|i| (i as f64 * 0.7).cos()).collect();
        let x: Vec<f64> = y.iter().map(|v| v + 0.5).collect();
        let s = unpaired_shift(&x, &y, 0.05).expect("data");
        assert!((s.estimate - 0.5).abs() < 0.05, "{s:?}");
        assert!(rank_sum_p_above(&x, &y, 0.0) < 0.05);
        assert!(rank_sum_p_above(&x, &y, 1.5) > 0.5);
    }

    #[test]
    fn the_detectable_shift_is_the_margin_without_spread() {
        assert_eq!(detectable_shift(0.01, 0.0, 40.0, 0.05), Some(0.01));
        let d = detectable_shift(0.01, 0.02, 40.0, 0.05).expect("n");
        assert!(d > 0.01 && d < 0.03, "{d}");
        assert_eq!(detectable_shift(0.01, 0.02, 0.0, 0.05), None);
    }
}
