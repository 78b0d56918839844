//! Hand-made error histories.

#![allow(dead_code)]

use attsync_verdict::{Thresholds, Verdict, classify};

/// Samples `0, dt, 2dt, …` up to and including `horizon`.
pub fn grid(horizon: f64, dt: f64) -> Vec<f64> {
    let n = (horizon / dt).round() as usize;
    (0..=n).map(|i| i as f64 * dt).collect()
}

/// `f` sampled every 0.01 s over `[0, horizon]` and classified against `tol`
/// with the default thresholds.
pub fn judge(horizon: f64, tol: f64, f: impl Fn(f64) -> f64) -> Verdict {
    let t = grid(horizon, 0.01);
    let x: Vec<f64> = t.iter().map(|&t| f(t)).collect();
    classify(&t, &x, tol, &Thresholds::default())
}

/// `|a − b| ≤ rel·|b|`.
pub fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// The fitted rate, or a panic naming the verdict.
pub fn rate(v: &Verdict) -> f64 {
    v.decay_rate
        .unwrap_or_else(|| panic!("no decay rate in {v:#?}"))
}

/// Deterministic noise in [0, 1) (a linear congruential generator on `i`).
pub fn noise(i: u64) -> f64 {
    let s = i
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (s >> 11) as f64 / (1u64 << 53) as f64
}
