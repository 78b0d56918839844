//! Issue 11 items 2–3: a step size the theory allows.
//!
//! RK4 is stable for a linear mode λ only while `dt·λ` stays in its region
//! `|1 + z + z²/2 + z³/6 + z⁴/24| ≤ 1`. Validation estimates the fastest
//! mode of each loop (the linearisation at the synchronised equilibrium,
//! `docs/stiffness.md`) and refuses a `simulation.dt` clearly beyond the
//! largest stable step. These tests make the paper's scenarios stiff
//! (one gain raised) and check both the refusal and the physics: just below
//! the estimated bound the in-process run stays finite, well above it
//! diverges.

mod common;

use attsync::scenario::StiffnessCheck;
use attsync::scenario::{Loaded, ScenarioError, load, load_with};
use common::{attsync, paper, run_args, stays_finite};
use std::path::Path;

fn sets(s: &[&str]) -> Vec<String> {
    s.iter().map(|x| x.to_string()).collect()
}

/// The paper's scheme-1 scenario with `k_σ = 2000`: its `σ̂` mode is
/// `k_σ λmax(Ξ + LLᵀ) ≈ 8.5e3 s⁻¹`, so `dt = 1 ms` is far beyond RK4's region.
const STIFF_SIGMA: &str = "scheme.observer.k_sigma=2000";

/// The estimated largest stable step of `file` with `set` (not refused).
fn dt_max(file: &str, set: &[&str]) -> f64 {
    let l = load_with(Path::new(&paper(file)), &sets(set), StiffnessCheck::Warn).expect("valid");
    l.resolved.stiffness.expect("agents").dt_max
}

/// `file` with `set` and `dt` (duration `steps`·dt).
fn load_dt(
    file: &str,
    set: &[&str],
    dt: f64,
    steps: u32,
    check: StiffnessCheck,
) -> Result<Loaded, ScenarioError> {
    let mut s = sets(set);
    s.push(format!("simulation.dt={dt:e}"));
    s.push(format!("simulation.duration={:e}", dt * f64::from(steps)));
    s.push(format!("output.sample_period={:e}", dt * 10.0));
    load_with(Path::new(&paper(file)), &s, check)
}

