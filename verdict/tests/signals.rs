//! Hand-made signals, one class at a time.

mod common;

use attsync_verdict::{Kind, Thresholds, classify, diverged};
use common::{close, grid, judge, noise, rate};
use std::f64::consts::{FRAC_PI_2, PI};

#[test]
fn exponential_decay_is_converging_then_converged() {
    let f = |t: f64| (-0.1 * t).exp();
    let v = judge(40.0, 1e-3, f);
    assert_eq!(v.kind, Kind::Converging, "{v:#?}");
    assert!(close(rate(&v), -0.1, 0.01), "{v:#?}");
    let reach = 1e3f64.ln() / 0.1; // 69.08 s
    assert!(
        close(v.projected_time.expect("projected"), reach, 0.01),
        "{v:#?}"
    );
    assert_eq!(v.settle_time, None);
    let v = judge(100.0, 1e-3, f);
    assert_eq!(v.kind, Kind::Converged, "{v:#?}");
    assert!(close(rate(&v), -0.1, 0.01), "{v:#?}");
    assert!(
        close(v.settle_time.expect("settled"), reach, 0.001),
        "{v:#?}"
    );
}

#[test]
fn decaying_oscillation_with_an_offset_is_converging_at_its_rate() {
    let v = judge(100.0, 1e-3, |t| {
        (-0.05 * t).exp() * (0.5 + 0.5 * (3.0 * t).cos().abs())
    });
    assert_eq!(v.kind, Kind::Converging, "{v:#?}");
    assert!(close(rate(&v), -0.05, 0.01), "{v:#?}");
}

#[test]
fn rectified_decaying_oscillation_is_converging_at_its_rate() {
    let f = |t: f64| (-0.05 * t).exp() * (0.8 * t).cos().abs();
    let v = judge(100.0, 1e-3, f);
    assert_eq!(v.kind, Kind::Converging, "{v:#?}");
    assert!(close(rate(&v), -0.05, 0.01), "{v:#?}");
    // The projection agrees with where a longer run settles, to a period.
    let projected = v.projected_time.expect("projected");
    let long = judge(300.0, 1e-3, f);
    assert_eq!(long.kind, Kind::Converged, "{long:#?}");
    let settled = long.settle_time.expect("settled");
    assert!(
        (settled - projected).abs() < PI / 0.8,
        "{projected} vs {settled}"
    );
}

#[test]
fn the_largest_of_two_decaying_modes_is_converging_at_their_rate() {
    let v = judge(200.0, 1e-6, |t| {
        let a = (-0.03 * t).exp() * (0.8 * t).cos().abs();
        let b = 0.7 * (-0.03 * t).exp() * (1.3 * t + 0.4).sin().abs();
        a.max(b)
    });
    assert_eq!(v.kind, Kind::Converging, "{v:#?}");
    assert!(close(rate(&v), -0.03, 0.01), "{v:#?}");
}

#[test]
fn decay_to_a_round_off_floor_is_converged() {
    for floor in [1e-16, 1e-12] {
        let v = judge(200.0, 1e-6, |t| {
            let i = (t * 100.0).round() as u64;
            (-0.3 * t).exp() + floor * (1.0 + noise(i))
        });
        assert_eq!(v.kind, Kind::Converged, "floor {floor}: {v:#?}");
        assert!(v.settle_time.is_some());
    }
    // The decay inside the window, the floor after it: still converged.
    let v = judge(140.0, 1e-6, |t| {
        let i = (t * 100.0).round() as u64;
        (-0.4 * t).exp().max(1e-15 * (1.0 + noise(i)))
    });
    assert_eq!(v.kind, Kind::Converged, "{v:#?}");
}

#[test]
fn constant_offset_is_persistent_without_a_period() {
    let v = judge(100.0, 1e-3, |_| 0.05);
    assert_eq!(v.kind, Kind::Persistent, "{v:#?}");
    assert_eq!(v.amplitude, Some(0.05));
    assert_eq!(v.period, None);
    assert!(rate(&v).abs() < 1e-12, "{v:#?}");
    assert_eq!(v.projected_time, None);
}

#[test]
fn an_offset_with_a_dying_transient_is_persistent() {
    let v = judge(100.0, 1e-3, |t| 0.1 + 0.01 * (-0.1 * t).exp());
    assert_eq!(v.kind, Kind::Persistent, "{v:#?}");
    assert_eq!(v.period, None);
}

