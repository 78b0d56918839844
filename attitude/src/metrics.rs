//! The quantities the paper reports (Section `simulation`).

use crate::network::AgentState;
use crate::reference::LeaderState;
use crate::so3::abs_i;
use nalgebra::Matrix3;

/// Synchronisation errors of one agent against the leader at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Errors {
    /// `|Rᵢ R₀ᵀ|_I ∈ [0, 1]`.
    pub att: f64,
    /// `‖ωᵢ − ω₀‖`, rad/s.
    pub angvel: f64,
    /// `|R̂ᵢ R₀ᵀ|_I` and `‖ω̂ᵢ − ω₀‖` when the agent runs an observer.
    pub observer: Option<(f64, f64)>,
}

/// Errors of agent state `x` against leader state `l`.
///
/// # NOTE
/// `‖ωᵢ − ω₀‖` compares body-frame vectors of two different frames, exactly
/// as the paper's figures do; it vanishes when `Rᵢ = R₀` and `ωᵢ = ω₀`.
#[must_use]
pub fn errors(x: &AgentState, l: &LeaderState, has_observer: bool) -> Errors {
    Errors {
        att: att_err(&(x.r * l.r0.transpose())),
        angvel: (x.w - l.w0).norm(),
        observer: has_observer.then(|| {
            (
                att_err(&(x.r_hat * l.r0.transpose())),
                (x.w_hat - l.w0).norm(),
            )
        }),
    }
}

/// How far the followers are from agreeing along their edges, whatever the
/// leader's attitude: `max |Rᵢ Rⱼᵀ|_I` over `edges` (index pairs into
/// `agents`), 0 without edges, NaN if an attitude is not finite. It
/// vanishes exactly when the two ends of every edge agree, i.e. each
/// connected group of followers is synchronised among itself: what tells
/// agents synchronised apart from the leader from agents not synchronised
/// at all.
#[must_use]
pub fn spread(agents: &[AgentState], edges: &[(usize, usize)]) -> f64 {
    edges.iter().fold(0.0, |m, &(i, j)| {
        let e = att_err(&(agents[i].r * agents[j].r.transpose()));
        if m.is_nan() || e.is_nan() {
            f64::NAN
        } else {
            m.max(e)
        }
    })
}

/// `|R|_I` of a relative attitude, NaN if any entry is not finite: a
/// diverged state has no attitude error (`abs_i` alone would clamp a NaN to 1).
fn att_err(r: &Matrix3<f64>) -> f64 {
    if r.iter().all(|v| v.is_finite()) {
        abs_i(r)
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn the_spread_is_zero_iff_the_agents_agree() {
        let x = |r: Matrix3<f64>| AgentState {
            r,
            w: Vector3::zeros(),
            r_hat: r,
            w_hat: Vector3::zeros(),
            s_hat: Vector3::zeros(),
        };
        let a = crate::so3::rot(0.7, &Vector3::new(1.0, 2.0, 3.0).normalize());
        let b = crate::so3::rot(0.3, &Vector3::z());
        let path = [(0, 1), (1, 2)];
        assert_eq!(spread(&[x(a), x(a), x(a)], &path), 0.0);
        let s = spread(&[x(a), x(a), x(b * a)], &path);
        assert!((s - abs_i(&(b * a * a.transpose()))).abs() < 1e-15, "{s}");
        // Two groups, each agreeing, no edge between them: agreed.
        assert_eq!(spread(&[x(a), x(a), x(b), x(b)], &[(0, 1), (2, 3)]), 0.0);
        let nan = x(Matrix3::from_element(f64::NAN));
        assert!(spread(&[x(a), nan], &[(0, 1)]).is_nan());
        assert_eq!(spread(&[x(a)], &[]), 0.0);
    }

    #[test]
    fn a_nan_state_has_nan_errors_never_one() {
        let l = LeaderState {
            r0: Matrix3::identity(),
            w0: Vector3::zeros(),
            s0: Vector3::zeros(),
        };
        let nan = Matrix3::from_element(f64::NAN);
        let x = AgentState {
            r: nan,
            w: Vector3::repeat(f64::NAN),
            r_hat: nan,
            w_hat: Vector3::zeros(),
            s_hat: Vector3::zeros(),
        };
        let e = errors(&x, &l, true);
        assert!(e.att.is_nan() && e.angvel.is_nan(), "{e:?}");
        assert!(e.observer.is_some_and(|(a, _)| a.is_nan()), "{e:?}");
        let mut inf = x;
        inf.r = Matrix3::identity() * f64::INFINITY;
        assert!(errors(&inf, &l, false).att.is_nan());
        let fine = AgentState {
            r: Matrix3::identity(),
            r_hat: Matrix3::identity(),
            ..x
        };
        assert_eq!(errors(&fine, &l, true).att, 0.0);
    }
}
