//! Eigenvalues of dense matrices, with an iteration limit: a real matrix by
//! balancing, Householder reduction to Hessenberg form and Francis's
//! double-shift QR (EISPACK's `balanc`, `orthes`, `hqr`), and a complex
//! matrix by Householder reduction and single-shift QR with Wilkinson's
//! shift (EISPACK's `comqr`).
//!
//! # NOTE
//! Not nalgebra's Schur iteration: it has no exceptional shifts and does not
//! converge on some matrices with repeated eigenvalues (`attitude::stiffness`
//! saw it hang). Both iterations here shift exceptionally every 10 sweeps
//! and give up (`None`) after [`MAX_SWEEPS`] sweeps on one eigenvalue.

use nalgebra::{Complex, DMatrix};

/// Sweeps on one eigenvalue before giving up.
pub const MAX_SWEEPS: usize = 80;

/// A dense square matrix, row-major, indexed from 1 (the indices of the
/// EISPACK routines transcribed below).
struct Mat1 {
    n: usize,
    d: Vec<f64>,
}

impl std::ops::Index<(usize, usize)> for Mat1 {
    type Output = f64;
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        &self.d[(i - 1) * self.n + (j - 1)]
    }
}

impl std::ops::IndexMut<(usize, usize)> for Mat1 {
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        &mut self.d[(i - 1) * self.n + (j - 1)]
    }
}

/// The eigenvalues of a real square matrix (each complex pair as `a ± ib`,
/// in no particular order), or `None` if the QR iteration did not converge.
#[must_use]
pub fn real_eigenvalues(a: &DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    assert!(a.is_square(), "eigenvalues of a non-square matrix");
    let n = a.nrows();
    if n == 0 {
        return Some(Vec::new());
    }
    if !a.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut m = Mat1 {
        n,
        d: (0..n * n).map(|k| a[(k / n, k % n)]).collect(),
    };
    balance(&mut m);
    hessenberg(&mut m);
    hqr(&mut m)
}

/// Scales rows and columns by powers of 2 (exact) so that each row and its
/// column have comparable norms (EISPACK `balanc`, without permutations):
/// a similarity that reduces the norm, and so the rounding of QR.
fn balance(a: &mut Mat1) {
    const RADIX: f64 = 2.0;
    let sqrdx = RADIX * RADIX;
    let n = a.n;
    let mut done = false;
    while !done {
        done = true;
        for i in 1..=n {
            let (mut r, mut c) = (0.0, 0.0);
            for j in 1..=n {
                if j != i {
                    c += a[(j, i)].abs();
                    r += a[(i, j)].abs();
                }
            }
            if c != 0.0 && r != 0.0 {
                let mut g = r / RADIX;
                let mut f = 1.0;
                let s = c + r;
                while c < g {
                    f *= RADIX;
                    c *= sqrdx;
                }
                g = r * RADIX;
                while c > g {
                    f /= RADIX;
                    c /= sqrdx;
                }
                if (c + r) / f < 0.95 * s {
                    done = false;
                    let g = 1.0 / f;
                    for j in 1..=n {
                        a[(i, j)] *= g;
                    }
                    for j in 1..=n {
                        a[(j, i)] *= f;
                    }
                }
            }
        }
    }
}

