//! A body's box: the uniform box whose inertia is the agent's `Jᵢ`.

use nalgebra::Matrix3;

/// Half-side vectors (body frame, m up to a common scale) of the uniform box
/// with inertia `j`: its principal axes (the eigenvectors of `J`), each
/// scaled by the box's half-side along it.
///
/// # Equation
/// ```text
/// a box of half-sides a₁, a₂, a₃ and mass m:  Jₖ = m/3 (aₗ² + aₘ²)  ({k, l, m} = {1, 2, 3})
///   ⇒  aₖ² = 3/(2m) (Jₗ + Jₘ − Jₖ)
/// ```
/// The mass is free (a common scale); a half-side squared below 1 % of the
/// largest (an inertia no solid box has, e.g. a thin rod's) is raised to it,
/// so every box is visible.
#[must_use]
pub fn box_axes(j: &Matrix3<f64>) -> [[f64; 3]; 3] {
    let eig = j.symmetric_eigen();
    let l = eig.eigenvalues;
    let sq = [
        (l[1] + l[2] - l[0]) / 2.0,
        (l[0] + l[2] - l[1]) / 2.0,
        (l[0] + l[1] - l[2]) / 2.0,
    ];
    let top = sq.iter().copied().fold(f64::MIN_POSITIVE, f64::max);
    let mut out = [[0.0; 3]; 3];
    for (k, axis) in out.iter_mut().enumerate() {
        let half = sq[k].max(top * 0.01).sqrt();
        let v = eig.eigenvectors.column(k) * half;
        *axis = [v[0], v[1], v[2]];
    }
    out
}

/// The longest half-side of a box from [`box_axes`].
#[must_use]
pub fn largest_half_side(axes: &[[f64; 3]; 3]) -> f64 {
    axes.iter()
        .map(|a| a.iter().map(|x| x * x).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lengths(j: Matrix3<f64>) -> Vec<f64> {
        let mut l: Vec<f64> = box_axes(&j)
            .iter()
            .map(|a| a.iter().map(|x| x * x).sum::<f64>().sqrt())
            .collect();
        l.sort_by(f64::total_cmp);
        l
    }

    #[test]
    fn a_box_has_the_inertia_it_was_made_from() {
        // Half-sides 1, 2, 3 (m = 3): J = diag(4+9, 1+9, 1+4).
        let l = lengths(Matrix3::from_diagonal(&[13.0, 10.0, 5.0].into()));
        for (a, b) in l.iter().zip([1.0, 2.0, 3.0]) {
            assert!((a - b).abs() < 1e-12, "{l:?}");
        }
        // The paper's J₁ = diag(1, 3, 2)/10 is a flat plate (J_y = J_x + J_z):
        // half-sides ∝ √2, 0 (shown as a tenth of the largest), 1.
        let l = lengths(Matrix3::from_diagonal(&[0.1, 0.3, 0.2].into()));
        assert!((l[2] / l[1] - 2.0_f64.sqrt()).abs() < 1e-12, "{l:?}");
        assert!((l[0] / l[2] - 0.1).abs() < 1e-12, "{l:?}");
        assert_eq!(
            largest_half_side(&box_axes(&Matrix3::identity())),
            0.5_f64.sqrt()
        );
    }

    #[test]
    fn a_rod_still_gets_a_visible_box() {
        let l = lengths(Matrix3::from_diagonal(&[1.0, 1.0, 1e-9].into()));
        assert!(l[0] > 0.09 * l[2], "{l:?}");
    }
}
