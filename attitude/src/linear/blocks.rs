//! The decoupled systems of a [`super::Linearisation`]: dense matrices
//! ([`dense`]) while the pseudospectral discretisation fits
//! ([`dense_size`]), else per axis on the forest ([`trees`],
//! [`super::tree`]); and scheme 2's delay-free tracking roots
//! ([`tracking`]). The equations are in [`super::model`]'s docs.

use super::profile::Profile;
use super::roots::{self, MIN_ORDER};
use super::system::Dde;
use super::tree::{Entry, NotForest, Tree};
use crate::network::{Network, Scheme};
use crate::stiffness::{psi_gain, quadratic_roots};
use nalgebra::{Complex, DMatrix, Matrix3};
use std::collections::{BTreeMap, BTreeSet};

/// One decoupled system: an axis (or all three) and its matrices.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Block {
    pub(super) axis: Option<usize>,
    pub(super) body: Body,
}

/// A decoupled system's matrices: dense, or (large networks, per axis) a
/// tree-structured characteristic matrix.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Body {
    Dense(Dense),
    Tree(TreeBody),
}

/// The own-state terms and, per follower-link delay in steps, the coupling
/// terms.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Dense {
    pub(super) a0: DMatrix<f64>,
    pub(super) links: BTreeMap<u64, DMatrix<f64>>,
    /// `G(ω)` of the common-delay system ([`Profile`]).
    pub(super) profile: Profile,
}

/// `Δ(s)` on the forest, and the follower-link delays in steps its entries
/// index ([`Entry::delay`]).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TreeBody {
    pub(super) tree: Tree,
    pub(super) steps: Vec<u64>,
}

/// Which delays a root search is for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Delays {
    /// The network's own per-link delays.
    Own,
    /// Every follower link delayed by this many seconds.
    Common(f64),
}

impl Dense {
    /// The delay system at the network's own per-link delays.
    pub(super) fn own(&self, dt: f64) -> Dde {
        let delayed = self
            .links
            .iter()
            .map(|(&k, a)| (k as f64 * dt, a.clone()))
            .collect();
        Dde::new(self.a0.clone(), delayed)
    }

    /// Every coupling term together (`A₁`).
    pub(super) fn coupling(&self) -> DMatrix<f64> {
        let n = self.a0.nrows();
        self.links
            .values()
            .fold(DMatrix::zeros(n, n), |acc, a| acc + a)
    }

    /// The delay system with every follower link delayed by `d`.
    pub(super) fn common(&self, d: f64) -> Dde {
        Dde::new(self.a0.clone(), vec![(d, self.coupling())])
    }
}

impl TreeBody {
    /// The delay of each entry index, s.
    pub(super) fn taus(&self, dt: f64, which: Delays) -> Vec<f64> {
        match which {
            Delays::Own => self.steps.iter().map(|&k| k as f64 * dt).collect(),
            Delays::Common(d) => vec![d; self.steps.len()],
        }
    }
}

impl Block {
    /// The dense delay system (built from the tree for a tree body).
    pub(super) fn dde(&self, dt: f64, which: Delays) -> Dde {
        match (&self.body, which) {
            (Body::Dense(b), Delays::Own) => b.own(dt),
            (Body::Dense(b), Delays::Common(d)) => b.common(d),
            (Body::Tree(t), w) => t.tree.to_dde(&t.taus(dt, w)),
        }
    }

    /// The distinct follower-link delays in steps.
    pub(super) fn steps(&self) -> Vec<u64> {
        match &self.body {
            Body::Dense(b) => b.links.keys().copied().collect(),
            Body::Tree(t) => t.steps.clone(),
        }
    }
}

/// Whether `m` is diagonal (off-diagonal entries exactly 0).
pub(super) fn diagonal(m: &Matrix3<f64>) -> bool {
    (0..3).all(|i| (0..3).all(|j| i == j || m[(i, j)] == 0.0))
}

