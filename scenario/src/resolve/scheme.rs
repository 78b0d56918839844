//! `[scheme]`: which of the paper's schemes, with its scalar gains and the
//! signs of its law (`scheme.law`).

use super::ctx::Ctx;
use super::kind_name;
use crate::schema::{ObserverGainsSpec, SchemeKind, SchemeSpec};
use attitude::control::{ControlGains, ControlLaw};
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

/// The field that selects the law.
pub(super) const LAW_FIELD: &str = "scheme.law";

/// What `attsync run`, `sweep` and `check` say of `law = "as-printed"`.
pub(super) const AS_PRINTED_WARNING: &str = "\"as-printed\" runs the paper's printed Σᵢ, Γᵢ \
(eqs. sigmai, gammai), which are known wrong (erratum 1, docs/paper.md): scheme 1 stalls \
near 1e-2 instead of converging (in scheme 2 the error fades with the observer's ω̂); \
it is meant only as a negative control";

/// `scheme.law`: the printed signs (erratum 1) only where the paper prints
/// `Σᵢ`, `Γᵢ` (schemes 1 and 2, whose `controlconstantestimate` takes `Γᵢ`
/// from eq. `gammai`), with a warning; scheme 3's `districontrol` has
/// neither, so `as-printed` is refused there.
pub(super) fn law(c: &mut Ctx, s: &SchemeSpec) -> ControlLaw {
    match (s.law, s.kind) {
        (ControlLaw::Corrected, _) => {}
        (ControlLaw::AsPrinted, SchemeKind::Observerless) => c.err(
            LAW_FIELD,
            "\"as-printed\" is for the observer schemes only: the observerless law \
             (districontrol) has no Σᵢ, Γᵢ, so the paper prints no other law to run",
        ),
        (ControlLaw::AsPrinted, _) => c.warn(LAW_FIELD, AS_PRINTED_WARNING),
    }
    s.law
}
