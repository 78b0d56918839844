//! The choices that keep a generated scenario valid, stable and long enough:
//! scheme 1's `k_ω`, `k_σ` (Appendix D), `dt` (RK4's stable step) and the
//! duration (the slowest linear mode, within the step limit), all from one
//! resolve of the drawn scenario ([`Analysis`]): the spectrum of `Ξ + LLᵀ`
//! does not depend on the gains, and the stiffness estimate depends on `dt`
//! and the duration not at all.

use crate::scenario::StiffnessCheck;
use crate::scenario::resolve::{self, MAX_STEPS, Resolved, stable_dt};
use crate::scenario::schema::Scenario;
use attitude::network::Scheme;
use attitude::observer::ObserverGains;
use attitude::spectrum::{
    appendix_d_balanced_gain, appendix_d_k_sigma_threshold, appendix_d_min_eigenvalue_from_extremes,
};
use attitude::stiffness::Estimate;

/// Margin of the generated `k_σ` over the smallest one for which the matrix
/// F of Appendix D is positive definite.
pub const K_SIGMA_MARGIN: f64 = 1.25;

/// The generated `dt` is at most this fraction of the largest stable RK4
/// step (`docs/stiffness.md`), rounded down to `0.001 / n`.
pub const DT_FRACTION: f64 = 0.5;

/// The paper's step, s; a generated `dt` is it divided by a round number.
pub(super) const PAPER_DT: f64 = 0.001;

/// The duration when `--duration` is not given, at least, s.
pub const DEFAULT_DURATION: f64 = 40.0;

/// The estimated time to converge is this multiple of the slowest linear
/// mode's time to decay by 1e6 (`ln(1e6) / rate`): the linear estimate
/// ignores the nonlinear transient from large initial errors
/// (`docs/stiffness.md`, "How long a generated network needs").
pub const CONVERGE_MULTIPLE: f64 = 4.0;

/// A generated duration is a whole multiple of this, s (and so of every
/// generated `dt`, `0.001 / n`).
const DURATION_QUANTUM: f64 = 10.0;

/// The drawn scenario, resolved once (with the stiffness check only warning).
pub(super) struct Analysis {
    resolved: Resolved,
}

impl Analysis {
    /// Resolves `s`, its duration set aside (a given `--duration` is checked
    /// against the picked `dt` at the end, [`super::tree`]); `None` if the
    /// drawn scenario is invalid.
    pub(super) fn of(s: &mut Scenario) -> Option<Self> {
        let duration = std::mem::replace(&mut s.simulation.duration, DEFAULT_DURATION);
        let resolved = resolve::resolve_with(s, StiffnessCheck::Warn).ok();
        s.simulation.duration = duration;
        resolved.map(|resolved| Self { resolved })
    }

    /// The stiffness estimate with `s`'s scheme-1 observer gains
    /// (those [`pick_gains`] chose), as a resolve of `s` would give it.
    fn estimate(&self, s: &Scenario) -> Option<Estimate> {
        let first = &self.resolved.network.agents.first()?.model;
        let scheme = match (first.scheme, &s.scheme.observer) {
            (Scheme::ObserverTimeVarying { observer, control }, Some(o)) => {
                Scheme::ObserverTimeVarying {
                    observer: ObserverGains {
                        k_w: o.k_omega,
                        k_sigma: o.k_sigma.unwrap_or(observer.k_sigma),
                        ..observer
                    },
                    control,
                }
            }
            (other, _) => other,
        };
        resolve::stiffness_with(&self.resolved, scheme)
    }
}

/// Picks the gains, `dt` and duration of `s` (see [`super::tree`]);
/// returns the notes and the warning.
pub(super) fn pick(
    s: &mut Scenario,
    a: &Analysis,
    given: Option<f64>,
) -> (Vec<String>, Option<String>) {
    let mut notes: Vec<String> = pick_gains(s, a).into_iter().collect();
    let Some(est) = a.estimate(s) else {
        return (notes, None);
    };
    notes.extend(pick_dt(s, &est));
    let (note, warning) = pick_duration(s, given, &est);
    notes.extend(note);
    (notes, warning)
}

/// For scheme 1, Theorem 1's gain condition (`F > 0`, Appendix D). The
/// paper's gains when `k_σ = 12 ≥ K_SIGMA_MARGIN · k_σ*(k_ω = 14)`
/// ([`appendix_d_k_sigma_threshold`]); otherwise `k_ω = k_σ = k`, the
/// smallest equal pair with `k_σ ≥ K_SIGMA_MARGIN · k_σ*(k_ω = k)` (the
/// condition is on the product, [`appendix_d_balanced_gain`]: equal gains
/// keep the fastest mode, `∝ max(k_ω, k_σ)`, and so the step, as large as
/// possible). Confirmed by the exact test. Returns the reason, for the
/// file's header.
fn pick_gains(s: &mut Scenario, a: &Analysis) -> Option<String> {
    let o = s.scheme.observer.as_mut()?;
    let paper = o.k_sigma?;
    let p = a.resolved.network.p;
    // The thresholds are decreasing in λ > 0: λmin decides them.
    let ext = a.resolved.spectrum_extremes;
    let paper_ok = K_SIGMA_MARGIN * appendix_d_k_sigma_threshold(ext, o.k_omega, &p) <= paper;
    let (mut k_w, mut k_s) = if paper_ok {
        (o.k_omega, paper)
    } else {
        let k = appendix_d_balanced_gain(ext, &p, K_SIGMA_MARGIN).max(o.k_omega.max(paper));
        (k, k)
    };
    // The exact test, once: a round-off at the boundary only ever asks for more.
    for _ in 0..8 {
        if appendix_d_min_eigenvalue_from_extremes(ext, k_w, k_s, &p) > 0.0 {
            break;
        }
        (k_w, k_s) = (k_w * 2.0, k_s * 2.0);
    }
    (o.k_omega, o.k_sigma) = (k_w, Some(k_s));
    let threshold = appendix_d_k_sigma_threshold(ext, k_w, &p);
    Some(if paper_ok {
        format!(
            "k_sigma = {k_s}, k_omega = {k_w} (the paper's): F of Appendix D (Theorem 1's gain condition) is positive definite iff k_sigma > {threshold:.4e}, and {K_SIGMA_MARGIN} × that <= {paper}"
        )
    } else {
        format!(
            "k_sigma = k_omega = {k_s:.4}: F of Appendix D (Theorem 1's gain condition) is positive definite iff k_sigma > {threshold:.4e} at this k_omega; the condition is on the product k_sigma·k_omega, so both are raised together to the smallest equal pair with k_sigma >= {K_SIGMA_MARGIN} × that (the paper's {paper} is too small for this graph; docs/stiffness.md)"
        )
    })
}

