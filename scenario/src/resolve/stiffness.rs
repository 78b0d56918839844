//! The step size the theory allows (after `checks`, on the assembled
//! network): the fastest linear mode of each loop of the scheme and RK4's
//! largest stable step ([`attitude::stiffness`], `docs/stiffness.md`).
//!
//! A `simulation.dt` above [`REFUSE_FACTOR`]`·dt_max` is refused (or, with
//! `--no-stiffness-check`, only warned about); one in
//! `[`[`WARN_FROM`]`, `[`REFUSE_FACTOR`]`]·dt_max` is warned about.

use super::ctx::Ctx;
use attitude::checks::sym_eigenvalues;
use attitude::network::{AgentModel, Network, Scheme};
use attitude::stiffness::{Estimate, Interval, Loop, estimate, psi_gain};
use nalgebra::Matrix3;

/// What validation does with a `simulation.dt` clearly beyond the largest
/// stable RK4 step of the scenario's loops (`docs/stiffness.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StiffnessCheck {
    /// Refuse the scenario (exit code 2), naming a `dt` that would work.
    #[default]
    Refuse,
    /// Only warn (`--no-stiffness-check`): the run goes on and may diverge.
    Warn,
}

impl StiffnessCheck {
    /// The policy of the flag `--no-stiffness-check` (`true` if given).
    #[must_use]
    pub fn from_flag(no_stiffness_check: bool) -> Self {
        if no_stiffness_check {
            Self::Warn
        } else {
            Self::Refuse
        }
    }
}

/// A `dt` above this multiple of the estimated `dt_max` is "clearly beyond"
/// it and refused. Calibrated on runs (`docs/stiffness.md`, "Calibration"):
/// where the estimate is exact (the observers' `σ̂` and `ω̂` modes, a
/// tracking loop whose fastest gain and inertia belong to one agent) runs
/// diverge just above `dt_max`, but the estimate bounds gains and inertias
/// by their extremes separately, and the observerless paper scenario with a
/// stiff `k_Ř` stayed finite up to 1.5·dt_max (diverged from 1.6): at 2 no
/// calibration run that is refused would have run.
pub const REFUSE_FACTOR: f64 = 2.0;

/// A `dt` at or above this multiple of `dt_max` (and not refused) is warned about.
pub const WARN_FROM: f64 = 0.8;

/// The extremes `[λmin, λmax]` of the spectrum of `Ξ + LLᵀ`.
///
/// # NOTE
/// The one place the stiffness estimate takes the graph's spectrum: today
/// the dense eigenvalues `checks` computed (ascending); a sparse extreme
/// eigenvalue solver for large graphs replaces this function only.
pub(super) fn graph_extremes(spectrum: &[f64]) -> Option<Interval> {
    Some(Interval {
        min: *spectrum.first()?,
        max: *spectrum.last()?,
    })
}

/// The loops of `scheme` (`net`'s own, or the same with other gains) with
/// what their linearisations need from `net`, or `None` for a network
/// without agents.
pub(super) fn loops(net: &Network, scheme: Scheme, graph: Interval) -> Option<Vec<Loop>> {
    let models: Vec<&AgentModel> = net.agents.iter().map(|a| &a.model).collect();
    let coupling = eig_interval(models.iter().flat_map(|m| {
        m.neighbours
            .iter()
            .map(|n| psi_gain(&n.a))
            .chain(m.leader_gain.as_ref().map(psi_gain))
    }))?;
    let j = eig_interval(models.iter().map(|m| m.inertia.j))?;
    let tracking_e = eig_interval(models.iter().map(|m| psi_gain(&m.a_bar)))?;
    let observer = |o: &attitude::observer::ObserverGains, p| Loop::Observer {
        k_r: o.k_r,
        k_w: o.k_w,
        k_sigma: o.k_sigma,
        p,
        e: coupling,
        graph,
    };
    let tracking = |c: &attitude::control::ControlGains| Loop::Tracking {
        k_r: c.k_r,
        k_w: c.k_w,
        e: tracking_e,
        j,
    };
    Some(match scheme {
        Scheme::ObserverTimeVarying {
            observer: o,
            control,
        } => vec![
            observer(&o, Some(net.p)),
            tracking(&control),
            Loop::Leader { p: net.p },
        ],
        Scheme::ObserverConstant {
            observer: o,
            control,
        } => {
            vec![observer(&o, None), tracking(&control)]
        }
        Scheme::Observerless { control } => vec![Loop::Observerless {
            k_r: control.k_r,
            k_w: control.k_w,
            e: coupling,
            j,
            graph,
        }],
    })
}