#[test]
fn sustained_oscillation_is_persistent_with_the_error_signal_period() {
    // The period of |sin 2t| itself: π/2, not the sine's π.
    let v = judge(100.0, 1e-3, |t| 0.2 * (2.0 * t).sin().abs());
    assert_eq!(v.kind, Kind::Persistent, "{v:#?}");
    assert!(close(v.period.expect("period"), FRAC_PI_2, 0.01), "{v:#?}");
    assert!(close(v.amplitude.expect("amplitude"), 0.2, 1e-3), "{v:#?}");
}

#[test]
fn growth_is_diverging_above_and_below_the_tolerance() {
    let v = judge(100.0, 1e-3, |t| 1e-6 * (0.1 * t).exp());
    assert_eq!(v.kind, Kind::Diverging, "{v:#?}");
    assert!(close(rate(&v), 0.1, 0.01), "{v:#?}");
    let v = judge(50.0, 1e-3, |t| 1e-9 * (0.1 * t).exp());
    assert_eq!(v.kind, Kind::Diverging, "{v:#?}");
}

/// Growth inside the window that stays below the error's earlier peak is
/// a transient (a stable network's errors may grow for a while after
/// large initial errors): undecided until it passes that peak.
#[test]
fn growth_below_an_earlier_peak_is_a_transient_not_divergence() {
    // A decay from 1, then a rise that stays below it.
    let v = judge(10.0, 1e-3, |t| {
        if t < 5.0 {
            (-t).exp()
        } else {
            (-5.0_f64).exp() * (0.5 * (t - 5.0)).exp()
        }
    });
    assert_eq!(v.kind, Kind::Undecided, "{v:#?}");
    assert!(v.reason.contains("transient"), "{v:#?}");
    // The same rise past the earlier peak is divergence.
    let v = judge(40.0, 1e-3, |t| {
        if t < 5.0 {
            (-t).exp()
        } else {
            (-5.0_f64).exp() * (0.5 * (t - 5.0)).exp()
        }
    });
    assert_eq!(v.kind, Kind::Diverging, "{v:#?}");
}

#[test]
fn a_non_finite_error_or_the_guard_is_diverging() {
    let t = grid(10.0, 0.01);
    let mut x: Vec<f64> = t.iter().map(|&t| (-t).exp()).collect();
    x[500] = f64::NAN;
    let v = classify(&t, &x, 1e-3, &Thresholds::default());
    assert_eq!(v.kind, Kind::Diverging, "{v:#?}");
    assert_eq!(v.window, [5.0, 5.0]);
    x[500] = f64::INFINITY;
    assert_eq!(
        classify(&t, &x, 1e-3, &Thresholds::default()).kind,
        Kind::Diverging
    );
    let g = diverged(12.5, 1e-3);
    assert_eq!(
        (g.kind, g.window, g.decay_rate),
        (Kind::Diverging, [12.5, 12.5], None)
    );
}

#[test]
fn too_short_is_undecided() {
    let v = judge(0.1, 1e-3, |t| (-t).exp());
    assert_eq!(v.kind, Kind::Undecided, "{v:#?}");
    let v = classify(&[], &[], 1e-3, &Thresholds::default());
    assert_eq!(v.kind, Kind::Undecided, "{v:#?}");
    // 6.4 periods of π/0.4 s in the 50 s window: blocks of 1.5 periods
    // leave 4 blocks, fewer than the 6 needed.
    let v = judge(100.0, 1e-3, |t| 0.2 * (0.4 * t).sin().abs());
    assert_eq!(v.kind, Kind::Undecided, "{v:#?}");
    // Twice as long: 8 blocks, persistent.
    let v = judge(200.0, 1e-3, |t| 0.2 * (0.4 * t).sin().abs());
    assert_eq!(v.kind, Kind::Persistent, "{v:#?}");
}

#[test]
fn slow_decays_are_never_persistent_once_the_window_resolves_them() {
    // Rate −0.01: a 40 s window sees e^−0.4 already; 400 s sees e^−4.
    for horizon in [80.0, 800.0] {
        let v = judge(horizon, 1e-6, |t| 0.5 * (-0.01 * t).exp());
        assert_eq!(v.kind, Kind::Converging, "T = {horizon}: {v:#?}");
        assert!(close(rate(&v), -0.01, 0.01), "{v:#?}");
    }
    // Rate −0.001: over 40 s a change of e^−0.04, below the trend threshold
    // (0.1) but above the flat one (0.01): undecided, run longer; over
    // 400 s, e^−0.4: converging.
    let v = judge(80.0, 1e-6, |t| 0.5 * (-0.001 * t).exp());
    assert_eq!(v.kind, Kind::Undecided, "{v:#?}");
    assert!(close(rate(&v), -0.001, 0.01), "{v:#?}");
    let v = judge(800.0, 1e-6, |t| 0.5 * (-0.001 * t).exp());
    assert_eq!(v.kind, Kind::Converging, "{v:#?}");
    // Rate −1e-5: a change of 4e-4 over 40 s, below the flat threshold:
    // persistent at this horizon (the documented limit), its rate reported.
    let v = judge(80.0, 1e-6, |t| 0.5 * (-1e-5 * t).exp());
    assert_eq!(v.kind, Kind::Persistent, "{v:#?}");
    assert!(close(rate(&v), -1e-5, 0.01), "{v:#?}");
}

