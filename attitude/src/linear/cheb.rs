//! Chebyshev extremal nodes on `[−1, 1]`, their differentiation matrix and
//! the barycentric Lagrange basis: what the pseudospectral discretisation
//! ([`super::roots`]) is made of (Trefethen, *Spectral Methods in MATLAB*,
//! ch. 6; Berrut & Trefethen, SIAM Review 46(3), 2004).

use nalgebra::DMatrix;

/// The `m + 1` Chebyshev extremal nodes `x_j = cos(jπ/m)`, `j = 0..=m`
/// (`x_0 = 1`, `x_m = −1`), computed as `sin(π(m − 2j)/(2m))` so that they
/// are exactly symmetric.
#[must_use]
pub fn nodes(m: usize) -> Vec<f64> {
    assert!(m >= 1, "at least two nodes");
    let mf = m as f64;
    (0..=m)
        .map(|j| (std::f64::consts::PI * (mf - 2.0 * j as f64) / (2.0 * mf)).sin())
        .collect()
}

/// The differentiation matrix `D` on [`nodes`]`(m)`: for a polynomial `p` of
/// degree ≤ `m`, `(D p(x))_j = p'(x_j)` exactly (up to rounding).
///
/// `D_ij = (c_i/c_j) (−1)^{i+j} / (x_i − x_j)` for `i ≠ j` (`c_0 = c_m = 2`,
/// else 1), and `D_ii = −Σ_{j≠i} D_ij` (the derivative of a constant is 0).
#[must_use]
pub fn differentiation(m: usize) -> DMatrix<f64> {
    let x = nodes(m);
    let c = |i: usize| if i == 0 || i == m { 2.0 } else { 1.0 };
    let mut d = DMatrix::zeros(m + 1, m + 1);
    for i in 0..=m {
        let mut sum = 0.0;
        for j in 0..=m {
            if i != j {
                let sgn = if (i + j) % 2 == 0 { 1.0 } else { -1.0 };
                let v = c(i) / c(j) * sgn / (x[i] - x[j]);
                d[(i, j)] = v;
                sum += v;
            }
        }
        d[(i, i)] = -sum;
    }
    d
}

/// The Lagrange basis of [`nodes`]`(m)` at `x ∈ [−1, 1]`: `ℓ_j(x)` for
/// `j = 0..=m`, so that `p(x) = Σ_j ℓ_j(x) p(x_j)` for every polynomial of
/// degree ≤ `m` (the barycentric formula with the nodes' weights
/// `(−1)^j δ_j`, `δ_0 = δ_m = ½`, else 1). At a node, the unit vector.
#[must_use]
pub fn lagrange(m: usize, x: f64) -> Vec<f64> {
    assert!(
        (-1.0..=1.0).contains(&x),
        "interpolation at {x} outside [−1, 1]"
    );
    let nodes = nodes(m);
    let mut out = vec![0.0; m + 1];
    if let Some(k) = nodes.iter().position(|&xj| xj == x) {
        out[k] = 1.0;
        return out;
    }
    let mut total = 0.0;
    for (j, &xj) in nodes.iter().enumerate() {
        let w = if j % 2 == 0 { 1.0 } else { -1.0 } * if j == 0 || j == m { 0.5 } else { 1.0 };
        out[j] = w / (x - xj);
        total += out[j];
    }
    for v in &mut out {
        *v /= total;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// p(x) = Σ a_k x^k and its derivative.
    fn poly(a: &[f64], x: f64) -> (f64, f64) {
        let (mut p, mut dp) = (0.0, 0.0);
        for &c in a.iter().rev() {
            dp = dp * x + p;
            p = p * x + c;
        }
        (p, dp)
    }

    #[test]
    fn nodes_run_from_one_to_minus_one() {
        let x = nodes(4);
        assert_eq!(x.len(), 5);
        assert_eq!(x[0], 1.0);
        assert_eq!(x[4], -1.0);
        assert_eq!(x[2], 0.0);
        assert!((x[1] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
        assert_eq!(x[1], -x[3]);
    }

    #[test]
    fn differentiation_is_exact_on_polynomials_of_degree_m() {
        for m in [1usize, 2, 5, 8, 16, 32] {
            let d = differentiation(m);
            let x = nodes(m);
            // Degree m, coefficients of both signs.
            let a: Vec<f64> = (0..=m).map(|k| ((k * 7 + 3) % 5) as f64 - 2.0).collect();
            let vals = nalgebra::DVector::from_iterator(m + 1, x.iter().map(|&t| poly(&a, t).0));
            let got = &d * vals;
            let scale: f64 = (0..=m).map(|k| k as f64 * a[k].abs()).sum::<f64>().max(1.0);
            for j in 0..=m {
                let want = poly(&a, x[j]).1;
                assert!(
                    (got[j] - want).abs() < 1e-12 * scale * (m * m) as f64,
                    "m={m} j={j}: {} vs {want}",
                    got[j]
                );
            }
        }
        // And not exact beyond degree m: x^(m+1) at m = 2.
        let d = differentiation(2);
        let x = nodes(2);
        let v = nalgebra::DVector::from_iterator(3, x.iter().map(|t| t.powi(3)));
        let got = d * v;
        assert!((got[0] - 3.0).abs() > 0.1);
    }

    #[test]
    fn lagrange_interpolation_is_exact_on_polynomials_of_degree_m() {
        for m in [1usize, 3, 8, 16, 32] {
            let x = nodes(m);
            let a: Vec<f64> = (0..=m).map(|k| ((k * 5 + 1) % 7) as f64 - 3.0).collect();
            for t in [-1.0, -0.93, -0.5, -1.0 / 3.0, 0.0, 0.123, 0.77, 1.0] {
                let l = lagrange(m, t);
                let got: f64 = l.iter().zip(&x).map(|(w, &xj)| w * poly(&a, xj).0).sum();
                let want = poly(&a, t).0;
                let scale: f64 = a.iter().map(|c| c.abs()).sum();
                assert!(
                    (got - want).abs() < 1e-13 * scale * m as f64,
                    "m={m} t={t}: {got} vs {want}"
                );
            }
            // A partition of unity, and the unit vector at the last node.
            let l = lagrange(m, -0.3);
            assert!((l.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            let end = lagrange(m, -1.0);
            assert_eq!(end[m], 1.0);
            assert_eq!(end.iter().filter(|&&v| v != 0.0).count(), 1);
        }
    }
}