/// The interval of the eigenvalues of symmetric matrices.
fn eig_interval(ms: impl Iterator<Item = Matrix3<f64>>) -> Option<Interval> {
    ms.map(|m| {
        let e = sym_eigenvalues(&m);
        Interval {
            min: e[0],
            max: e[2],
        }
    })
    .reduce(Interval::union)
}

/// The estimate for `net` (graph spectrum `spectrum`, ascending) and its
/// verdict on `simulation.dt`: an error or a warning in `c` when `dt` is
/// beyond or close to the largest stable step.
pub(super) fn stiffness(
    c: &mut Ctx,
    net: &Network,
    spectrum: &[f64],
    check: StiffnessCheck,
) -> Option<Estimate> {
    let scheme = net.agents.first()?.model.scheme;
    let est = estimate(&loops(net, scheme, graph_extremes(spectrum)?)?);
    let Some(b) = est.binding().filter(|b| b.dt_max.is_finite()) else {
        return Some(est);
    };
    let dt = net.dt;
    let what = format!(
        "the largest stable step ≈ {:.1e} s of the {} loop (fastest mode {:.1e} s⁻¹, docs/stiffness.md)",
        b.dt_max, b.name, b.fastest_rate
    );
    let fix = format!(
        "try --set simulation.dt={}",
        stable_dt(dt, WARN_FROM * b.dt_max)
    );
    if dt > REFUSE_FACTOR * b.dt_max {
        let reason = format!("dt = {dt} s exceeds {what}; RK4 diverges: {fix}");
        match check {
            StiffnessCheck::Refuse => c.err("simulation.dt", reason),
            StiffnessCheck::Warn => c.warn(
                "simulation.dt",
                format!("{reason} (not refused: --no-stiffness-check)"),
            ),
        }
    } else if dt >= WARN_FROM * b.dt_max {
        c.warn(
            "simulation.dt",
            format!(
                "dt = {dt} s is {:.2} × {what}: close to RK4's stability limit, the run may diverge; {fix}",
                dt / b.dt_max
            ),
        );
    }
    Some(est)
}

/// The largest `dt / n` at most `limit`, `n` one of 1, 2, 4, 5, 10, 20, 40,
/// 50, …: a divisor of `dt` (so every field that was a whole multiple of
/// `dt` stays one) that keeps a decimal `dt` decimal. `dt` itself if it is
/// within `limit` already.
#[must_use]
pub fn stable_dt(dt: f64, limit: f64) -> f64 {
    if !(limit > 0.0 && dt > 0.0) {
        return dt;
    }
    let mut decade = 1.0;
    loop {
        for m in [1.0, 2.0, 4.0, 5.0] {
            let n = m * decade;
            if dt / n <= limit || n > 1e15 {
                return dt / n;
            }
        }
        decade *= 10.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stable_dt_divides_dt_by_a_round_number() {
        assert_eq!(stable_dt(0.001, 0.01), 0.001);
        assert_eq!(stable_dt(0.001, 0.0006), 0.0005);
        assert_eq!(stable_dt(0.001, 1.9e-4), 0.001 / 10.0);
        assert_eq!(stable_dt(0.001, 3e-4), 0.001 / 4.0);
        assert!(stable_dt(0.001, 1.5e-6) <= 1.5e-6);
    }

    #[test]
    fn graph_extremes_are_the_ends_of_the_spectrum() {
        assert_eq!(graph_extremes(&[]), None);
        assert_eq!(
            graph_extremes(&[0.1, 1.0, 4.5]),
            Some(Interval { min: 0.1, max: 4.5 })
        );
    }
}
