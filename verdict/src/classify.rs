//! The decision: from an error history to a [`Verdict`].

use crate::envelope;
use crate::kind::Kind;
use crate::oscillation::{self, Periods};
use crate::settle::settle_time;
use crate::thresholds::Thresholds;
use crate::trend::{Shape, Trend};
use crate::verdict::Verdict;

/// Classifies the history `x(t)` (samples in time order, typically the
/// largest attitude error over agents at each sample; only the first
/// `min(t.len(), x.len())` are read) against `tolerance`.
///
/// `docs/verdicts.md`, "How a verdict is reached", states the rules.
#[must_use]
pub fn classify(t: &[f64], x: &[f64], tolerance: f64, th: &Thresholds) -> Verdict {
    let n = t.len().min(x.len());
    let (t, x) = (&t[..n], &x[..n]);
    let mut v = judge(t, x, tolerance, th);
    v.settle_time = settle_time(t, x, tolerance);
    v
}

/// Everything but the settle time.
fn judge(t: &[f64], x: &[f64], tol: f64, th: &Thresholds) -> Verdict {
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        let why = format!("the error is not finite at t = {} s", t[i]);
        return Verdict::bare(Kind::Diverging, tol, [t[i], t[i]], why);
    }
    let Some(&t1) = t.last() else {
        return Verdict::bare(Kind::Undecided, tol, [0.0, 0.0], "no samples".into());
    };
    let start = window_start(t, th.window_fraction);
    let window = [t[start], t1];
    match evidence(t, x, start, th) {
        Ok(ev) => decide(&ev, tol, th),
        Err(why) => Verdict::bare(Kind::Undecided, tol, window, why.to_string()),
    }
}

/// What the window `start..` shows, or why it is too short to tell.
fn evidence(t: &[f64], x: &[f64], start: usize, th: &Thresholds) -> Result<Evidence, TooShort> {
    let (samples, window) = (t.len() - start, [t[start], t[t.len() - 1]]);
    let span = window[1] - window[0];
    if samples < th.min_samples.max(3) || span.is_nan() || span <= 0.0 {
        let need = th.min_samples;
        return Err(TooShort::Samples { samples, need });
    }
    let periods = oscillation::periods(&t[start..], &x[start..], th.oscillation_swing);
    let count = block_count(samples, window, periods, th);
    if count < th.min_blocks.max(3) {
        let need = th.min_blocks;
        return Err(match periods.signal {
            Some(period) => TooShort::Periods { span, period, need },
            None => TooShort::Blocks { samples, need },
        });
    }
    let blocks = envelope::blocks(t, x, start, count);
    Ok(Evidence {
        window,
        period: periods.signal,
        trend: Trend::fit(&blocks, window, th),
        last_max: blocks.last().map_or(f64::INFINITY, |b| b.max),
        window_max: blocks.iter().map(|b| b.max).fold(0.0, f64::max),
        before_max: x[..start].iter().copied().fold(0.0, f64::max),
    })
}

/// Why the window is too short to tell (the verdict's reason).
#[derive(Debug, Clone, Copy, PartialEq)]
enum TooShort {
    /// Fewer samples than needed, or a window of no length.
    Samples {
        /// Samples in the window.
        samples: usize,
        /// `min_samples`.
        need: usize,
    },
    /// Too few periods of the oscillation for the blocks.
    Periods {
        /// The window's length, s.
        span: f64,
        /// The oscillation's period, s.
        period: f64,
        /// `min_blocks`.
        need: usize,
    },
    /// Too few samples for the blocks.
    Blocks {
        /// Samples in the window.
        samples: usize,
        /// `min_blocks`.
        need: usize,
    },
}

impl std::fmt::Display for TooShort {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            TooShort::Samples { samples, need } => {
                write!(f, "{samples} samples in the window, {need} needed")
            }
            TooShort::Periods { span, period, need } => write!(
                f,
                "the {span:.3} s window holds too few periods ({period:.4} s) of the oscillation for {need} blocks"
            ),
            TooShort::Blocks { samples, need } => {
                write!(f, "{samples} samples are too few for {need} blocks")
            }
        }
    }
}

/// First sample of the trailing window `[t_end − f·(t_end − t₀), t_end]`.
fn window_start(t: &[f64], fraction: f64) -> usize {
    let (t0, t1) = (t[0], t[t.len() - 1]);
    let cut = t1 - fraction.clamp(0.0, 1.0) * (t1 - t0);
    t.partition_point(|&s| s < cut).min(t.len() - 1)
}

/// As many blocks as `max_blocks` allows, each holding at least two samples
/// and lasting at least `block_periods` envelope periods (the beat) if that
/// leaves `min_blocks`, else `block_periods` signal periods.
fn block_count(samples: usize, window: [f64; 2], p: Periods, th: &Thresholds) -> usize {
    let fit = |period: Option<f64>| {
        let by_period = period.map_or(usize::MAX, |p| {
            ((window[1] - window[0]) / (th.block_periods * p)).floor() as usize
        });
        th.max_blocks.min(by_period).min(samples / 2)
    };
    let beat = fit(p.envelope.or(p.signal));
    if beat >= th.min_blocks {
        beat
    } else {
        fit(p.signal)
    }
}

