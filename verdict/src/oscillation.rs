//! The periods of the error's oscillation, from the spacing of its peaks.

use crate::fit::fit_line;

/// The periods of an error history's oscillation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Periods {
    /// The period of the error signal itself: the mean spacing of the peaks
    /// of `ln x` after removing its least-squares line, counting only peaks
    /// that rise at least `swing` above the troughs on either side (`|sin 2t|`
    /// has π/2). `None` with fewer than two such peaks.
    pub signal: Option<f64>,
    /// The period of the modulation of those peaks' heights (the beat of two
    /// close frequencies), found the same way in the sequence of peak heights.
    pub envelope: Option<f64>,
}

/// The periods of `x(t)`'s oscillation. Samples where `x` is not positive
/// are left out (they have no logarithm).
pub(crate) fn periods(t: &[f64], x: &[f64], swing: f64) -> Periods {
    let pts: Vec<(f64, f64)> = t
        .iter()
        .zip(x)
        .filter(|&(_, &v)| v > 0.0)
        .map(|(&t, &v)| (t, v.ln()))
        .collect();
    let Some(line) = fit_line(&pts) else {
        return Periods::default();
    };
    let residual: Vec<f64> = pts.iter().map(|&(t, y)| y - line.at(t)).collect();
    let level1: Vec<(f64, f64)> = peaks(&residual, swing)
        .into_iter()
        .map(|i| (pts[i].0, residual[i]))
        .collect();
    let heights: Vec<f64> = level1.iter().map(|p| p.1).collect();
    let level2: Vec<(f64, f64)> = peaks(&heights, swing)
        .into_iter()
        .map(|k| level1[k])
        .collect();
    Periods {
        signal: mean_spacing(&level1),
        envelope: mean_spacing(&level2),
    }
}

/// Mean spacing in time of at least two points.
fn mean_spacing(p: &[(f64, f64)]) -> Option<f64> {
    match (p.first(), p.last()) {
        (Some(a), Some(b)) if p.len() >= 2 => Some((b.0 - a.0) / (p.len() - 1) as f64),
        _ => None,
    }
}

/// Indices of the peaks of `r` with a trough at least `swing` below them on
/// both sides (hysteresis peak detection). It starts by looking for a
/// trough, so a run that starts high and falls has no peak at its start,
/// and a last maximum not followed by a fall of `swing` is not a peak.
fn peaks(r: &[f64], swing: f64) -> Vec<usize> {
    let mut out = Vec::new();
    let (mut hi, mut hi_at) = (f64::NEG_INFINITY, 0);
    let mut lo = f64::INFINITY;
    let mut rising = false;
    for (i, &v) in r.iter().enumerate() {
        if rising {
            if v > hi {
                (hi, hi_at) = (v, i);
            } else if v < hi - swing {
                out.push(hi_at);
                (rising, lo) = (false, v);
            }
        } else if v < lo {
            lo = v;
        } else if v > lo + swing {
            (rising, hi, hi_at) = (true, v, i);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{peaks, periods};
    use approx::assert_relative_eq;

    fn grid(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|i| i as f64 * dt).collect()
    }

    #[test]
    fn peaks_need_a_swing_on_both_sides() {
        let r = [1.0, 0.0, 1.0, 0.0, 0.5, 0.45, 0.9, 0.0, 0.8];
        assert_eq!(peaks(&r, 0.3), vec![2, 6]);
        assert!(peaks(&[0.0, 0.001, 0.0, 0.001], 0.01).is_empty());
    }

    #[test]
    fn period_of_a_rectified_sine_is_half_the_sine_period() {
        let t = grid(5000, 0.01);
        let x: Vec<f64> = t.iter().map(|&t| 0.2 * (2.0 * t).sin().abs()).collect();
        let p = periods(&t, &x, 0.01);
        let s = p.signal.expect("oscillates");
        assert_relative_eq!(s, std::f64::consts::FRAC_PI_2, max_relative = 1e-3);
        assert_eq!(p.envelope, None);
    }

    #[test]
    fn period_survives_a_decaying_trend() {
        let t = grid(5000, 0.01);
        let x: Vec<f64> = t
            .iter()
            .map(|&t| (-0.05 * t).exp() * (0.8 * t).cos().abs())
            .collect();
        let p = periods(&t, &x, 0.01).signal.expect("oscillates");
        assert_relative_eq!(p, std::f64::consts::PI / 0.8, max_relative = 1e-3);
    }

    #[test]
    fn monotone_signals_do_not_oscillate() {
        let t = grid(5000, 0.01);
        let one: Vec<f64> = t.iter().map(|&t| (-0.3 * t).exp()).collect();
        let two: Vec<f64> = t
            .iter()
            .map(|&t| (-0.3 * t).exp() + 0.1 * (-0.02 * t).exp())
            .collect();
        assert_eq!(periods(&t, &one, 0.01).signal, None);
        assert_eq!(periods(&t, &two, 0.01).signal, None);
        assert_eq!(periods(&t, &[0.3; 5000], 0.01).signal, None);
    }

    #[test]
    fn a_beat_is_the_envelope_period() {
        // sin t + 0.7 sin 1.1t: peaks every π s (the larger term sets the
        // mean phase speed), heights beating
        // with period 2π/0.1.
        let t = grid(100_000, 0.01);
        let x: Vec<f64> = t
            .iter()
            .map(|&t| (t.sin() + 0.7 * (1.1 * t).sin()).abs())
            .collect();
        let p = periods(&t, &x, 0.01);
        let s = p.signal.expect("oscillates");
        assert_relative_eq!(s, std::f64::consts::PI, max_relative = 0.02);
        let e = p.envelope.expect("beats");
        assert_relative_eq!(e, 20.0 * std::f64::consts::PI, max_relative = 0.02);
    }
}