/// Householder reduction to upper Hessenberg form (EISPACK `orthes`,
/// without the transformations): below the subdiagonal is set to zero.
/// Rows are contiguous, so both sides are applied row by row.
fn hessenberg(a: &mut Mat1) {
    let n = a.n;
    let d = &mut a.d;
    let mut u = vec![0.0; n];
    let mut f = vec![0.0; n];
    for k in 0..n.saturating_sub(2) {
        // Column k below the diagonal: rows k+1..n (0-based).
        let scale: f64 = (k + 1..n).map(|i| d[i * n + k].abs()).sum();
        if scale == 0.0 {
            continue;
        }
        let mut h = 0.0;
        for i in k + 1..n {
            u[i] = d[i * n + k] / scale;
            h += u[i] * u[i];
        }
        let g = -u[k + 1].signum() * h.sqrt();
        h -= u[k + 1] * g;
        u[k + 1] -= g;
        // P = I − u uᵀ / h from the left (columns k..n): f = uᵀ A, A −= u fᵀ / h …
        let fk = &mut f[k..n];
        fk.fill(0.0);
        for i in k + 1..n {
            let ui = u[i];
            for (fj, aij) in fk.iter_mut().zip(&d[i * n + k..(i + 1) * n]) {
                *fj += ui * aij;
            }
        }
        for i in k + 1..n {
            let c = u[i] / h;
            for (aij, fj) in d[i * n + k..(i + 1) * n].iter_mut().zip(fk.iter()) {
                *aij -= c * fj;
            }
        }
        // … and from the right (every row): A −= (A u) uᵀ / h.
        let uk = &u[k + 1..n];
        for i in 0..n {
            let row = &mut d[i * n + k + 1..(i + 1) * n];
            let s = row.iter().zip(uk).map(|(x, y)| x * y).sum::<f64>() / h;
            for (aij, uj) in row.iter_mut().zip(uk) {
                *aij -= s * uj;
            }
        }
        d[(k + 1) * n + k] = scale * g;
        for i in k + 2..n {
            d[i * n + k] = 0.0;
        }
    }
}

/// `|a|` with the sign of `b` (Fortran's `SIGN`).
fn sign(a: f64, b: f64) -> f64 {
    if b >= 0.0 { a.abs() } else { -a.abs() }
}

