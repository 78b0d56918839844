//! One axis of a per-axis decoupled network as a tree-structured
//! characteristic matrix ([`Tree`]), and its determinant in `O(N)`.
//!
//! Per axis, the `2N`-state delay system of [`super::model`] is the
//! second-order system `Δ(s) x = 0` with
//!
//! ```text
//! Δ_ii(s) = a_i s² + b_i s + c_i
//! Δ_ij(s) = −e^{−s τ_ij} (β_ij s + γ_ij)     (j a neighbour of i)
//! ```
//!
//! (scheme 3: `a_i = J_i`, `b_i = k_ω̌`, `c_i = k_Ř D_i`, `β = 0`,
//! `γ_ij = k_Ř W_ij`; scheme 2's observer: `a_i = 1`, `b_i = k_ω D'_i`,
//! `c_i = k_R D_i`, `β = k_ω`, `γ_ij = k_R W_ij`), and
//! `det(sI − A₀ − Σ A_k e^{−sτ_k}) = det Δ(s) / Π a_i`: the same roots.
//!
//! On a forest, `Δ(s)` has nonzeros only on the diagonal and the edges:
//! Gaussian elimination leaves first (every node after its children, no
//! pivoting) creates no fill-in, and `det Δ(s)` is the product of the
//! pivots `p_v = Δ_vv − Σ_{children c} Δ_vc Δ_cv / p_c`. Differentiating
//! that recurrence gives `(log det Δ)' = Σ p_v'/p_v` (along `s`, or along
//! a common delay `d`) in the same pass: `O(N)` per point, where the dense
//! `tr(Δ⁻¹Δ')` is `O(N³)`.

use nalgebra::Complex;

type C = Complex<f64>;

/// One off-diagonal entry `Δ_ij(s) = −e^{−s τ} (β s + γ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry {
    /// `β`, the coefficient of `s`.
    pub beta: f64,
    /// `γ`, the constant coefficient.
    pub gamma: f64,
    /// Index of its delay in the delay list given to [`Tree::eval`].
    pub delay: usize,
}

impl Entry {
    /// `(Δ_ij(s), ∂Δ_ij/∂s)` with `e = e^{−sτ}`.
    fn at(&self, s: C, e: C, tau: f64) -> (C, C) {
        let q = s * self.beta + self.gamma;
        (-e * q, e * (q * tau - self.beta))
    }
}

/// A tree-structured characteristic matrix: the diagonal, and for every
/// node but a root the two entries between it and its parent.
#[derive(Debug, Clone, PartialEq)]
pub struct Tree {
    /// `(a_i, b_i, c_i)` of `Δ_ii = a s² + b s + c`.
    diag: Vec<[f64; 3]>,
    /// Nodes leaves first: every node after all of its children.
    order: Vec<usize>,
    /// Per node: the link to its parent (`None` for a root).
    up: Vec<Option<Link>>,
}

/// A node's link to its parent: the entries `Δ_{parent,v}` and
/// `Δ_{v,parent}` (`None` where that direction has no entry).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Link {
    parent: usize,
    to_parent: Option<Entry>,
    from_parent: Option<Entry>,
}

/// `log det Δ(s)` (real part exact, imaginary part modulo 2π) and its
/// derivative along the chosen direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogDet {
    /// `ln det Δ(s)`, imaginary part in `(−π, π]`.
    pub value: C,
    /// `d/ds ln det Δ` ([`Tree::eval`]) or `d/dd` ([`Tree::eval_delay`]).
    pub slope: C,
}

/// Why a graph has no [`Tree`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotForest;

/// Peels leaves (degree ≤ 1) of the graph on `0..n`: the order and each
/// node's parent; `None` unless the graph is a forest.
fn peel(n: usize, adj: &[Vec<usize>]) -> Option<(Vec<usize>, Vec<Option<usize>>)> {
    let mut degree: Vec<usize> = adj.iter().map(Vec::len).collect();
    let mut queue: std::collections::VecDeque<usize> = (0..n).filter(|&v| degree[v] <= 1).collect();
    let mut done = vec![false; n];
    let (mut order, mut parent) = (Vec::with_capacity(n), vec![None; n]);
    while let Some(v) = queue.pop_front() {
        done[v] = true;
        order.push(v);
        let mut later = adj[v].iter().copied().filter(|&u| !done[u]);
        let Some(u) = later.next() else { continue };
        if later.next().is_some() {
            return None;
        }
        parent[v] = Some(u);
        degree[u] -= 1;
        if degree[u] == 1 {
            queue.push_back(u);
        }
    }
    (order.len() == n).then_some((order, parent))
}