/// `dt ≤ DT_FRACTION · dt_max` as `0.001 / n` (so that the default sample
/// period and any duration in ms stay whole multiples). Returns the reason.
fn pick_dt(s: &mut Scenario, est: &Estimate) -> Option<String> {
    let b = est.binding()?;
    let dt = stable_dt(PAPER_DT, DT_FRACTION * est.dt_max);
    s.simulation.dt = dt;
    Some(format!(
        "dt = {dt} s: the largest stable RK4 step of the linearised loops is {:.3e} s ({} loop, fastest mode {:.3e} 1/s; docs/stiffness.md); generated as {PAPER_DT}/n <= {DT_FRACTION} × that",
        est.dt_max, b.name, b.fastest_rate
    ))
}

/// The estimated time for every loop to converge, s:
/// `CONVERGE_MULTIPLE · ln(1e6) / slowest_rate`, and the loop and rate.
fn converge_time(est: &Estimate) -> Option<(f64, &'static str, f64)> {
    let slow = est.slowest()?;
    let t = CONVERGE_MULTIPLE * 1e6f64.ln() / slow.slowest_rate;
    t.is_finite().then_some((t, slow.name, slow.slowest_rate))
}

/// `simulation.duration`: the given one, with a note and a warning when the
/// estimate says it is too short to converge; else
/// `max(DEFAULT_DURATION, the estimate)` rounded up to a whole 10 s (a
/// whole multiple of every generated `dt`), but at most the longest whole
/// 10 s within [`MAX_STEPS`] steps of `dt` (then with a note and a
/// warning: `check` refuses a longer horizon). Returns (note, warning).
fn pick_duration(
    s: &mut Scenario,
    given: Option<f64>,
    est: &Estimate,
) -> (Option<String>, Option<String>) {
    let Some((t, name, rate)) = converge_time(est) else {
        return (None, None);
    };
    let why = format!(
        "an ESTIMATE, not a promise: the slowest linear mode ({name} loop, bounded by its \
         gains' and the graph's eigenvalue extremes) decays at {rate:.3e} 1/s, so converging \
         to 1e-6 would need about {CONVERGE_MULTIPLE} × ln(1e6)/rate = {t:.0} s \
         (docs/stiffness.md); the real network may be slower (large initial errors, the \
         coupling of the modes): `attsync margin FILE` gives the linearisation's exact \
         slowest rate, and `attsync run --until settled` extends a run until its verdict \
         is final (docs/verdicts.md)"
    );
    match given {
        Some(d) if d < t => {
            let w = format!(
                "duration = {d} s (as given) is shorter than the estimate: {why}; the run may not converge"
            );
            (Some(w.clone()), Some(w))
        }
        Some(d) => (Some(format!("duration = {d} s (as given): {why}")), None),
        None => {
            let d = DEFAULT_DURATION.max((t / DURATION_QUANTUM).ceil() * DURATION_QUANTUM);
            let dt = s.simulation.dt;
            let longest = longest_duration(dt);
            if d <= longest {
                s.simulation.duration = d;
                return (
                    Some(format!(
                        "duration = {d} s: {why}; generated as max({DEFAULT_DURATION}, that) rounded up to 10 s"
                    )),
                    None,
                );
            }
            s.simulation.duration = longest;
            let w = format!(
                "duration = {longest} s: {why}, more than check allows (at most 2^40 = {MAX_STEPS:e} steps of dt = {dt} s), so it is clamped to the longest whole 10 s within that limit; the run may not converge"
            );
            (Some(w.clone()), Some(w))
        }
    }
}

/// The longest whole multiple of [`DURATION_QUANTUM`] that is at most
/// [`MAX_STEPS`] steps of `dt` (0 when none is).
fn longest_duration(dt: f64) -> f64 {
    let mut d = (MAX_STEPS * dt / DURATION_QUANTUM).floor() * DURATION_QUANTUM;
    // `check` rounds `d / dt` to the step count: stay within the limit after it.
    while d > 0.0 && (d / dt).round() > MAX_STEPS {
        d -= DURATION_QUANTUM;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_longest_duration_is_whole_10_s_within_the_step_limit() {
        for dt in [5e-8, 1e-7, 2e-9, 0.001 / 3.0] {
            let d = longest_duration(dt);
            assert_eq!(d % DURATION_QUANTUM, 0.0, "{dt}");
            assert!((d / dt).round() <= MAX_STEPS, "{dt}: {d}");
            assert!(
                ((d + DURATION_QUANTUM) / dt).round() > MAX_STEPS,
                "{dt}: {d}"
            );
        }
        assert_eq!(longest_duration(5e-8), 54_970.0);
        assert_eq!(longest_duration(1e-12), 0.0);
    }
}
