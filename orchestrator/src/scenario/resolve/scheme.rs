//! `[scheme]`: which of the paper's schemes, with its scalar gains.

use super::ctx::Ctx;
use super::kind_name;
use crate::scenario::schema::{ObserverGainsSpec, SchemeKind, SchemeSpec};
use attitude::control::ControlGains;
use attitude::network::Scheme;
use attitude::observer::ObserverGains;

/// The scheme, or `None` if its gains are incomplete.
pub(super) fn scheme(c: &mut Ctx, s: &SchemeSpec) -> Option<Scheme> {
    let kind = s.kind;
    let control = ControlGains {
        k_r: c.positive("scheme.control.k_r", s.control.k_r),
        k_w: c.positive("scheme.control.k_omega", s.control.k_omega),
    };
    let observer = match (&s.observer, kind) {
        (None, SchemeKind::Observerless) => None,
        (Some(_), SchemeKind::Observerless) => {
            c.warn(
                "scheme.observer",
                "ignored: the observerless scheme has no observer",
            );
            None
        }
        (None, _) => {
            c.err(
                "scheme.observer",
                format!("is required by scheme {}", kind_name(kind)),
            );
            None
        }
        (Some(o), _) => Some(observer(c, o, kind)),
    };
    match (kind, observer) {
        (SchemeKind::ObserverTimeVarying, Some(observer)) => {
            Some(Scheme::ObserverTimeVarying { observer, control })
        }
        (SchemeKind::ObserverConstant, Some(observer)) => {
            Some(Scheme::ObserverConstant { observer, control })
        }
        (SchemeKind::Observerless, _) => Some(Scheme::Observerless { control }),
        _ => None,
    }
}

/// `scheme.observer` of a scheme with an observer.
fn observer(c: &mut Ctx, o: &ObserverGainsSpec, kind: SchemeKind) -> ObserverGains {
    let k_sigma = match (o.k_sigma, kind) {
        (Some(k), SchemeKind::ObserverTimeVarying) => c.positive("scheme.observer.k_sigma", k),
        (None, SchemeKind::ObserverTimeVarying) => {
            c.err(
                "scheme.observer.k_sigma",
                "is required by scheme observer-time-varying (eq. 7c)",
            );
            0.0
        }
        (Some(_), _) => {
            c.warn(
                "scheme.observer.k_sigma",
                "ignored: observer 16a-16b has no σ̂",
            );
            0.0
        }
        (None, _) => 0.0,
    };
    ObserverGains {
        k_r: c.positive("scheme.observer.k_r", o.k_r),
        k_w: c.positive("scheme.observer.k_omega", o.k_omega),
        k_sigma,
    }
}