impl Tree {
    /// The matrix with diagonal `diag` and off-diagonal `entries`
    /// `(i, j, Δ_ij)`; [`NotForest`] unless their pattern (both directions
    /// together) is a forest with at most one entry per ordered pair and no
    /// entry on the diagonal.
    pub fn new(diag: Vec<[f64; 3]>, entries: &[(usize, usize, Entry)]) -> Result<Self, NotForest> {
        let n = diag.len();
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
        for &(i, j, _) in entries {
            if i == j || i >= n || j >= n {
                return Err(NotForest);
            }
            if !adj[i].contains(&j) {
                adj[i].push(j);
                adj[j].push(i);
            }
        }
        let (order, parent) = peel(n, &adj).ok_or(NotForest)?;
        let mut up: Vec<Option<Link>> = parent
            .iter()
            .map(|p| {
                p.map(|parent| Link {
                    parent,
                    to_parent: None,
                    from_parent: None,
                })
            })
            .collect();
        for &(i, j, e) in entries {
            // Either j is i's parent (Δ_{v,parent}) or i is j's (Δ_{parent,v}).
            let (v, to_parent) = if parent[i] == Some(j) {
                (i, true)
            } else if parent[j] == Some(i) {
                (j, false)
            } else {
                return Err(NotForest);
            };
            let Some(l) = up[v].as_mut() else {
                return Err(NotForest);
            };
            let slot = if to_parent {
                &mut l.to_parent
            } else {
                &mut l.from_parent
            };
            if slot.replace(e).is_some() {
                return Err(NotForest);
            }
        }
        Ok(Self { diag, order, up })
    }

    /// Number of nodes `N`.
    #[must_use]
    pub fn len(&self) -> usize {
        self.diag.len()
    }

