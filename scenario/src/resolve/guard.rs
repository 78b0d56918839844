//! `[guard]`: the envelope of a sane state (`attitude::guard`), every bound
//! finite and > 0.

use super::ctx::Ctx;
use crate::schema::GuardSpec;
use attitude::guard::Envelope;

/// The envelope of `[guard]`, unset fields at their defaults.
pub(super) fn guard(c: &mut Ctx, g: &GuardSpec) -> Envelope {
    let d = Envelope::default();
    let mut bound = |field: &str, v: Option<f64>, default: f64| match v {
        Some(x) => {
            c.positive(field, x);
            x
        }
        None => default,
    };
    Envelope {
        omega: bound("guard.omega", g.omega, d.omega),
        omega_hat: bound("guard.omega_hat", g.omega_hat, d.omega_hat),
        sigma_hat: bound("guard.sigma_hat", g.sigma_hat, d.sigma_hat),
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    fn load(sets: &[&str]) -> Result<crate::Loaded, crate::ScenarioError> {
        let file =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper/timevarying.toml");
        let sets: Vec<String> = sets.iter().map(|s| (*s).to_string()).collect();
        crate::load(&file, &sets)
    }

    #[test]
    fn unset_bounds_take_the_defaults_and_set_ones_are_used() {
        let net = load(&[]).expect("valid").resolved.network;
        assert_eq!(net.guard, attitude::guard::Envelope::default());
        let net = load(&["guard.sigma_hat=5e5"])
            .expect("valid")
            .resolved
            .network;
        assert_eq!((net.guard.sigma_hat, net.guard.omega), (5e5, 1e4));
    }

    #[test]
    fn a_bound_must_be_finite_and_positive() {
        let e =
            (load(&["guard.omega=-1", "guard.omega_hat=nan"]).expect_err("invalid")).to_string();
        assert!(e.contains("guard.omega: must be > 0, got -1"), "{e}");
        assert!(
            e.contains("guard.omega_hat: must be a finite number"),
            "{e}"
        );
        let e = load(&["guard.speed=1"])
            .expect_err("unknown key")
            .to_string();
        assert!(e.contains("guard.speed"), "{e}");
    }
}