/// Adds `v` to the `b × b` block of `m` at block row `r`, block column `c`.
fn add(m: &mut DMatrix<f64>, b: usize, r: usize, c: usize, v: &DMatrix<f64>) {
    let mut blk = m.view_mut((r * b, c * b), (b, b));
    blk += v;
}

/// An upper bound on the size of the dense discretisation at the second
/// Chebyshev order ([`roots::size`] of every block, `n + p·(M + M/2)`):
/// `n = 2bN` (`b` = 1 per axis, 3 for one system), `p` = `b` (scheme 3:
/// attitudes) or `2b` (scheme 2: and rates) per agent some agent hears.
pub(super) fn dense_size(net: &Network, observer: bool, split: bool) -> usize {
    let b = if split { 1 } else { 3 };
    let heard: BTreeSet<u32> = net
        .agents
        .iter()
        .flat_map(|a| a.model.neighbours.iter().map(|n| n.id))
        .collect();
    let per = if observer { 2 * b } else { b };
    2 * b * net.agents.len() + per * heard.len() * (MIN_ORDER + MIN_ORDER / 2)
}

/// The dense systems: one per axis if `split`, else one.
pub(super) fn dense(net: &Network, observer: bool, gains: (f64, f64), split: bool) -> Vec<Block> {
    let axes: Vec<Option<usize>> = if split {
        vec![Some(0), Some(1), Some(2)]
    } else {
        vec![None]
    };
    axes.into_iter()
        .map(|axis| Block {
            axis,
            body: Body::Dense(dense_block(net, observer, gains, split, axis)),
        })
        .collect()
}

/// The dense system of one axis (or of all three).
fn dense_block(
    net: &Network,
    observer: bool,
    (k_r, k_w): (f64, f64),
    split: bool,
    axis: Option<usize>,
) -> Dense {
    let b = if split { 1 } else { 3 };
    let states = 2 * b * net.agents.len();
    let index = net.index_by_id();
    let proj = |m: &Matrix3<f64>| -> DMatrix<f64> {
        match axis {
            Some(k) => DMatrix::from_element(1, 1, m[(k, k)]),
            None => DMatrix::from_column_slice(3, 3, m.as_slice()),
        }
    };
    let eye = proj(&Matrix3::identity());
    let mut a0 = DMatrix::zeros(states, states);
    let mut links: BTreeMap<u64, DMatrix<f64>> = BTreeMap::new();
    for (p, agent) in net.agents.iter().enumerate() {
        let m = &agent.model;
        let (pos, vel) = (2 * p, 2 * p + 1);
        // The observer has no inertia (eq. 16b); the bodies do.
        let scale = if !observer {
            if split {
                Matrix3::from_diagonal(&m.inertia.j.diagonal().map(|j| 1.0 / j))
            } else {
                m.inertia.j_inv
            }
        } else {
            Matrix3::identity()
        };
        let mut stiff = m.leader_gain.as_ref().map_or(Matrix3::zeros(), psi_gain);
        let mut damp = if m.leader_gain.is_some() && observer {
            1.0
        } else {
            0.0
        };
        for nb in &m.neighbours {
            stiff += psi_gain(&nb.a);
            if observer {
                damp += 1.0;
            }
            let q = index[&nb.id];
            let steps = nb.link.map_or(0, |l| l.delay);
            let c = links
                .entry(steps)
                .or_insert_with(|| DMatrix::zeros(states, states));
            add(c, b, vel, 2 * q, &proj(&(scale * psi_gain(&nb.a) * k_r)));
            if observer {
                add(c, b, vel, 2 * q + 1, &(&eye * k_w));
            }
        }
        add(&mut a0, b, pos, vel, &eye);
        add(&mut a0, b, vel, pos, &proj(&(scale * stiff * -k_r)));
        let damping = if !observer {
            proj(&(scale * -k_w))
        } else {
            &eye * (-k_w * damp)
        };
        add(&mut a0, b, vel, vel, &damping);
    }
    let coupling = links
        .values()
        .fold(DMatrix::zeros(states, states), |acc, a| acc + a);
    let profile = Profile::of(&a0, &coupling);
    Dense { a0, links, profile }
}

