//! Success-rate statistics: Wilson intervals, proportion tests (unpaired and McNemar's exact), multiplicity corrections, power, percentiles.

/// Wilson score interval for k successes in n trials at normal quantile z.
pub fn wilson(k: u64, n: u64, z: f64) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let (k, n) = (k as f64, n as f64);
    let p = k / n;
    let z2 = z * z;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = z * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / denom;
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// 95 % two-sided normal quantile.
pub const Z95: f64 = 1.959_963_984_540_054;

/// Standard normal CDF (Abramowitz–Stegun 7.1.26 erf, |error| < 1.5e-7).
pub fn normal_cdf(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs() / std::f64::consts::SQRT_2);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-(x * x) / 2.0).exp();
    if x >= 0.0 {
        0.5 * (1.0 + erf)
    } else {
        0.5 * (1.0 - erf)
    }
}

/// One-sided p-value that the success rate dropped from (k0/n0) to (k1/n1): pooled
/// two-proportion z-test, H1: p1 < p0.
pub fn drop_p_value(k0: u64, n0: u64, k1: u64, n1: u64) -> f64 {
    if n0 == 0 || n1 == 0 {
        return 1.0;
    }
    let (p0, p1) = (k0 as f64 / n0 as f64, k1 as f64 / n1 as f64);
    let pooled = (k0 + k1) as f64 / (n0 + n1) as f64;
    let se = (pooled * (1.0 - pooled) * (1.0 / n0 as f64 + 1.0 / n1 as f64)).sqrt();
    if se == 0.0 {
        // Both all-success or all-failure: a drop is impossible to see, or total.
        return if p1 < p0 { 0.0 } else { 1.0 };
    }
    normal_cdf((p1 - p0) / se)
}

