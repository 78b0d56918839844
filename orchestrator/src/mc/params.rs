//! One trial's draws of the `[[monte_carlo.param]]` fields: from the
//! trial's second ChaCha stream (stream 1 of its seed), so the initial
//! conditions' draws (stream 0, [`super::draws`]) are the same with or
//! without them; the fields in file order, one draw each (a bounded
//! normal redraws until it falls within its bounds).
//!
//! The value a trial used is read back from its effective scenario
//! ([`used`]): `trials.csv` holds what ran, not what was meant to.

use super::dispersion::{Dispersed, Law};
use crate::scenario::{Loaded, overrides};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// The stream of a trial's parameter draws (its initial conditions: 0).
const PARAM_STREAM: u64 = 1;

/// The draws of `params` for the trial of seed `seed`, in file order.
#[must_use]
pub fn draw(params: &[Dispersed], seed: u64) -> Vec<f64> {
    if params.is_empty() {
        return Vec::new();
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(PARAM_STREAM);
    params.iter().map(|p| sample(&p.law, &mut rng)).collect()
}

/// One draw of `law`.
pub fn sample(law: &Law, rng: &mut impl Rng) -> f64 {
    match *law {
        Law::Uniform { min, max } => min + (max - min) * rng.random::<f64>(),
        Law::LogUniform { min, max } => {
            let (a, b) = (min.ln(), max.ln());
            (a + (b - a) * rng.random::<f64>()).exp().clamp(min, max)
        }
        Law::Normal {
            mean,
            std,
            min,
            max,
        } => {
            let (lo, hi) = (
                min.unwrap_or(f64::NEG_INFINITY),
                max.unwrap_or(f64::INFINITY),
            );
            loop {
                let z: f64 = rng.sample(StandardNormal);
                let x = mean + std * z;
                if lo <= x && x <= hi {
                    break x;
                }
            }
        }
    }
}

/// `values` rounded to each field's step: its `step`, else `dt` for a
/// timing field ([`crate::sweep::default_quantum`]), else as drawn.
#[must_use]
pub fn quantised(params: &[Dispersed], values: &[f64], dt: f64) -> Vec<f64> {
    (params.iter().zip(values))
        .map(|(p, &v)| {
            match p
                .step
                .or_else(|| crate::sweep::default_quantum(&p.field, dt))
            {
                Some(q) => crate::sweep::quantise(v, q),
                None => v,
            }
        })
        .collect()
}

/// The `--set` overrides that put `values` into `params`' fields
/// (numbers in Rust's shortest round-trip form: exact).
#[must_use]
pub fn overrides(params: &[Dispersed], values: &[f64]) -> Vec<String> {
    (params.iter().zip(values))
        .map(|(p, v)| format!("{}={}", p.field, number(*v)))
        .collect()
}

/// `v` as a TOML float (`1` is written `1.0`, so a float field takes it).
fn number(v: f64) -> String {
    let s = format!("{v}");
    if s.contains(['.', 'e', 'E', 'N', 'i']) {
        s
    } else {
        format!("{s}.0")
    }
}

/// The value each of `params`' fields has in `loaded`'s effective
/// scenario (NaN where it is not a number).
#[must_use]
pub fn used(loaded: &Loaded, params: &[Dispersed]) -> Vec<f64> {
    if params.is_empty() {
        return Vec::new();
    }
    let doc = toml::Table::try_from(&loaded.document).unwrap_or_default();
    (params.iter())
        .map(|p| match overrides::get(&doc, &p.field) {
            Some(toml::Value::Float(x)) => *x,
            Some(toml::Value::Integer(i)) => *i as f64,
            _ => f64::NAN,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law(distribution: &str, extra: &str) -> Law {
        let text = format!(
            "[[monte_carlo.param]]\nfield = \"x\"\ndistribution = \"{distribution}\"\n{extra}"
        );
        #[derive(serde::Deserialize)]
        struct Doc {
            monte_carlo: crate::scenario::monte_carlo::MonteCarloSpec,
        }
        let doc: Doc = toml::from_str(&text).expect("toml");
        let specs = doc.monte_carlo.param.expect("a param");
        let mut issues = Vec::new();
        let d = crate::scenario::monte_carlo::param::check(&specs, &mut issues);
        assert!(issues.is_empty(), "{issues:?}");
        d[0].law
    }

    /// Mean and standard deviation of `n` draws.
    fn moments(law: &Law, n: usize) -> (f64, f64, f64, f64) {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let xs: Vec<f64> = (0..n).map(|_| sample(law, &mut rng)).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (mean, var.sqrt(), lo, hi)
    }

    #[test]
    fn each_law_has_its_moments_and_stays_in_its_bounds() {
        let n = 200_000;
        // Uniform on [1, 3]: mean 2, std 2/√12.
        let (m, s, lo, hi) = moments(&law("uniform", "min = 1.0\nmax = 3.0"), n);
        assert!((m - 2.0).abs() < 0.01 && (s - 2.0 / 12f64.sqrt()).abs() < 0.01);
        assert!(lo >= 1.0 && hi <= 3.0);
        // Log-uniform on [1, e²]: ln x uniform on [0, 2], E[x] = (e² − 1)/2.
        let e2 = 2f64.exp();
        let (m, _, lo, hi) = moments(&law("log-uniform", &format!("min = 1.0\nmax = {e2}")), n);
        assert!((m - (e2 - 1.0) / 2.0).abs() < 0.02, "{m}");
        assert!(lo >= 1.0 && hi <= e2);
        // Normal(5, 2).
        let (m, s, _, _) = moments(&law("normal", "mean = 5.0\nstd = 2.0"), n);
        assert!((m - 5.0).abs() < 0.02 && (s - 2.0).abs() < 0.02, "{m} {s}");
        // Normal(0, 1) on [0, ∞): the half-normal, mean √(2/π).
        let (m, _, lo, _) = moments(&law("normal", "mean = 0.0\nstd = 1.0\nmin = 0.0"), n);
        assert!(
            (m - (2.0 / std::f64::consts::PI).sqrt()).abs() < 0.01,
            "{m}"
        );
        assert!(lo >= 0.0);
    }

    #[test]
    fn the_parameter_stream_is_apart_from_the_initial_conditions() {
        let params = [Dispersed {
            field: "x".into(),
            law: Law::Uniform { min: 0.0, max: 1.0 },
            step: None,
        }];
        let a = draw(&params, 42);
        assert_eq!(a, draw(&params, 42));
        let first_ic: f64 = super::super::trial_rng(42).random();
        assert_ne!(a[0], first_ic);
        assert_eq!(overrides(&params, &[1.0]), ["x=1.0"]);
        assert_eq!(overrides(&params, &[0.25]), ["x=0.25"]);
    }
}
