//! The one definition of a settle time.

/// Time after which `x` stays below `threshold`: the sample after the last
/// one at or above it (NaN counts as above); `Some(t[0])` if always below;
/// `None` if the last sample is not below (or there are no samples).
///
/// Only the first `min(t.len(), x.len())` samples are read.
///
/// ```
/// # use attsync_verdict::settle_time;
/// let t = [0.0, 1.0, 2.0, 3.0];
/// assert_eq!(settle_time(&t, &[1.0, 1e-4, 2e-3, 1e-4], 1e-3), Some(3.0));
/// ```
#[must_use]
pub fn settle_time(t: &[f64], x: &[f64], threshold: f64) -> Option<f64> {
    let n = t.len().min(x.len());
    match x[..n].iter().rposition(|&e| e >= threshold || e.is_nan()) {
        None => t.first().copied().filter(|_| n > 0),
        Some(k) if k + 1 < n => Some(t[k + 1]),
        Some(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::settle_time;

    #[test]
    fn the_sample_after_the_last_excursion() {
        let t = [0.0, 1.0, 2.0, 3.0];
        assert_eq!(settle_time(&t, &[1.0, 1e-4, 2e-3, 1e-4], 1e-3), Some(3.0));
        assert_eq!(settle_time(&t, &[1e-4; 4], 1e-3), Some(0.0));
        assert_eq!(settle_time(&t, &[1e-4, 1e-4, 1e-4, 1.0], 1e-3), None);
    }

    #[test]
    fn nan_counts_as_above_and_equal_is_not_below() {
        let t = [0.0, 1.0, 2.0];
        assert_eq!(settle_time(&t, &[f64::NAN, 0.0, 0.0], 1e-3), Some(1.0));
        assert_eq!(settle_time(&t, &[0.0, 1e-3, 0.0], 1e-3), Some(2.0));
        assert_eq!(settle_time(&t, &[0.0, 0.0, f64::NAN], 1e-3), None);
    }

    #[test]
    fn no_samples_never_settle() {
        assert_eq!(settle_time(&[], &[], 1e-3), None);
        assert_eq!(settle_time(&[0.0, 1.0], &[], 1e-3), None);
    }
}
