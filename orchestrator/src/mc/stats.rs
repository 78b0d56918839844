//! Exact binomial confidence bounds (Clopper–Pearson) for a failure rate.
//!
//! With `x` failures in `n` independent trials, the one-sided upper bound
//! at confidence `1 − α` is the `p` with `P(X ≤ x; n, p) = α` (for `x = 0`:
//! `1 − α^{1/n}`, about `3/n` at 95 %, the "rule of three"); the two-sided
//! interval puts `α/2` in each tail. Both invert the binomial CDF by
//! bisection (it is monotone in `p`), so they are exact to f64 precision.

/// `P(X ≤ x)` for `X ~ Binomial(n, p)`, summed in log space (no overflow
/// for large `n`).
#[must_use]
pub fn binomial_cdf(x: u64, n: u64, p: f64) -> f64 {
    if x >= n || p <= 0.0 {
        return 1.0;
    }
    if p >= 1.0 {
        return 0.0;
    }
    let (lp, lq) = (p.ln(), (-p).ln_1p());
    let mut log_choose = 0.0_f64; // ln C(n, k)
    let mut terms = Vec::with_capacity(x as usize + 1);
    for k in 0..=x {
        if k > 0 {
            log_choose += ((n - k + 1) as f64).ln() - (k as f64).ln();
        }
        terms.push(log_choose + k as f64 * lp + (n - k) as f64 * lq);
    }
    let top = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let sum: f64 = terms.iter().map(|t| (t - top).exp()).sum();
    (top + sum.ln()).exp().min(1.0)
}

/// The `p` in [0, 1] where the monotone `f` crosses `target` (increasing
/// `f` if `rising`), by 200 bisections.
fn invert(f: impl Fn(f64) -> f64, target: f64, rising: bool) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (f(mid) < target) == rising {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The exact one-sided upper confidence bound of a rate with `x` events in
/// `n` trials, at confidence `1 − alpha` (1 when `x = n`).
#[must_use]
pub fn upper_bound(x: u64, n: u64, alpha: f64) -> f64 {
    assert!(x <= n && n > 0 && alpha > 0.0 && alpha < 1.0);
    if x == n {
        return 1.0;
    }
    invert(|p| binomial_cdf(x, n, p), alpha, false)
}

/// The exact two-sided Clopper–Pearson interval `[lower, upper]` of a rate
/// with `x` events in `n` trials, at confidence `1 − alpha`.
#[must_use]
pub fn interval(x: u64, n: u64, alpha: f64) -> (f64, f64) {
    assert!(x <= n && n > 0 && alpha > 0.0 && alpha < 1.0);
    let lower = if x == 0 {
        0.0
    } else {
        // P(X ≥ x; p) = 1 − P(X ≤ x − 1; p), rising in p.
        invert(|p| 1.0 - binomial_cdf(x - 1, n, p), alpha / 2.0, true)
    };
    let upper = if x == n {
        1.0
    } else {
        invert(|p| binomial_cdf(x, n, p), alpha / 2.0, false)
    };
    (lower, upper)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_failures_in_200_trials() {
        // 1 − 0.05^(1/200) and 1 − 0.025^(1/200).
        let one_sided = upper_bound(0, 200, 0.05);
        assert!((one_sided - 0.014_867_4).abs() < 1e-6, "{one_sided}");
        assert!((one_sided - (1.0 - 0.05_f64.powf(1.0 / 200.0))).abs() < 1e-12);
        let (lo, hi) = interval(0, 200, 0.05);
        assert_eq!(lo, 0.0);
        assert!((hi - 0.018_275).abs() < 1e-6, "{hi}");
        assert!((3.0 / 200.0 - one_sided).abs() < 2e-4);
    }

    #[test]
    fn published_intervals() {
        // Clopper & Pearson (1934) style tables, e.g. R's binom.test:
        // 1/10 → [0.002529, 0.445016]; 5/10 → [0.187086, 0.812914].
        let (lo, hi) = interval(1, 10, 0.05);
        assert!((lo - 0.002_529).abs() < 1e-6 && (hi - 0.445_016).abs() < 1e-6);
        let (lo, hi) = interval(5, 10, 0.05);
        assert!((lo - 0.187_086).abs() < 1e-6 && (hi - 0.812_914).abs() < 1e-6);
        assert_eq!(interval(10, 10, 0.05).1, 1.0);
        assert_eq!(upper_bound(7, 7, 0.05), 1.0);
    }

    #[test]
    fn cdf_sums_to_one_and_is_exact_at_small_n() {
        assert!((binomial_cdf(3, 3, 0.3) - 1.0).abs() < 1e-15);
        // P(X ≤ 1; 3, 0.5) = 4/8.
        assert!((binomial_cdf(1, 3, 0.5) - 0.5).abs() < 1e-14);
        assert!(binomial_cdf(0, 100_000, 0.5) < 1e-300 || binomial_cdf(0, 100_000, 0.5) == 0.0);
    }
}
