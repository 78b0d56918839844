//! `[guard]`: the envelope of a sane state (`attitude::guard`), every bound
//! finite and > 0.

use super::ctx::Ctx;
use crate::scenario::schema::GuardSpec;
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
