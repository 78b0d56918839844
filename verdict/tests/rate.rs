//! The fitted rate of a pure exponential, over random amplitudes and rates.

mod common;

use attsync_verdict::{Thresholds, classify};
use common::{close, grid};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn the_rate_of_an_exponential_is_recovered_to_one_percent(
        a in 1e-3f64..=1.0,
        lambda in -1.0f64..=-0.01,
        longer in 1.0f64..=2.0,
    ) {
        let t = grid(5.0 / -lambda * longer, 0.01);
        let x: Vec<f64> = t.iter().map(|&t| a * (lambda * t).exp()).collect();
        let v = classify(&t, &x, 1e-12, &Thresholds::default());
        let r = v.decay_rate.expect("a rate");
        prop_assert!(close(r, lambda, 0.01), "{r} vs {lambda}: {v:#?}");
    }
}