#[test]
fn the_verdict_does_not_depend_on_a_long_enough_horizon() {
    let decaying = |t: f64| (-0.02 * t).exp() * (0.8 * t).cos().abs();
    let sustained = |t: f64| 0.1 + 0.05 * (1.3 * t).sin().abs();
    let mut rates = Vec::new();
    for horizon in [100.0, 200.0, 400.0] {
        let v = judge(horizon, 1e-6, decaying);
        assert_eq!(v.kind, Kind::Converging, "T = {horizon}: {v:#?}");
        rates.push(rate(&v));
        let p = judge(horizon, 1e-3, sustained);
        assert_eq!(p.kind, Kind::Persistent, "T = {horizon}: {p:#?}");
        assert!(close(p.period.expect("period"), PI / 1.3, 0.01), "{p:#?}");
    }
    for r in &rates {
        assert!(close(*r, rates[0], 0.01), "{rates:?}");
        assert!(close(*r, -0.02, 0.01), "{rates:?}");
    }
    // A converging run becomes converged as it lengthens, and stays so.
    let kinds: Vec<_> = [50.0, 100.0, 200.0, 400.0]
        .map(|h| judge(h, 1e-3, |t| (-0.1 * t).exp()).kind)
        .to_vec();
    assert_eq!(
        kinds,
        [
            Kind::Converging,
            Kind::Converged,
            Kind::Converged,
            Kind::Converged
        ]
    );
}

#[test]
fn the_envelope_point_of_a_block_is_a_peak_not_a_flank() {
    // A block that starts on the flank just after a peak has a larger
    // first sample than its own peak; taking it would bias the rate by
    // ~0.1 %. Taking the block's highest local peak is exact to sampling.
    let v = judge(100.0, 1e-3, |t| (-0.05 * t).exp() * (0.8 * t).cos().abs());
    assert!(close(rate(&v), -0.05, 2e-4), "{v:#?}");
}

#[test]
fn a_beating_sustained_oscillation_is_persistent_once_blocks_span_its_beats() {
    let f = |t: f64| (0.1 * t.sin() + 0.07 * (2f64.sqrt() * t).sin()).abs();
    let v = judge(400.0, 1e-3, f);
    assert_eq!(v.kind, Kind::Persistent, "{v:#?}");
    assert!(v.period.is_some(), "{v:#?}");
    assert!(close(v.amplitude.expect("amplitude"), 0.17, 0.01), "{v:#?}");
}

#[test]
fn an_oscillation_slower_than_the_window_gets_no_final_verdict() {
    // Period π/0.03 ≈ 105 s: windows of 50…600 s see part of a hump or
    // too few periods; 9 periods (1.5 per block, 6 blocks) fit from T ≈ 1900.
    let f = |t: f64| 0.2 * (0.03 * t).sin().abs() + 0.01;
    for horizon in [100.0, 150.0, 200.0, 300.0, 600.0, 1200.0] {
        let v = judge(horizon, 1e-3, f);
        assert!(!v.kind.is_final(), "T = {horizon}: {v:#?}");
    }
    let v = judge(2000.0, 1e-3, f);
    assert_eq!(v.kind, Kind::Persistent, "{v:#?}");
    assert!(close(v.period.expect("period"), PI / 0.03, 0.01), "{v:#?}");
}

#[test]
fn a_changing_rate_is_undecided_until_one_exponential_remains() {
    // A fast mode dies out inside the window [30, 60] s: the rates of its
    // halves differ. Later only the slow mode is left.
    let f = |t: f64| (-0.3 * t).exp() + 1e-3 * (-0.03 * t).exp();
    let v = judge(60.0, 1e-9, f);
    assert_eq!(v.kind, Kind::Undecided, "{v:#?}");
    let v = judge(200.0, 1e-9, f);
    assert_eq!(v.kind, Kind::Converging, "{v:#?}");
    assert!(close(rate(&v), -0.03, 0.01), "{v:#?}");
}