/// Eigenvalues of an upper Hessenberg matrix by Francis's double-shift QR
/// (EISPACK `hqr`; the matrix is destroyed). Exceptional shifts at every
/// 10th sweep on one eigenvalue, alternately from the bottom and the top of
/// the active block (as LAPACK's `dlahqr`); `None` after [`MAX_SWEEPS`].
#[allow(clippy::many_single_char_names)]
fn hqr(a: &mut Mat1) -> Option<Vec<Complex<f64>>> {
    let n = a.n;
    let mut out = Vec::with_capacity(n);
    let mut anorm = 0.0;
    for i in 1..=n {
        for j in i.saturating_sub(1).max(1)..=n {
            anorm += a[(i, j)].abs();
        }
    }
    let mut nn = n;
    let mut t = 0.0;
    while nn >= 1 {
        let mut its = 0;
        loop {
            // A negligible subdiagonal element splits the matrix at l.
            let mut l = nn;
            while l >= 2 {
                let mut s = a[(l - 1, l - 1)].abs() + a[(l, l)].abs();
                if s == 0.0 {
                    s = anorm;
                }
                if a[(l, l - 1)].abs() + s == s {
                    a[(l, l - 1)] = 0.0;
                    break;
                }
                l -= 1;
            }
            let mut x = a[(nn, nn)];
            if l == nn {
                // One root.
                out.push(Complex::new(x + t, 0.0));
                nn -= 1;
                break;
            }
            let mut y = a[(nn - 1, nn - 1)];
            let mut w = a[(nn, nn - 1)] * a[(nn - 1, nn)];
            if l == nn - 1 {
                // Two roots, from the trailing 2×2 block.
                let p = 0.5 * (y - x);
                let q = p * p + w;
                let mut z = q.abs().sqrt();
                x += t;
                if q >= 0.0 {
                    z = p + sign(z, p);
                    let big = x + z;
                    let small = if z != 0.0 { x - w / z } else { big };
                    out.push(Complex::new(big, 0.0));
                    out.push(Complex::new(small, 0.0));
                } else {
                    out.push(Complex::new(x + p, z));
                    out.push(Complex::new(x + p, -z));
                }
                nn -= 2;
                break;
            }
            if its == MAX_SWEEPS {
                return None;
            }
            if its > 0 && its % 10 == 0 {
                // Exceptional shift.
                t += x;
                for i in 1..=nn {
                    a[(i, i)] -= x;
                }
                let s = if (its / 10) % 2 == 0 && l + 2 <= nn {
                    a[(l + 1, l)].abs() + a[(l + 2, l + 1)].abs()
                } else {
                    a[(nn, nn - 1)].abs() + a[(nn - 1, nn - 2)].abs()
                };
                x = 0.75 * s;
                y = x;
                w = -0.4375 * s * s;
            }
            its += 1;
            // Two consecutive small subdiagonal elements: start the sweep at m.
            let mut m = nn - 2;
            let (mut p, mut q, mut r);
            loop {
                let z = a[(m, m)];
                let rr = x - z;
                let s = y - z;
                p = (rr * s - w) / a[(m + 1, m)] + a[(m, m + 1)];
                q = a[(m + 1, m + 1)] - z - rr - s;
                r = a[(m + 2, m + 1)];
                let s = p.abs() + q.abs() + r.abs();
                p /= s;
                q /= s;
                r /= s;
                if m == l {
                    break;
                }
                let u = a[(m, m - 1)].abs() * (q.abs() + r.abs());
                let v = p.abs() * (a[(m - 1, m - 1)].abs() + z.abs() + a[(m + 1, m + 1)].abs());
                if u + v == v {
                    break;
                }
                m -= 1;
            }
            for i in m + 2..=nn {
                a[(i, i - 2)] = 0.0;
                if i != m + 2 {
                    a[(i, i - 3)] = 0.0;
                }
            }
            // The double-shift QR sweep on rows and columns l..=nn.
            for k in m..nn {
                if k != m {
                    p = a[(k, k - 1)];
                    q = a[(k + 1, k - 1)];
                    r = if k != nn - 1 { a[(k + 2, k - 1)] } else { 0.0 };
                    x = p.abs() + q.abs() + r.abs();
                    if x != 0.0 {
                        p /= x;
                        q /= x;
                        r /= x;
                    }
                }
                let s = sign((p * p + q * q + r * r).sqrt(), p);
                if s == 0.0 {
                    continue;
                }
                if k == m {
                    if l != m {
                        a[(k, k - 1)] = -a[(k, k - 1)];
                    }
                } else {
                    a[(k, k - 1)] = -s * x;
                }
                p += s;
                x = p / s;
                y = q / s;
                let z = r / s;
                q /= p;
                r /= p;
                // Rows k, k+1 (and k+2), columns k..=nn: contiguous slices.
                let n = a.n;
                let (c0, c1) = ((k - 1) * n + (k - 1), (k - 1) * n + nn);
                let (top, rest) = a.d.split_at_mut(k * n);
                let row_k = &mut top[c0..c1];
                let (mid, low) = rest.split_at_mut(n);
                let row_k1 = &mut mid[k - 1..nn];
                if k != nn - 1 {
                    let row_k2 = &mut low[k - 1..nn];
                    for ((a0, a1), a2) in row_k
                        .iter_mut()
                        .zip(row_k1.iter_mut())
                        .zip(row_k2.iter_mut())
                    {
                        let pp = *a0 + q * *a1 + r * *a2;
                        *a2 -= pp * z;
                        *a1 -= pp * y;
                        *a0 -= pp * x;
                    }
                } else {
                    for (a0, a1) in row_k.iter_mut().zip(row_k1.iter_mut()) {
                        let pp = *a0 + q * *a1;
                        *a1 -= pp * y;
                        *a0 -= pp * x;
                    }
                }
                let mmin = nn.min(k + 3);
                for i in l..=mmin {
                    let base = (i - 1) * n + (k - 1);
                    if k != nn - 1 {
                        let row = &mut a.d[base..base + 3];
                        let pp = x * row[0] + y * row[1] + z * row[2];
                        row[2] -= pp * r;
                        row[1] -= pp * q;
                        row[0] -= pp;
                    } else {
                        let row = &mut a.d[base..base + 2];
                        let pp = x * row[0] + y * row[1];
                        row[1] -= pp * q;
                        row[0] -= pp;
                    }
                }
            }
        }
    }
    Some(out)
}

/// `|re| + |im|`: the cheap modulus EISPACK's complex routines compare.
fn l1(z: Complex<f64>) -> f64 {
    z.re.abs() + z.im.abs()
}