    /// Whether the tree has no node.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.diag.is_empty()
    }

    /// `(a_i, b_i, c_i)` per node.
    #[must_use]
    pub fn diagonal(&self) -> &[[f64; 3]] {
        &self.diag
    }

    /// Every off-diagonal entry `(i, j, Δ_ij)`.
    #[must_use]
    pub fn entries(&self) -> Vec<(usize, usize, Entry)> {
        let mut out = Vec::new();
        for (v, link) in self.up.iter().enumerate() {
            if let Some(l) = link {
                out.extend(l.from_parent.map(|e| (l.parent, v, e)));
                out.extend(l.to_parent.map(|e| (v, l.parent, e)));
            }
        }
        out
    }

    /// `ln det Δ(s)` and `d/ds ln det Δ(s)` with delays `taus` (indexed by
    /// [`Entry::delay`]); `None` where a pivot is exactly 0 or not finite
    /// (`s` is a root, or overflow).
    #[must_use]
    pub fn eval(&self, s: C, taus: &[f64]) -> Option<LogDet> {
        let exps: Vec<C> = taus.iter().map(|&t| (-s * t).exp()).collect();
        self.eliminate(
            |[a, b, c]| (s * s * a + s * b + c, s * (2.0 * a) + b),
            |e: &Entry| e.at(s, exps[e.delay], taus[e.delay]),
        )
    }

    /// `ln det Δ(s)` and `∂/∂d ln det Δ(s)` with every entry delayed by the
    /// common delay `d` (`∂Δ_ij/∂d = −s Δ_ij`); `None` as [`Self::eval`].
    #[must_use]
    pub fn eval_delay(&self, s: C, d: f64) -> Option<LogDet> {
        let e = (-s * d).exp();
        self.eliminate(
            |[a, b, c]| (s * s * a + s * b + c, C::new(0.0, 0.0)),
            |x: &Entry| {
                let v = -e * (s * x.beta + x.gamma);
                (v, -s * v)
            },
        )
    }

    /// Leaves-first elimination with entries and their derivatives from
    /// `diag` and `off`: `Σ ln p_v` (as a scaled product) and `Σ p_v'/p_v`.
    fn eliminate(
        &self,
        diag: impl Fn([f64; 3]) -> (C, C),
        off: impl Fn(&Entry) -> (C, C),
    ) -> Option<LogDet> {
        let mut acc: Vec<(C, C)> = self.diag.iter().map(|&d| diag(d)).collect();
        let (mut prod, mut exp2) = (C::new(1.0, 0.0), 0i32);
        let mut slope = C::new(0.0, 0.0);
        for &v in &self.order {
            let (p, dp) = acc[v];
            if p.norm_sqr() == 0.0 || !(p.re.is_finite() && p.im.is_finite()) {
                return None;
            }
            let inv = p.inv();
            slope += dp * inv;
            prod *= p;
            let m = prod.re.abs().max(prod.im.abs());
            if !(1e-100..=1e100).contains(&m) {
                let k = m.log2().floor() as i32;
                prod *= 2f64.powi(-k);
                exp2 += k;
            }
            if let Some(Link {
                parent,
                to_parent: Some(a),
                from_parent: Some(b),
            }) = &self.up[v]
            {
                let ((x1, d1), (x2, d2)) = (off(a), off(b));
                let x = x1 * x2;
                let dx = d1 * x2 + x1 * d2;
                let q = x * inv;
                acc[*parent].0 -= q;
                acc[*parent].1 -= (dx - q * dp) * inv;
            }
        }
        if prod.norm_sqr() == 0.0 || !(slope.re.is_finite() && slope.im.is_finite()) {
            return None;
        }
        let value = prod.ln() + f64::from(exp2) * std::f64::consts::LN_2;
        Some(LogDet { value, slope })
    }

    /// A bound on `|s|` for every root with `Re s ≥ sigma` at delays
    /// `taus`: in the row of `x`'s largest entry,
    /// `a|s|² − |b||s| − |c| ≤ |Δ_ii(s)| ≤ Σ_j |Δ_ij(s)| ≤ e^{−στ}(|β||s| + |γ|)`
    /// (Gershgorin), so `|s|` is at most the largest positive root of
    /// `a x² − (|b| + Σ|β|e^{−στ}) x − (|c| + Σ|γ|e^{−στ})`.
    #[must_use]
    pub fn radius(&self, sigma: f64, taus: &[f64]) -> f64 {
        let grow = |k: usize| (-sigma * taus[k]).exp().max(1.0);
        let mut lin: Vec<f64> = self.diag.iter().map(|d| d[1].abs()).collect();
        let mut cst: Vec<f64> = self.diag.iter().map(|d| d[2].abs()).collect();
        for (i, _, e) in self.entries() {
            lin[i] += e.beta.abs() * grow(e.delay);
            cst[i] += e.gamma.abs() * grow(e.delay);
        }
        (0..self.len())
            .map(|i| {
                let a = self.diag[i][0];
                (lin[i] + (lin[i] * lin[i] + 4.0 * a * cst[i]).sqrt()) / (2.0 * a)
            })
            .fold(0.0, f64::max)
    }

    /// Whether `diag(|Δ_ii(iω)|) − |Δ_ij(iω)|` (common delay: `|e^{−iωd}| =
    /// 1`) is a nonsingular M-matrix, i.e. `ρ(|P⁻¹Q|) < 1` with `P` the
    /// diagonal and `Q` the rest: then no eigenvalue of `P(iω)⁻¹Q(iω)` is on
    /// the unit circle and no common delay puts a root at `iω`. Leaves-first
    /// elimination: every pivot of a Z-matrix positive.
    #[must_use]
    pub fn dominant(&self, w: f64) -> bool {
        let s = C::new(0.0, w);
        let mut acc: Vec<f64> = self
            .diag
            .iter()
            .map(|&[a, b, c]| (s * s * a + s * b + c).norm())
            .collect();
        let abs = |e: &Entry| (s * e.beta + e.gamma).norm();
        for &v in &self.order {
            let p = acc[v];
            if p <= 0.0 {
                return false;
            }
            if let Some(Link {
                parent,
                to_parent: Some(a),
                from_parent: Some(b),
            }) = &self.up[v]
            {
                acc[*parent] -= abs(a) * abs(b) / p;
            }
        }
        true
    }
}

impl Tree {
    /// The first-order delay system `z = [x₁, ẋ₁, x₂, ẋ₂, …]` with these
    /// roots: `ẍ_i = (−b_i ẋ_i − c_i x_i + Σ_j (β_ij ẋ_j + γ_ij x_j)(t − τ_ij)) / a_i`
    /// (dense, `2N` square: for checks on small trees).
    #[must_use]
    pub fn to_dde(&self, taus: &[f64]) -> super::system::Dde {
        use nalgebra::DMatrix;
        let n = 2 * self.len();
        let mut a0 = DMatrix::zeros(n, n);
        for (i, &[a, b, c]) in self.diag.iter().enumerate() {
            a0[(2 * i, 2 * i + 1)] = 1.0;
            a0[(2 * i + 1, 2 * i)] = -c / a;
            a0[(2 * i + 1, 2 * i + 1)] = -b / a;
        }
        let mut delayed: Vec<(f64, DMatrix<f64>)> =
            taus.iter().map(|&t| (t, DMatrix::zeros(n, n))).collect();
        for (i, j, e) in self.entries() {
            let a = self.diag[i][0];
            let m = &mut delayed[e.delay].1;
            m[(2 * i + 1, 2 * j)] += e.gamma / a;
            m[(2 * i + 1, 2 * j + 1)] += e.beta / a;
        }
        super::system::Dde::new(a0, delayed)
    }
}
