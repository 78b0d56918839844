//! The verdict on a node's own published stage states
//! ([`Exchanged::trust`]): judged in full at a step's first stage, and for
//! the step's other stages proven when it can be — the same verdict, for
//! a fraction of the work.
//!
//! # NOTE: why the verdict of stages 1–3 may be proven
//! Within a step the attitude published at stage s ≥ 1 is
//! `fl(Q · E)`, `E = fl(exp(u))` (the RKMK4 stage point, [`Rkmk4`],
//! `PROTOCOL.md` § 10.3),
//! where `Q` is the attitude published (and judged in full) at stage 0 of
//! the same step. If `Q` is finite with `d = ‖QᵀQ − I‖_F ≤` [`MARGIN`]
//! `= 1e-8` and `det Q > 0`, and `‖u‖² ≤` [`MAX_INCREMENT2`] `= 1`, then:
//! - `E`'s entries are finite and bounded by 2 (Rodrigues with
//!   `θ ≤ 1`: `sin θ/θ`, `(1 − cos θ)/θ²` finite), so are `fl(Q E)`'s (≤ 7);
//! - `E` is orthogonal to `‖EᵀE − I‖ ≲ 1e-14` (each of its entries is a
//!   few roundings of numbers ≤ 1 away from an exact rotation), the
//!   product adds `‖fl(QE) − QE‖_F ≤ 3·3·2⁻⁵³·‖Q‖‖E‖ ≲ 1e-15`, and
//!   `(QE)ᵀ(QE) − I = Eᵀ(QᵀQ − I)E + (EᵀE − I)`, so the defect of
//!   `fl(Q E)`, evaluated in floating point, is below `d + 1e-13 ≤ 1.01e-8`,
//!   a hundred times below [`ROTATION_TOLERANCE`] `= 1e-6`;
//! - `det Q ≥ (1 − d)^{3/2} > 0.99` (its singular values are within
//!   `√(1 ± d)` of 1 and its sign is known), `det E = 1 ± 1e-13`, and the
//!   roundings move the determinant by less than `1e-13`: `det fl(Q E) > 0`.
//!
//! So the attitude's part of [`Exchanged::trust`] holds, and the verdict is
//! that of the vectors alone (finite or not), evaluated as `trust` does.
//!
//! An observerless agent with sensors publishes what it measures,
//! `fl(P · S)` at every stage, `P` the stage point above and
//! `S = fl(exp(η))` its sensors' rotation for the step (`PROTOCOL.md`
//! § 10.13). With `‖η‖² ≤` [`MAX_INCREMENT2`], `S` is a rotation to
//! `1e-14` with entries bounded by 2, exactly as `E` is, so the same
//! argument carries once more: `d(fl(P S)) ≤ d(P) + 1e-13`. Judged at
//! stage 0 is `fl(Q S)`, whose defect `d'` bounds `Q`'s:
//! `Q = (QS)Sᵀ` up to roundings, `d(Q) ≤ d' + 1e-13`; so with `d' ≤`
//! [`MARGIN`] every stage's published defect stays below `1.1e-8`, and
//! the determinants stay positive as above. When the guard has checked the
//! step's start state instead, its defect is `Q`'s own, and `fl(Q S)`'s
//! verdict is proven from it in the same way (`d(Q) ≤ MARGIN`).
//! Outside these conditions (a diverging node, a huge increment) the check
//! runs in full. The engine's verdicts are therefore exactly
//! `trust().is_ok()`, bit-identical runs included (tested in `agent.rs`).
//!
//! [`Rkmk4`]: crate::integrate::Rkmk4

use crate::network::{Exchanged, ROTATION_TOLERANCE};
use nalgebra::Vector3;
use std::num::NonZeroU64;

/// Largest orthogonality defect `‖QᵀQ − I‖_F` of a step's start attitude
/// for which the verdicts of the step's other stages are proven.
pub const MARGIN: f64 = 1e-8;

/// Largest `‖u‖²` of a stage increment for which the stage attitude's
/// verdict is proven (`θ ≤ 1` rad within one stage; typical `θ` is
/// `‖ω‖·dt/2 ≈ 1e-3`).
pub const MAX_INCREMENT2: f64 = 1.0;

/// What a node remembers between its stages to prove their verdicts: the
/// step whose start attitude is a rotation to [`MARGIN`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Verdicts {
    proven_for: Option<Step>,
    /// A step whose start state passed the guard ([`Verdicts::checked`]),
    /// and the defect of its published attitude (meaningful with the step).
    checked: (Option<Step>, f64),
}

/// A step index `n` kept as `n + 1`, so that `Option<Step>` takes 8 bytes
/// (the verdicts sit in every agent, whose size is its working set:
/// `attitude/tests/layout.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Step(NonZeroU64);

impl Step {
    fn of(n: u64) -> Option<Self> {
        NonZeroU64::new(n.wrapping_add(1)).map(Self)
    }
}

impl Verdicts {
    /// Books that the state at the start of step `n` is inside the guard's
    /// envelope ([`crate::guard::check_agent_defects`]) and that `defect` is
    /// its published attitude's: the stage-0 value of step n (that state's
    /// attitude and vectors) is then trusted without a second check — the
    /// guard's checks imply [`Exchanged::trust`]'s (finite entries, the same
    /// defect and determinant, finite norms hence finite vectors).
    pub fn checked(&mut self, n: u64, defect: f64) {
        self.checked = (Step::of(n), defect);
    }

    /// The verdict on `x`, published at stage `s` of step `n`, whose
    /// attitude is the step's start attitude times `exp(u)` (at stage 0:
    /// the start attitude itself), turned by the sensors' rotation of
    /// `‖η‖² = turned` when it is measured. Always equal to
    /// `x.trust().is_ok()`.
    pub fn judge(
        &mut self,
        x: &Exchanged,
        (n, s): (u64, usize),
        u: &Vector3<f64>,
        turned: Option<f64>,
    ) -> bool {
        let small = turned.is_none_or(|eta2| eta2 <= MAX_INCREMENT2);
        if s == 0 {
            let checked = std::mem::take(&mut self.checked);
            let defect = match checked {
                (Some(m), d) if Some(m) == Step::of(n) && turned.is_none() => Some(d),
                (Some(m), d) if Some(m) == Step::of(n) && small && d <= MARGIN => {
                    Self::vectors_finite(x).then_some(d)
                }
                _ => x.trusted_defect().ok(),
            };
            self.proven_for = defect
                .is_some_and(|d| d <= MARGIN && small)
                .then(|| Step::of(n))
                .flatten();
            return defect.is_some();
        }
        if self.proven_for.is_some()
            && self.proven_for == Step::of(n)
            && u.norm_squared() <= MAX_INCREMENT2
            && small
        {
            return Self::vectors_finite(x);
        }
        x.trust().is_ok()
    }

    /// The vectors' part of [`Exchanged::trust`].
    fn vectors_finite(x: &Exchanged) -> bool {
        Exchanged::finite(x.w.as_slice()) && Exchanged::finite(x.s.as_slice())
    }
}

const _: () = assert!(MARGIN * 100.0 <= ROTATION_TOLERANCE);
