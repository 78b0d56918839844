//! `[leader]`: the generator `P` and the leader's initial state.

use super::ctx::{Ctx, rows};
use super::kind_name;
use crate::schema::{LeaderSpec, ReferenceKind, SchemeKind};
use attitude::checks::p_is_admissible;
use nalgebra::{Matrix3, Vector3};

/// The resolved leader; `r0` is `None` if its attitude was invalid.
pub(super) struct Leader {
    /// Generator of `σ̇₀ = P σ₀` (zero when not given).
    pub(super) p: Matrix3<f64>,
    /// `R₀(0)`.
    pub(super) r0: Option<Matrix3<f64>>,
    /// `ω₀(0)`.
    pub(super) w0: Vector3<f64>,
    /// `σ₀(0)`.
    pub(super) s0: Vector3<f64>,
}

/// `[leader]` under scheme `kind`.
pub(super) fn leader(c: &mut Ctx, l: &LeaderSpec, kind: SchemeKind) -> Leader {
    let p = generator(c, l, kind);
    let r0 = c.rotation("leader.attitude", &l.attitude);
    let (w0, s0) = match l.reference {
        ReferenceKind::TimeVarying => {
            let required = |c: &mut Ctx, f: &str, v: &Option<[f64; 3]>| match v {
                Some(w) => c.vec3(f, w),
                None => {
                    c.err(f, "is required by reference = \"time-varying\"");
                    Vector3::zeros()
                }
            };
            let w0 = required(c, "leader.omega", &l.omega);
            let s0 = required(c, "leader.sigma", &l.sigma);
            if kind != SchemeKind::ObserverTimeVarying {
                c.warn(
                    "leader.reference",
                    format!("scheme {} is designed for a constant reference; a time-varying one is not covered by the paper's theorems", kind_name(kind)),
                );
            }
            (w0, s0)
        }
        ReferenceKind::Constant => {
            for (f, v) in [("leader.omega", &l.omega), ("leader.sigma", &l.sigma)] {
                if v.is_some() {
                    c.err(
                        f,
                        "must be absent for reference = \"constant\" (ω₀ = σ₀ = 0)",
                    );
                }
            }
            (Vector3::zeros(), Vector3::zeros())
        }
    };
    Leader { p, r0, w0, s0 }
}

/// `leader.p`, checked against eq. `leader` where it is used.
fn generator(c: &mut Ctx, l: &LeaderSpec, kind: SchemeKind) -> Matrix3<f64> {
    let needed =
        kind == SchemeKind::ObserverTimeVarying || l.reference == ReferenceKind::TimeVarying;
    let Some(p) = l.p else {
        if needed {
            c.err("leader.p", "is required by a time-varying reference and by scheme observer-time-varying (eq. 7c)");
        }
        return Matrix3::zeros();
    };
    let m = rows(&p);
    if m.iter().any(|x| !x.is_finite()) {
        c.err("leader.p", "must hold finite numbers");
    } else if needed && !p_is_admissible(&m) {
        c.err(
            "leader.p",
            format!(
                "violates the paper's condition on P (eq. leader): eigenvalues on the imaginary axis must be simple and non-zero, all others must have negative real part; eigenvalues are {}",
                fmt_complex(&m)
            ),
        );
    }
    m
}

fn fmt_complex(m: &Matrix3<f64>) -> String {
    let ev = m.complex_eigenvalues();
    let parts: Vec<String> = ev
        .iter()
        .map(|z| format!("{:.4}{:+.4}i", z.re, z.im))
        .collect();
    parts.join(", ")
}