/// What the window shows.
struct Evidence {
    window: [f64; 2],
    period: Option<f64>,
    trend: Option<Trend>,
    /// The largest error of the last block.
    last_max: f64,
    /// The largest error of the window.
    window_max: f64,
    /// The largest error before the window (0 if none).
    before_max: f64,
}

/// The rules, in order: below the tolerance over the last block → converged
/// unless growing; above it → by the trend's shape.
fn decide(ev: &Evidence, tol: f64, th: &Thresholds) -> Verdict {
    let shape = ev.trend.map(|tr| tr.shape(th));
    let mut v = match (ev.last_max < tol, shape) {
        (_, Some(Shape::Growing)) if ev.last_max > ev.before_max => growing(ev, tol),
        (_, Some(Shape::Growing)) => transient(ev, tol),
        (true, _) => converged(ev, tol),
        (false, Some(Shape::Decaying)) => converging(ev, tol),
        (false, Some(Shape::Flat)) => persistent(ev, tol, "its envelope is flat"),
        (false, Some(s)) => unresolved(ev, tol, s),
        (false, None) if ev.window_max <= th.floor => persistent(
            ev,
            tol,
            "it sits at the round-off floor, above the tolerance",
        ),
        (false, None) => {
            let why = "fewer than 3 envelope blocks are above the round-off floor";
            Verdict::bare(Kind::Undecided, tol, ev.window, why.into())
        }
    };
    v.decay_rate = ev.trend.map(|tr| tr.rate);
    v.decay_rate_se = ev.trend.map(|tr| tr.rate_se);
    v
}

fn converged(ev: &Evidence, tol: f64) -> Verdict {
    let why = format!(
        "the error stays below the tolerance {tol:e} (largest {:.3e} over the last envelope block) and does not grow",
        ev.last_max
    );
    Verdict::bare(Kind::Converged, tol, ev.window, why)
}

fn growing(ev: &Evidence, tol: f64) -> Verdict {
    let why = match ev.trend {
        Some(tr) => format!(
            "the envelope grows at {:+.4e}/s ({:+.3} ± {:.3} in ln over the window)",
            tr.rate, tr.change, tr.uncertainty
        ),
        None => "the envelope grows".into(),
    };
    Verdict::bare(Kind::Diverging, tol, ev.window, why)
}

/// Growth that has not passed the error's earlier peak: a transient
/// (errors of a stable network can grow for a while), not yet divergence.
fn transient(ev: &Evidence, tol: f64) -> Verdict {
    let rate = ev.trend.map_or(f64::NAN, |tr| tr.rate);
    let why = format!(
        "the envelope grows at {rate:+.4e}/s but stays below the error's earlier peak \
         {:.3e}: a transient so far; run longer",
        ev.before_max
    );
    Verdict::bare(Kind::Undecided, tol, ev.window, why)
}

fn converging(ev: &Evidence, tol: f64) -> Verdict {
    let mut v = Verdict::bare(Kind::Converging, tol, ev.window, String::new());
    if let Some(tr) = ev.trend {
        let t_end = ev.window[1];
        let projected = (t_end + (tol / tr.end).ln() / tr.rate).max(t_end);
        v.projected_time = Some(projected);
        v.reason = format!(
            "the envelope ({:.3e} at the window's end) decays at {:+.4e}/s ({:+.3} ± {:.3} in ln over the window) and reaches {tol:e} at t ≈ {projected:.4} s",
            tr.end, tr.rate, tr.change, tr.uncertainty
        );
    }
    v
}

fn persistent(ev: &Evidence, tol: f64, what: &str) -> Verdict {
    let mut v = Verdict::bare(Kind::Persistent, tol, ev.window, String::new());
    v.amplitude = Some(ev.window_max);
    v.period = ev.period;
    let osc = ev.period.map_or("an offset".to_string(), |p| {
        format!("an oscillation of period {p:.4} s")
    });
    v.reason = format!(
        "the error stays above the tolerance {tol:e} as {osc} up to {:.3e}: {what}{}",
        ev.window_max,
        ev.trend.map_or(String::new(), |tr| format!(
            " ({:+.2e} ± {:.2e} in ln over the window)",
            tr.change, tr.uncertainty
        ))
    );
    v
}

fn unresolved(ev: &Evidence, tol: f64, shape: Shape) -> Verdict {
    let (change, u) = ev
        .trend
        .map_or((f64::NAN, f64::NAN), |tr| (tr.change, tr.uncertainty));
    let why = if shape == Shape::Slow {
        format!(
            "the envelope changes by {change:+.3} in ln over the window (± {u:.2e}): a trend too slow for this window; run longer"
        )
    } else if let Some([a, b]) = ev
        .trend
        .and_then(|tr| tr.halves)
        .filter(|_| shape == Shape::Bending)
    {
        format!(
            "the envelope's rate changes within the window ({a:+.3e}/s in its first half, {b:+.3e}/s in its last): not yet one exponential"
        )
    } else {
        format!(
            "the fit cannot establish the sign of the envelope's change ({change:+.3} ± {u:.3} in ln over the window)"
        )
    };
    Verdict::bare(Kind::Undecided, tol, ev.window, why)
}