/// The eigenvalues of a complex square matrix (in no particular order), or
/// `None` if the QR iteration did not converge.
#[must_use]
pub fn complex_eigenvalues(a: &DMatrix<Complex<f64>>) -> Option<Vec<Complex<f64>>> {
    assert!(a.is_square(), "eigenvalues of a non-square matrix");
    let n = a.nrows();
    if n == 0 {
        return Some(Vec::new());
    }
    if !a.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
        return None;
    }
    let mut h: Vec<Complex<f64>> = (0..n * n).map(|k| a[(k / n, k % n)]).collect();
    complex_hessenberg(&mut h, n);
    complex_qr(&mut h, n)
}

/// Householder reduction of a complex matrix (row-major, 0-based) to upper
/// Hessenberg form; below the subdiagonal is set to zero.
fn complex_hessenberg(h: &mut [Complex<f64>], n: usize) {
    let zero = Complex::new(0.0, 0.0);
    let mut v = vec![zero; n];
    for k in 0..n.saturating_sub(2) {
        let norm = (k + 1..n)
            .map(|i| h[i * n + k].norm_sqr())
            .sum::<f64>()
            .sqrt();
        let tail = (k + 2..n).map(|i| h[i * n + k].norm_sqr()).sum::<f64>();
        if norm == 0.0 || tail == 0.0 {
            continue;
        }
        let x0 = h[(k + 1) * n + k];
        let phase = if x0.norm() == 0.0 {
            Complex::new(1.0, 0.0)
        } else {
            x0 / x0.norm()
        };
        let alpha = -phase * norm;
        // v = x − α e₁, normalised: H = I − 2 v v*.
        for i in k + 1..n {
            v[i] = h[i * n + k];
        }
        v[k + 1] -= alpha;
        let vn = (k + 1..n).map(|i| v[i].norm_sqr()).sum::<f64>().sqrt();
        for i in k + 1..n {
            v[i] /= vn;
        }
        for j in k..n {
            let f: Complex<f64> = (k + 1..n).map(|i| v[i].conj() * h[i * n + j]).sum();
            for i in k + 1..n {
                h[i * n + j] -= v[i] * f * 2.0;
            }
        }
        for i in 0..n {
            let f: Complex<f64> = (k + 1..n).map(|j| h[i * n + j] * v[j]).sum();
            for j in k + 1..n {
                h[i * n + j] -= f * v[j].conj() * 2.0;
            }
        }
        h[(k + 1) * n + k] = alpha;
        for i in k + 2..n {
            h[i * n + k] = zero;
        }
    }
}