/// The per-axis trees: `Δ(s)` of the module docs of [`super::tree`] for
/// each axis; [`NotForest`] unless the graph is a forest.
pub(super) fn trees(
    net: &Network,
    observer: bool,
    (k_r, k_w): (f64, f64),
) -> Result<Vec<Block>, NotForest> {
    let index = net.index_by_id();
    let steps: Vec<u64> = net
        .agents
        .iter()
        .flat_map(|a| a.model.neighbours.iter())
        .map(|n| n.link.map_or(0, |l| l.delay))
        .collect::<BTreeSet<u64>>()
        .into_iter()
        .collect();
    let slot = |k: u64| steps.partition_point(|&x| x < k);
    (0..3)
        .map(|k| {
            let mut diag = Vec::with_capacity(net.agents.len());
            let mut entries = Vec::new();
            for (p, agent) in net.agents.iter().enumerate() {
                let m = &agent.model;
                let mut stiff = m.leader_gain.as_ref().map_or(0.0, |g| psi_gain(g)[(k, k)]);
                let mut damp = f64::from(u8::from(m.leader_gain.is_some()));
                for nb in &m.neighbours {
                    let e = psi_gain(&nb.a)[(k, k)];
                    stiff += e;
                    damp += 1.0;
                    let entry = Entry {
                        beta: if observer { k_w } else { 0.0 },
                        gamma: k_r * e,
                        delay: slot(nb.link.map_or(0, |l| l.delay)),
                    };
                    entries.push((p, index[&nb.id], entry));
                }
                diag.push(if observer {
                    [1.0, k_w * damp, k_r * stiff]
                } else {
                    [m.inertia.j[(k, k)], k_w, k_r * stiff]
                });
            }
            let tree = Tree::new(diag, &entries)?;
            Ok(Block {
                axis: Some(k),
                body: Body::Tree(TreeBody {
                    tree,
                    steps: steps.clone(),
                }),
            })
        })
        .collect()
}

/// Scheme 2's tracking roots (`Im ≥ 0`), their agent and axis (none for
/// scheme 3).
pub(super) fn tracking(
    net: &Network,
    observer: bool,
    split: bool,
) -> Vec<(Complex<f64>, u32, Option<usize>)> {
    let mut tracking = Vec::new();
    if observer {
        for agent in &net.agents {
            let m = &agent.model;
            let (kr, kw) = match m.scheme {
                Scheme::ObserverConstant { control, .. }
                | Scheme::ObserverTimeVarying { control, .. } => (control.k_r, control.k_w),
                Scheme::Observerless { control } => (control.k_r, control.k_w),
            };
            let e = psi_gain(&m.a_bar);
            if split {
                for k in 0..3 {
                    let j = m.inertia.j[(k, k)];
                    for z in quadratic_roots(kw / j, kr * e[(k, k)] / j) {
                        if z.im >= 0.0 {
                            tracking.push((z, m.id, Some(k)));
                        }
                    }
                }
            } else {
                let mut t = DMatrix::zeros(6, 6);
                t.view_mut((0, 3), (3, 3)).fill_with_identity();
                let jinv = m.inertia.j_inv;
                t.view_mut((3, 0), (3, 3))
                    .copy_from_slice((jinv * e * -kr).as_slice());
                t.view_mut((3, 3), (3, 3))
                    .copy_from_slice((jinv * -kw).as_slice());
                for z in roots::eigenvalues(&t) {
                    if z.im >= 0.0 {
                        tracking.push((z, m.id, None));
                    }
                }
            }
        }
    }
    tracking
}