/// As [`load_dt`], not refused.
fn with_dt(file: &str, set: &[&str], dt: f64, steps: u32) -> Loaded {
    load_dt(file, set, dt, steps, StiffnessCheck::Warn).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_stiff_scenario_is_refused_naming_dt_the_bound_and_a_step_that_works() {
    let e = load(Path::new(&paper("timevarying")), &sets(&[STIFF_SIGMA])).unwrap_err();
    let ScenarioError::Invalid { issues, .. } = &e else {
        panic!("{e}")
    };
    assert_eq!(issues.len(), 1, "{e}");
    let i = &issues[0];
    assert_eq!(i.field, "simulation.dt");
    assert!(
        i.reason.contains(
            "dt = 0.001 s exceeds the largest stable step ≈ 3.3e-4 s of the observer loop"
        ),
        "{i}"
    );
    assert!(i.reason.contains("fastest mode 8.5e3 s⁻¹"), "{i}");
    let fix = i.reason.split("--set ").nth(1).expect("a fix").to_string();
    assert_eq!(fix, "simulation.dt=0.00025");
    let ok = load(
        Path::new(&paper("timevarying")),
        &sets(&[STIFF_SIGMA, &fix]),
    )
    .expect("the fix works");
    assert!(
        ok.resolved
            .warnings
            .iter()
            .all(|w| w.field != "simulation.dt")
    );
}

#[test]
fn no_stiffness_check_turns_the_refusal_into_a_warning() {
    let l = load_with(
        Path::new(&paper("timevarying")),
        &sets(&[STIFF_SIGMA]),
        StiffnessCheck::Warn,
    )
    .expect("not refused");
    let w: Vec<_> = l
        .resolved
        .warnings
        .iter()
        .filter(|w| w.field == "simulation.dt")
        .collect();
    assert_eq!(w.len(), 1, "{:?}", l.resolved.warnings);
    assert!(w[0].reason.contains("not refused: --no-stiffness-check"));
}

#[test]
fn a_step_close_to_the_bound_is_warned_about_not_refused() {
    let bound = dt_max("timevarying", &[STIFF_SIGMA]);
    let check = StiffnessCheck::Refuse;
    for f in [0.9, 1.9] {
        let l = load_dt("timevarying", &[STIFF_SIGMA], f * bound, 100, check)
            .unwrap_or_else(|e| panic!("{f}·dt_max refused: {e}"));
        let w = l
            .resolved
            .warnings
            .iter()
            .find(|w| w.field == "simulation.dt")
            .expect("a warning");
        assert!(w.reason.contains("close to RK4's stability limit"), "{w}");
    }
    assert!(load_dt("timevarying", &[STIFF_SIGMA], 2.1 * bound, 100, check).is_err());
    let l = load_dt("timevarying", &[STIFF_SIGMA], 0.7 * bound, 100, check).expect("valid");
    assert!(
        l.resolved
            .warnings
            .iter()
            .all(|w| w.field != "simulation.dt")
    );
}

#[test]
fn the_paper_scenarios_have_a_wide_margin() {
    for f in ["timevarying", "constant-observer", "constant-observerless"] {
        let l = load(Path::new(&paper(f)), &[]).expect("valid");
        let est = l.resolved.stiffness.expect("agents");
        assert!(est.dt_max > 10.0 * l.resolved.network.dt, "{f}: {est:?}");
        assert!(
            l.resolved
                .warnings
                .iter()
                .all(|w| w.field != "simulation.dt")
        );
    }
}

/// Just below the estimated bound a run stays finite, well above (2.5×) it
/// diverges, for a stiff loop of each kind: the `σ̂` observer mode (exact
/// estimate), the tracking loop's rate damping `k_ω̄/J`, the constant
/// observer's `k_ω` and the observerless law's `k_Ř` (the estimate bounds
/// gains and inertias separately: conservative, ~1.55× in calibration).
#[test]
fn just_below_the_bound_stays_finite_well_above_diverges() {
    let cases: [(&str, &str, f64); 4] = [
        ("timevarying", STIFF_SIGMA, 0.95),
        ("timevarying", "scheme.control.k_omega=2000", 0.95),
        ("constant-observer", "scheme.observer.k_omega=3000", 0.95),
        ("constant-observerless", "scheme.control.k_r=3000", 0.95),
    ];
    for (file, set, below) in cases {
        let bound = dt_max(file, &[set]);
        let l = with_dt(file, &[set], below * bound, 4000);
        assert!(
            stays_finite(&l.resolved.network),
            "{file} {set}: diverged at {below}·dt_max"
        );
        let l = with_dt(file, &[set], 2.5 * bound, 1500);
        assert!(
            !stays_finite(&l.resolved.network),
            "{file} {set}: finite at 2.5·dt_max"
        );
    }
}

/// The CLI: `check` refuses the stiff scenario (exit 2) naming the field,
/// the bound and a step that works; `--no-stiffness-check` lets `check` and
/// `run` through with a warning (the run then goes on, whatever it does).
#[test]
fn cli_refuses_a_stiff_scenario_unless_told_not_to() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = paper("timevarying");
    let check = ["check", &file, "--set", STIFF_SIGMA];
    let out = attsync(dir.path(), &check);
    let err = &out.stderr;
    assert_eq!(out.code, Some(2), "{err}");
    assert!(
        err.contains("simulation.dt: dt = 0.001 s exceeds the largest stable step"),
        "{err}"
    );
    assert!(err.contains("try --set simulation.dt=0.00025"), "{err}");
    let out = attsync(
        dir.path(),
        &[&check[..], &["--no-stiffness-check"]].concat(),
    );
    let text = &out.stdout;
    assert_eq!(out.code, Some(0), "{text}");
    assert!(
        text.contains("largest stable dt 3.268e-4 s for dt = 0.001 s: margin dt_max/dt = 0.327"),
        "{text}"
    );
    assert!(
        text.contains("(not refused: --no-stiffness-check)"),
        "{text}"
    );
    let sets = [STIFF_SIGMA, "simulation.duration=0.02"];
    let mut run = run_args(&file, "in-process", dir.path().join("r"), &sets);
    run.push("--no-stiffness-check".into());
    let out = attsync(dir.path(), &run);
    let err = &out.stderr;
    assert_ne!(out.code, Some(2), "{err}");
    assert!(
        err.contains("warning:") && err.contains("simulation.dt"),
        "{err}"
    );
    assert!(dir.path().join("r/errors.csv").exists(), "{err}");
}
