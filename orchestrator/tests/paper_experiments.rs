//! The paper's three experiments (Section `simulation`) as shipped in
//! `scenarios/paper/`, run with the in-process engine.
//!
//! Theorem `estimationstability` (scheme 1) and the theorems of Section
//! `constant` (schemes 2, 3) claim that every agent's attitude converges to
//! the leader's. With the corrected signs of erratum 1 this is exact
//! convergence: every agent's `|Rᵢ R₀ᵀ|_I` is below 1e-5 after 40 s. (With the
//! printed signs scheme 1 stalls near 1e-2; see
//! `attitude/tests/issue_2_erratum_sigma_gamma.rs`.)
//!
//! Step halving: dt = 1 ms and 0.5 ms give the same error curves to 1e-8 once
//! the first second's stiff transient is over (the tracking loop has a pole
//! at k_ω̄/J ≈ 130 s⁻¹, so RK4's error in the first tens of milliseconds is
//! ~1e-6 at 1 ms; it shrinks 16× per halving, which is also checked). Agent 5
//! of scheme 1 starts on the stable manifold of an unstable equilibrium and
//! leaves it at a time set by round-off (docs/paper.md), so its curve is excluded
//! from the comparison after it escapes.

mod common;

use attitude::engine::InProcess;
use attitude::metrics::errors;
use attsync::scenario::Loaded;
use common::load_paper;

/// `(t, agent id, att_err, angvel_err)` at every output sample.
fn error_curves(l: &Loaded) -> Vec<(f64, u32, f64, f64)> {
    let net = &l.resolved.network;
    let mut out = Vec::new();
    InProcess::new(net).run(|s| {
        for (x, a) in s.agents.iter().zip(&net.agents) {
            let e = errors(x, s.leader, false);
            out.push((s.step as f64 * net.dt, a.model.id, e.att, e.angvel));
        }
        true
    });
    out
}

fn assert_converges(name: &str) {
    let l = load_paper(name, &[]);
    let curves = error_curves(&l);
    let n = l.resolved.network.agents.len();
    let last = &curves[curves.len() - n..];
    assert!((last[0].0 - 40.0).abs() < 1e-9);
    for &(_, id, att, angvel) in last {
        assert!(att < 1e-5, "{name}: agent {id} att_err {att:e} at 40 s");
        assert!(
            angvel < 1e-4,
            "{name}: agent {id} angvel_err {angvel:e} at 40 s"
        );
    }
}

#[test]
fn scheme_1_time_varying_converges() {
    assert_converges("timevarying");
}

#[test]
fn scheme_2_constant_observer_converges() {
    assert_converges("constant-observer");
}

#[test]
fn scheme_3_constant_observerless_converges() {
    assert_converges("constant-observerless");
}

/// Largest |difference| of att_err and angvel_err between two runs, over
/// samples with t ≥ `from`, skipping `skip` agents.
fn max_diff(
    a: &[(f64, u32, f64, f64)],
    b: &[(f64, u32, f64, f64)],
    from: f64,
    skip: &[u32],
) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .filter(|(x, _)| x.0 >= from && !skip.contains(&x.1))
        .map(|(x, y)| {
            assert_eq!(x.1, y.1);
            (x.2 - y.2).abs().max((x.3 - y.3).abs())
        })
        .fold(0.0, f64::max)
}

#[test]
fn step_halving_converged_curves() {
    for (name, skip) in [
        ("timevarying", &[5u32][..]),
        ("constant-observer", &[][..]),
        ("constant-observerless", &[][..]),
    ] {
        let h1 = error_curves(&load_paper(name, &[]));
        let h2 = error_curves(&load_paper(name, &["simulation.dt=0.0005"]));
        let late = max_diff(&h1, &h2, 1.0, skip);
        assert!(
            late < 1e-8,
            "{name}: dt 1 ms vs 0.5 ms differ by {late:e} after 1 s"
        );
        if name == "constant-observerless" {
            let all = max_diff(&h1, &h2, 0.0, skip);
            assert!(all < 1e-8, "{name}: dt 1 ms vs 0.5 ms differ by {all:e}");
        }
    }
}

#[test]
fn step_halving_shows_fourth_order_on_the_transient() {
    let run = |dt: &str| {
        error_curves(&load_paper(
            "constant-observer",
            &["simulation.duration=1", &format!("simulation.dt={dt}")],
        ))
    };
    let (a, b, c) = (run("0.001"), run("0.0005"), run("0.00025"));
    let (d1, d2) = (max_diff(&a, &b, 0.0, &[]), max_diff(&b, &c, 0.0, &[]));
    let ratio = d1 / d2;
    assert!(
        (12.0..20.0).contains(&ratio),
        "error ratio per halving {ratio} (d1 {d1:e}, d2 {d2:e})"
    );
}