/// Normal quantile: the x with `normal_cdf(x) = p` (bisection; 0 < p < 1).
pub fn normal_quantile(p: f64) -> f64 {
    let (mut lo, mut hi) = (-40.0_f64, 40.0_f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if normal_cdf(mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// ln k! for k = 0..=n at least, so binomial probabilities need no gamma function: one
/// table for the process, extended as larger counts are asked for (each entry the same
/// running sum whatever the table's length, so the answers do not depend on what was
/// asked before).
fn ln_factorials(n: u64) -> std::sync::Arc<Vec<f64>> {
    static TABLE: std::sync::Mutex<Option<std::sync::Arc<Vec<f64>>>> = std::sync::Mutex::new(None);
    let mut kept = TABLE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let have = kept.as_ref().map_or(0, |t| t.len() as u64);
    if have > n
        && let Some(t) = kept.as_ref()
    {
        return t.clone();
    }
    let mut t: Vec<f64> = kept.as_ref().map_or_else(Vec::new, |t| t.as_ref().clone());
    if t.is_empty() {
        t.push(0.0);
    }
    t.reserve(n as usize + 1 - t.len());
    let mut acc = *t.last().unwrap_or(&0.0);
    for k in t.len() as u64..=n {
        acc += (k as f64).ln();
        t.push(acc);
    }
    let t = std::sync::Arc::new(t);
    *kept = Some(t.clone());
    t
}

/// Binomial probability of k in n at success probability p, from a ln-factorial table.
fn binom_pmf(lf: &[f64], n: u64, k: u64, p: f64) -> f64 {
    if p <= 0.0 {
        return f64::from(u8::from(k == 0));
    }
    if p >= 1.0 {
        return f64::from(u8::from(k == n));
    }
    let (n_, k_) = (n as usize, k as usize);
    (lf[n_] - lf[k_] - lf[n_ - k_] + k as f64 * p.ln() + (n - k) as f64 * (1.0 - p).ln()).exp()
}

/// P(X ≥ k) for X ~ Binomial(n, p).
pub fn binom_tail(k: u64, n: u64, p: f64) -> f64 {
    if k == 0 {
        return 1.0;
    }
    if k > n {
        return 0.0;
    }
    let lf = ln_factorials(n);
    let tail: f64 = (k..=n).map(|i| binom_pmf(&lf, n, i, p)).sum();
    tail.min(1.0)
}

/// McNemar's exact one-sided test that a paired success rate dropped: `broke` pairs
/// passed before and fail now, `fixed` the reverse; H0 gives each discordant pair either
/// direction with probability ½.
pub fn mcnemar_drop_p(broke: u64, fixed: u64) -> f64 {
    binom_tail(broke, broke + fixed, 0.5)
}

/// McNemar's exact two-sided test that two paired success rates differ.
pub fn mcnemar_two_sided_p(a_only: u64, b_only: u64) -> f64 {
    if a_only == b_only {
        return 1.0;
    }
    (2.0 * binom_tail(a_only.max(b_only), a_only + b_only, 0.5)).min(1.0)
}

/// How p-values of several rows tested together are adjusted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Correction {
    /// Holm's step-down: controls the chance of any false alarm (family-wise error).
    Holm,
    /// Benjamini–Hochberg: controls the expected share of false alarms among alarms.
    BenjaminiHochberg,
    /// No adjustment (each row at α on its own).
    None,
}

impl Correction {
    pub fn name(self) -> &'static str {
        match self {
            Correction::Holm => "Holm",
            Correction::BenjaminiHochberg => "Benjamini–Hochberg",
            Correction::None => "none",
        }
    }

    /// Adjusted p-values, in the order given.
    pub fn adjust(self, p: &[f64]) -> Vec<f64> {
        let m = p.len();
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
        let mut out = vec![0.0; m];
        match self {
            Correction::None => out.copy_from_slice(p),
            Correction::Holm => {
                let mut running: f64 = 0.0;
                for (rank, &i) in order.iter().enumerate() {
                    running = running.max(((m - rank) as f64 * p[i]).min(1.0));
                    out[i] = running;
                }
            }
            Correction::BenjaminiHochberg => {
                let mut running: f64 = 1.0;
                for (rank, &i) in order.iter().enumerate().rev() {
                    running = running.min((m as f64 / (rank + 1) as f64 * p[i]).min(1.0));
                    out[i] = running;
                }
            }
        }
        out
    }
}

/// Power of McNemar's exact one-sided test at level `alpha` over `n` pairs when a change
/// breaks a share (ψ + d)/2 of them and fixes (ψ − d)/2: ψ is the discordance rate, d the
/// drop (d ≤ ψ). Exact: the discordant count D ~ Bin(n, ψ), the broken ones given D
/// ~ Bin(D, (ψ + d)/2ψ).
pub fn paired_power(n: u64, drop: f64, discordance: f64, alpha: f64) -> f64 {
    let psi = discordance.max(drop).min(1.0);
    if n == 0 || drop <= 0.0 || psi <= 0.0 {
        return 0.0;
    }
    let q = ((psi + drop) / (2.0 * psi)).min(1.0);
    let lf = ln_factorials(n);
    let (mean, sd) = (n as f64 * psi, (n as f64 * psi * (1.0 - psi)).sqrt());
    let lo = (mean - 12.0 * sd - 2.0).max(0.0) as u64;
    let hi = ((mean + 12.0 * sd + 2.0) as u64).min(n);
    let mut power = 0.0;
    for d in lo..=hi {
        let w = binom_pmf(&lf, n, d, psi);
        if w < 1e-15 {
            continue;
        }
        // Smallest broken count k whose one-sided tail under H0 is below alpha.
        let mut tail = 0.0;
        let mut k = d + 1;
        while k > 0 {
            let t = tail + binom_pmf(&lf, d, k - 1, 0.5);
            if t >= alpha {
                break;
            }
            tail = t;
            k -= 1;
        }
        let reject: f64 = (k..=d).map(|i| binom_pmf(&lf, d, i, q)).sum();
        power += w * reject;
    }
    power.min(1.0)
}

/// Power of the one-sided pooled two-proportion test at level `alpha` (normal
/// approximation) to see a drop from `p0` (n0 trials) by `drop` with n1 new trials.
pub fn unpaired_power(p0: f64, n0: u64, n1: u64, drop: f64, alpha: f64) -> f64 {
    if n0 == 0 || n1 == 0 || drop <= 0.0 {
        return 0.0;
    }
    let p1 = (p0 - drop).max(0.0);
    let (a, b) = (n0 as f64, n1 as f64);
    let pooled = (a * p0 + b * p1) / (a + b);
    let se0 = (pooled * (1.0 - pooled) * (1.0 / a + 1.0 / b)).sqrt();
    let se1 = (p0 * (1.0 - p0) / a + p1 * (1.0 - p1) / b).sqrt();
    if se1 == 0.0 {
        return f64::from(u8::from(drop > 0.0));
    }
    normal_cdf((drop - normal_quantile(1.0 - alpha) * se0) / se1)
}

/// Power the gate's statements are made at.
pub const POWER: f64 = 0.8;

/// Smallest drop in (0, `max_drop`] that `power(d)` sees with at least [`POWER`]
/// (bisection to 0.1 percentage points); none when even `max_drop` is not seen.
pub fn min_detectable_drop(max_drop: f64, power: impl Fn(f64) -> f64) -> Option<f64> {
    if max_drop <= 0.0 || power(max_drop) < POWER {
        return None;
    }
    let (mut lo, mut hi) = (0.0, max_drop);
    while hi - lo > 1e-3 {
        let mid = 0.5 * (lo + hi);
        if power(mid) >= POWER {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// Fewest trials n ≤ `max_n` with `power(n)` ≥ [`POWER`] (power grows with n); none
/// when `max_n` is not enough. Searches upward by doubling, so the cost is that of
/// powers near the answer.
pub fn trials_needed(max_n: u64, power: impl Fn(u64) -> f64) -> Option<u64> {
    let mut hi = 1_u64;
    while power(hi) < POWER {
        if hi >= max_n {
            return None;
        }
        hi = (hi * 2).min(max_n);
    }
    let mut lo = hi / 2;
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if power(mid) >= POWER {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// Nearest-rank percentile of already sorted values (the one convention, in core).
pub use forkbench_core::quantile::percentile_sorted;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_matches_known_values() {
        // 8/10 at 95 %: (0.4902, 0.9433).
        let (lo, hi) = wilson(8, 10, Z95);
        assert!(
            (lo - 0.4902).abs() < 1e-4 && (hi - 0.9433).abs() < 1e-4,
            "{lo} {hi}"
        );
        let (lo, hi) = wilson(0, 20, Z95);
        assert!(lo == 0.0 && (hi - 0.1611).abs() < 1e-4, "{hi}");
    }

    #[test]
    fn normal_cdf_and_drop_test() {
        assert!((normal_cdf(0.0) - 0.5).abs() < 1e-7);
        assert!((normal_cdf(-1.644_853_6) - 0.05).abs() < 1e-6);
        // 90/100 → 70/100 is a clear drop; 90/100 → 92/100 is not.
        assert!(drop_p_value(90, 100, 70, 100) < 0.001);
        assert!(drop_p_value(90, 100, 92, 100) > 0.5);
    }

    #[test]
    fn binomial_tails_and_mcnemar() {
        // P(X ≥ 8 | n = 10, ½) = 56/1024.
        assert!((binom_tail(8, 10, 0.5) - 56.0 / 1024.0).abs() < 1e-12);
        assert_eq!(binom_tail(0, 10, 0.5), 1.0);
        assert_eq!(binom_tail(11, 10, 0.5), 0.0);
        // Unchanged code: no discordant pair, nothing to see.
        assert_eq!(mcnemar_drop_p(0, 0), 1.0);
        // 7 broke, 2 fixed: P(X ≥ 7 | 9, ½) = 46/512.
        assert!((mcnemar_drop_p(7, 2) - 46.0 / 512.0).abs() < 1e-12);
        assert!((mcnemar_two_sided_p(2, 7) - 92.0 / 512.0).abs() < 1e-12);
        assert!((normal_quantile(0.95) - 1.644_853_6).abs() < 1e-5);
    }

    #[test]
    fn holm_and_benjamini_hochberg_match_hand_values() {
        let p = [0.01, 0.04, 0.03, 0.005];
        // Holm: sorted 0.005·4, 0.01·3, 0.03·2, 0.04·1, made monotone.
        let h = Correction::Holm.adjust(&p);
        let want = [0.03, 0.06, 0.06, 0.02];
        for (a, b) in h.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{h:?}");
        }
        // BH: 0.005·4/1, 0.01·4/2, 0.03·4/3, 0.04·4/4, monotone from the top.
        let bh = Correction::BenjaminiHochberg.adjust(&p);
        let want = [0.02, 0.04, 0.04, 0.02];
        for (a, b) in bh.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{bh:?}");
        }
    }

    #[test]
    fn power_grows_with_trials_and_pairing_needs_fewer() {
        // A change that only breaks trials: 10 % of 100 pairs is seen almost surely.
        assert!(paired_power(100, 0.1, 0.1, 0.05) > 0.95);
        assert!(paired_power(20, 0.1, 0.1, 0.05) < paired_power(100, 0.1, 0.1, 0.05));
        // Background discordance costs power.
        assert!(paired_power(100, 0.1, 0.4, 0.05) < paired_power(100, 0.1, 0.1, 0.05));
        let paired = trials_needed(100_000, |n| paired_power(n, 0.05, 0.05, 0.05)).expect("n");
        let unpaired =
            trials_needed(100_000, |n| unpaired_power(0.5, n, n, 0.05, 0.05)).expect("n");
        assert!(paired < unpaired / 5, "{paired} vs {unpaired}");
        // The textbook unpaired figure: ~1,240 per arm for 50 → 45 % at one-sided 5 %, 80 %.
        assert!((1150..1300).contains(&unpaired), "{unpaired}");
        let d = min_detectable_drop(0.5, |d| unpaired_power(0.5, 1240, 1240, d, 0.05));
        assert!(d.is_some_and(|d| (d - 0.05).abs() < 0.003), "{d:?}");
    }
}
