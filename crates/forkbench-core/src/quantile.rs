//! The one quantile convention of every median and percentile forkbench reports: nearest rank.

/// Nearest-rank quantile `q` (in [0, 1]) of already sorted values: the smallest value with
/// at least a fraction `q` of them at or below it (the median of an even count is the
/// lower middle one); `None` when there are none.
pub fn percentile_sorted(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    Some(sorted[rank - 1])
}

/// [`percentile_sorted`] of values in any order, NaNs left out.
pub fn quantile(values: impl IntoIterator<Item = f64>, q: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| !x.is_nan()).collect();
    v.sort_by(f64::total_cmp);
    percentile_sorted(&v, q)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank() {
        let v: Vec<f64> = (1..=10).map(f64::from).collect();
        assert_eq!(percentile_sorted(&v, 0.95), Some(10.0));
        assert_eq!(percentile_sorted(&v, 0.5), Some(5.0));
        assert_eq!(percentile_sorted(&v, 0.0), Some(1.0));
        assert_eq!(percentile_sorted(&[], 0.5), None);
        assert_eq!(quantile([3.0, f64::NAN, 1.0, 2.0], 0.5), Some(2.0));
        assert_eq!(quantile([4.0, 1.0, 3.0, 2.0], 0.5), Some(2.0));
        assert_eq!(quantile([f64::NAN], 0.5), None);
    }
}