/// Eigenvalues of a complex upper Hessenberg matrix (row-major, 0-based;
/// destroyed) by explicitly shifted QR with Givens rotations on the active
/// block, Wilkinson's shift, an exceptional shift every 10th sweep.
fn complex_qr(h: &mut [Complex<f64>], n: usize) -> Option<Vec<Complex<f64>>> {
    let zero = Complex::new(0.0, 0.0);
    let norm: f64 = h.iter().map(|z| l1(*z)).sum();
    let mut out = Vec::with_capacity(n);
    let mut rot = vec![(0.0, zero); n];
    let mut hi = n - 1;
    let mut its = 0;
    loop {
        if hi == 0 {
            out.push(h[0]);
            return Some(out);
        }
        let mut l = hi;
        while l > 0 {
            let mut s = l1(h[(l - 1) * n + l - 1]) + l1(h[l * n + l]);
            if s == 0.0 {
                s = norm;
            }
            if l1(h[l * n + l - 1]) + s == s {
                h[l * n + l - 1] = zero;
                break;
            }
            l -= 1;
        }
        if l == hi {
            out.push(h[hi * n + hi]);
            hi -= 1;
            its = 0;
            continue;
        }
        if its == MAX_SWEEPS {
            return None;
        }
        its += 1;
        let d = h[hi * n + hi];
        let mu = if its % 10 == 0 {
            let below = if hi >= 2 {
                l1(h[(hi - 1) * n + hi - 2])
            } else {
                0.0
            };
            d + Complex::new(0.75, 0.4375) * (l1(h[hi * n + hi - 1]) + below)
        } else {
            // The eigenvalue of the trailing 2×2 block nearest its last entry.
            let a = h[(hi - 1) * n + hi - 1];
            let bc = h[(hi - 1) * n + hi] * h[hi * n + hi - 1];
            let p = (a - d) * 0.5;
            let mut disc = (p * p + bc).sqrt();
            if (p.conj() * disc).re < 0.0 {
                disc = -disc;
            }
            let den = p + disc;
            if den.norm() == 0.0 { d } else { d - bc / den }
        };
        for i in l..=hi {
            h[i * n + i] -= mu;
        }
        // H − μ I = Q R (rotations from the left), then R Q + μ I.
        for k in l..hi {
            let a = h[k * n + k];
            let b = h[(k + 1) * n + k];
            let r = (a.norm_sqr() + b.norm_sqr()).sqrt();
            let (c, s) = if r == 0.0 {
                (1.0, zero)
            } else if a.norm() == 0.0 {
                (0.0, Complex::new(1.0, 0.0))
            } else {
                let c = a.norm() / r;
                (c, (a / a.norm()) * b.conj() / r)
            };
            rot[k] = (c, s);
            for j in k..=hi {
                let x = h[k * n + j];
                let y = h[(k + 1) * n + j];
                h[k * n + j] = x * c + s * y;
                h[(k + 1) * n + j] = -s.conj() * x + y * c;
            }
        }
        for k in l..hi {
            let (c, s) = rot[k];
            for i in l..=(k + 1).min(hi) {
                let x = h[i * n + k];
                let y = h[i * n + k + 1];
                h[i * n + k] = x * c + y * s.conj();
                h[i * n + k + 1] = -x * s + y * c;
            }
        }
        for i in l..=hi {
            h[i * n + i] += mu;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex<f64> {
        Complex::new(re, im)
    }

    /// Every expected value has a distinct computed one within `tol`.
    fn same_set(got: &[Complex<f64>], want: &[Complex<f64>], tol: f64) {
        assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
        let mut used = vec![false; got.len()];
        for w in want {
            let k = (0..got.len())
                .filter(|&k| !used[k])
                .min_by(|&a, &b| (got[a] - w).norm().total_cmp(&(got[b] - w).norm()))
                .expect("a value left");
            assert!((got[k] - w).norm() <= tol, "{w} not found in {got:?}");
            used[k] = true;
        }
    }

    /// A deterministic pseudo-random stream in [−1, 1).
    fn stream(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    #[test]
    fn a_companion_matrix_has_its_polynomials_roots() {
        // (s + 1)(s + 2)(s² + 2 s + 5)(s − 3) = s⁵ + 2s⁴ − 2s³ − 20s² − 47s − 30.
        let coeffs = [2.0, -2.0, -20.0, -47.0, -30.0];
        let n = coeffs.len();
        let mut a = DMatrix::zeros(n, n);
        for j in 0..n {
            a[(0, j)] = -coeffs[j];
        }
        for i in 1..n {
            a[(i, i - 1)] = 1.0;
        }
        let got = real_eigenvalues(&a).expect("converges");
        same_set(
            &got,
            &[
                c(-1.0, 0.0),
                c(-2.0, 0.0),
                c(-1.0, 2.0),
                c(-1.0, -2.0),
                c(3.0, 0.0),
            ],
            1e-10,
        );
        let ac = a.map(|v| c(v, 0.0));
        let got = complex_eigenvalues(&ac).expect("converges");
        same_set(
            &got,
            &[
                c(-1.0, 0.0),
                c(-2.0, 0.0),
                c(-1.0, 2.0),
                c(-1.0, -2.0),
                c(3.0, 0.0),
            ],
            1e-10,
        );
    }

    /// A cyclic permutation: eigenvalues the n-th roots of unity, the classic
    /// matrix on which QR without exceptional shifts makes no progress.
    #[test]
    fn a_cyclic_permutation_converges() {
        for n in [2usize, 3, 5, 8] {
            let mut a = DMatrix::zeros(n, n);
            for i in 0..n {
                a[((i + 1) % n, i)] = 1.0;
            }
            let want: Vec<_> = (0..n)
                .map(|k| Complex::from_polar(1.0, 2.0 * std::f64::consts::PI * k as f64 / n as f64))
                .collect();
            same_set(&real_eigenvalues(&a).expect("converges"), &want, 1e-10);
            let ac = a.map(|v| c(v, 0.0));
            same_set(&complex_eigenvalues(&ac).expect("converges"), &want, 1e-10);
        }
    }

    /// JAMA's reported non-terminating case, and a block with repeated
    /// eigenvalues like the one nalgebra's Schur iteration hung on.
    #[test]
    fn hard_cases_converge() {
        let a = DMatrix::from_row_slice(
            5,
            5,
            &[
                0., 0., 0., 0., 0., 0., 0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0., 0., 1., 1.,
                0., 1., 0., 1.,
            ],
        );
        let got = real_eigenvalues(&a).expect("converges");
        // Each is a root of det(A − λI): check by the product of the
        // eigenvalues (det A = 0) and their sum (tr A = 1).
        let sum: Complex<f64> = got.iter().sum();
        assert!((sum - c(1.0, 0.0)).norm() < 1e-10, "{got:?}");
        let ac = a.map(|v| c(v, 0.0));
        let got2 = complex_eigenvalues(&ac).expect("converges");
        same_set(&got2, &got, 1e-7);

        // [[0, I, 0], [−k I, −d I, I], [0, 0, S]] with repeated roots.
        let (k, d) = (49.0, 14.0); // s² + 14 s + 49: double root −7, three times.
        let mut b = DMatrix::zeros(9, 9);
        for i in 0..3 {
            b[(i, 3 + i)] = 1.0;
            b[(3 + i, i)] = -k;
            b[(3 + i, 3 + i)] = -d;
            b[(3 + i, 6 + i)] = 1.0;
            b[(6 + i, 6 + i)] = -12.0;
        }
        let got = real_eigenvalues(&b).expect("converges");
        let mut want = vec![c(-7.0, 0.0); 6];
        want.extend([c(-12.0, 0.0); 3]);
        same_set(&got, &want, 1e-6);
    }

    #[test]
    fn random_matrices_match_their_trace_and_determinant() {
        let mut r = stream(7);
        for n in [1usize, 2, 3, 6, 17, 40] {
            let a = DMatrix::from_fn(n, n, |_, _| r());
            let got = real_eigenvalues(&a).expect("converges");
            assert_eq!(got.len(), n);
            let sum: Complex<f64> = got.iter().sum();
            let prod: Complex<f64> = got.iter().product();
            assert!((sum.re - a.trace()).abs() < 1e-10 * n as f64, "{n}");
            assert!(sum.im.abs() < 1e-10 * n as f64);
            let det = a.determinant();
            assert!(
                (prod - c(det, 0.0)).norm() < 1e-9 * (1.0 + det.abs()),
                "{n}"
            );
            // And each is an eigenvalue: A − λI is singular.
            for z in &got {
                let m = a.map(|v| c(v, 0.0)) - DMatrix::identity(n, n) * *z;
                let s = m.singular_values();
                assert!(s.min() <= 1e-9 * s.max().max(1.0), "{n}: {z}");
            }
            let ac = DMatrix::from_fn(n, n, |_, _| c(r(), r()));
            let got = complex_eigenvalues(&ac).expect("converges");
            let sum: Complex<f64> = got.iter().sum();
            assert!((sum - ac.trace()).norm() < 1e-10 * n as f64);
            for z in &got {
                let m = &ac - DMatrix::identity(n, n) * *z;
                let s = m.singular_values();
                assert!(s.min() <= 1e-9 * s.max().max(1.0), "{n}: {z}");
            }
        }
    }

    #[test]
    fn badly_scaled_matrices_are_balanced() {
        // diag(1, 1e6, 1e-6) similarity of a matrix with eigenvalues 1, 2, 3.
        let b = DMatrix::from_row_slice(3, 3, &[2.0, 1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 3.0]);
        let s = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 1e6, 1e-6]));
        let si = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 1e-6, 1e6]));
        let a = &s * b * si;
        let got = real_eigenvalues(&a).expect("converges");
        same_set(&got, &[c(1.0, 0.0), c(2.0, 0.0), c(3.0, 0.0)], 1e-9);
    }
}
