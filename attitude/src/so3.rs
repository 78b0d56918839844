//! Maps on SO(3) and so(3) used throughout the paper (Section `sec2`).

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Hat map ℝ³ → so(3), so that `hat(a) * b == a.cross(&b)`.
///
/// # Equation
/// ```text
/// a^× = [0 -a3 a2; a3 0 -a1; -a2 a1 0]
/// ```
/// Source: paper Section `sec2` (the `(·)^×` operator).
///
/// ```
/// # use attitude::so3::hat;
/// # use nalgebra::Vector3;
/// let (a, b) = (Vector3::new(1.0, 2.0, 3.0), Vector3::new(-2.0, 0.5, 4.0));
/// assert_eq!(hat(&a) * b, a.cross(&b));
/// ```
#[must_use]
pub fn hat(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Vex map so(3) → ℝ³, the inverse of [`hat`] on skew-symmetric matrices.
///
/// Reads the lower-triangular entries `[m32, m13, m21]`; use [`psi`] for a
/// matrix that is not exactly skew-symmetric.
#[must_use]
pub fn vex(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
}

/// Anti-symmetric part `Pa(A) = (A − Aᵀ)/2` (paper Section `sec2`).
#[must_use]
pub fn pa(a: &Matrix3<f64>) -> Matrix3<f64> {
    (a - a.transpose()) * 0.5
}

/// `ψ(A) = vex(Pa(A))` (paper Section `sec2`).
///
/// # Equation
/// ```text
/// ψ(A) = ½ [a32 − a23, a13 − a31, a21 − a12]
/// ```
/// Identities used by the paper's proofs (Appendix `appenD`), for symmetric A and R ∈ SO(3):
/// `ψ(AR) = Rᵀψ(RA)` and `ψ(AR) = −ψ(RᵀA)`.
#[must_use]
pub fn psi(a: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        0.5 * (a[(2, 1)] - a[(1, 2)]),
        0.5 * (a[(0, 2)] - a[(2, 0)]),
        0.5 * (a[(1, 0)] - a[(0, 1)]),
    )
}

/// Exponential map so(3) → SO(3): `exp(hat(u))` by Rodrigues' formula.
///
/// # Equation
/// ```text
/// exp(u^×) = I + sin θ/θ · u^× + (1 − cos θ)/θ² · (u^×)²,   θ = ‖u‖
/// ```
/// Uses Taylor series for θ < 1e-4 so the result stays orthogonal to
/// machine precision for tiny increments (the integrator's common case).
#[must_use]
#[inline(always)]
pub fn exp(u: &Vector3<f64>) -> Matrix3<f64> {
    let t2 = u.norm_squared();
    let (a, b) = if t2 < 1e-8 {
        // sin θ/θ = 1 − θ²/6 + θ⁴/120, (1 − cos θ)/θ² = ½ − θ²/24 + θ⁴/720
        (
            1.0 - t2 / 6.0 * (1.0 - t2 / 20.0),
            0.5 - t2 / 24.0 * (1.0 - t2 / 30.0),
        )
    } else {
        let t = t2.sqrt();
        (t.sin() / t, (1.0 - t.cos()) / t2)
    };
    let k = hat(u);
    Matrix3::identity() + k * a + k * k * b
}

/// Logarithm SO(3) → ℝ³ (rotation vector θu with θ ∈ [0, π]).
///
/// Goes through a unit quaternion (Shepperd's method in nalgebra), which is
/// accurate both near the identity and near θ = π.
#[must_use]
pub fn log(r: &Matrix3<f64>) -> Vector3<f64> {
    quaternion(r).scaled_axis()
}

/// `Rot(θ, u) = exp(θ u^×)` for a unit axis `u` (paper Section `sec2`).
#[must_use]
pub fn rot(theta: f64, u: &Vector3<f64>) -> Matrix3<f64> {
    exp(&(u * theta))
}

/// Unit quaternion of a rotation matrix (robust near θ = π).
#[must_use]
pub fn quaternion(r: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r))
}

/// Normalised attitude error `|R|_I = ½ √tr(I − R) = |sin(θ/2)| ∈ [0, 1]`
/// (paper Section `sec2`).
///
/// # NOTE
/// The printed formula loses every digit below ~1e-8 to cancellation in
/// `tr(I − R)`. Here it is the norm of the quaternion's vector part, whose
/// entries come from differences of off-diagonal terms, so an error of
/// 1e-12 is still resolved to full relative precision.
///
/// ```
/// # use attitude::so3::{abs_i, rot};
/// # use nalgebra::Vector3;
/// let r = rot(2e-12, &Vector3::z());
/// assert!((abs_i(&r) - 1e-12).abs() < 1e-24);
/// ```
#[must_use]
pub fn abs_i(r: &Matrix3<f64>) -> f64 {
    quaternion(r).imag().norm().min(1.0)
}

/// Inverse of the left-trivialised differential of `exp`, applied so that
/// `R(t) = R₀ exp(u(t))` follows `Ṙ = R ω^×` when `u̇ = dexp_inv(u, ω)`.
///
/// # Equation
/// ```text
/// u̇ = ω + ½ u × ω + (1/θ²)(1 − (θ/2) cot(θ/2)) u × (u × ω),   θ = ‖u‖
/// ```
/// This is `dexp⁻¹_{−u}(ω)` in Munthe-Kaas' notation, the form RKMK needs
/// for left-invariant fields. Series for small θ (θ² < 1e-6): the
/// coefficient is `1/12 + θ²/720 + θ⁴/30240`. `PROTOCOL.md` § 10.2 gives
/// the order of every operation.
#[must_use]
#[inline(always)]
pub fn dexp_inv(u: &Vector3<f64>, w: &Vector3<f64>) -> Vector3<f64> {
    let t2 = u.norm_squared();
    let c = if t2 < 1e-6 {
        1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    } else {
        let t = t2.sqrt();
        let half = 0.5 * t;
        (1.0 - half * half.cos() / half.sin()) / t2
    };
    let uw = u.cross(w);
    w + uw * 0.5 + u.cross(&uw) * c
}

/// Distance of `r` from SO(3): `‖RᵀR − I‖_F` (zero for a rotation).
#[must_use]
pub fn orthogonality_defect(r: &Matrix3<f64>) -> f64 {
    (r.transpose() * r - Matrix3::identity()).norm()
}
