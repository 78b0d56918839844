//! The linearisation of a [`Network`] about synchronisation, with its
//! communication delays: [`Linearisation`].
//!
//! With `Rᵢ = R₀ exp(xᵢ^×)` (or `R̂ᵢ` for the observer), `Rⱼᵀ Rᵢ ≈ I +
//! (xᵢ − xⱼ)^×` and, for symmetric `A`, `ψ(A exp(δ^×)) = E(A) δ + O(|δ|²)`,
//! `E(A) = ½ (tr(A) I − A)` ([`crate::stiffness::psi_gain`]). A link
//! `j → i` with a constant delay of `k` steps makes agent `i` use `xⱼ(t − k·dt)`
//! (the engine runs RK4 on this delay equation by the method of steps,
//! [`crate::link`]). The reference is constant, so a leader link's delay
//! (or any other impairment of it) changes nothing.
//!
//! ```text
//! districontrol:  ẋᵢ = ωᵢ
//!                 Jᵢ ω̇ᵢ = −k_Ř Ξᵢ E(Ǎ_{i0}) xᵢ − k_Ř Σ_{j∈N(i)} E(Ǎ_{ij}) (xᵢ(t) − xⱼ(t − d_{j→i})) − k_ω̌ ωᵢ
//! 16a–16b:        ẋᵢ = ω̂ᵢ
//!                 dω̂ᵢ/dt = −k_R Σ_j E(A_{ij}) (xᵢ(t) − xⱼ(t − d_{j→i})) − k_ω Σ_j (ω̂ᵢ(t) − ω̂ⱼ(t − d_{j→i}))
//!                          − k_R Ξᵢ E(A_{i0}) xᵢ − k_ω Ξᵢ ω̂ᵢ
//! controlerror2:  Jᵢ ε̈ᵢ = −k_R̄ E(Āᵢ) εᵢ − k_ω̄ ε̇ᵢ          (scheme 2's bodies, delay-free)
//! ```
//!
//! The gyroscopic `ωᵢ × Jᵢ ωᵢ` is quadratic and drops; so does the
//! difference of the printed `Γᵢ` (`2 vᵢ × Jᵢ vᵢ`, `law = as-printed`).
//! Scheme 2 is a cascade: the bodies track their observers through the
//! autonomous loop `controlerror2`, so the closed loop's roots are the
//! observer system's and every agent's tracking roots.
//!
//! When every `Jᵢ` and every gain matrix is diagonal, `E(·)` is diagonal
//! and the system splits into 3 independent per-axis systems of `2N` states
//! (`E(diag(a₁, a₂, a₃)) = ½ diag(a₂+a₃, a₁+a₃, a₁+a₂)`); otherwise one
//! system of `6N`. States are ordered agent by agent, `[xᵢ, ωᵢ]`.

use super::Root;
use super::blocks::{self, Block, Body, Delays, diagonal};
use super::error::{Impairment, LinearError};
use super::margin::{self, Margin};
use super::roots;
use super::system::Dde;
use super::tree_margin;
use super::tree_roots::Search;
use crate::link::Loss;
use crate::network::{Coupling, Network, Scheme};
use nalgebra::Complex;

/// The largest dense pseudospectral matrix computed ([`roots::size`]): a
/// network whose first two orders may not fit (counting every agent some
/// agent hears as delayed) goes to the tree path ([`super::tree`]) if it
/// splits per axis and its graph is a forest, else is refused
/// ([`LinearError::TooLarge`]).
pub const DENSE_LIMIT: usize = 1000;

/// Above this dense size a network that can take the tree path takes it:
/// the dense method's cost grows as the cube of its size (0.03 s at 140,
/// 0.5 s at 400, 12 s at 1000 on the 2-core reference machine), the tree
/// path's about linearly with the agents (BENCHMARKS.md).
pub const DENSE_PREFERRED: usize = 300;

/// The most agents the tree path takes (`O(N)` memory and work per
/// evaluation of `det Δ`; beyond, [`LinearError::TooLarge`]).
pub const TREE_LIMIT: usize = 200_000;

/// Which part of the closed loop a root belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The observer delay system (eqs. `16a`–`16b`, scheme 2).
    Observer,
    /// The bodies under the observerless law (eq. `districontrol`, scheme 3).
    Observerless,
    /// Agent `agent`'s tracking loop (eq. `controlerror2`, scheme 2).
    Tracking {
        /// The agent's id.
        agent: u32,
    },
}

/// The rightmost root of the closed loop and where it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rightmost {
    /// The root (of a conjugate pair, the one with `Im ≥ 0`).
    pub root: Root,
    /// The part of the closed loop it belongs to.
    pub part: Part,
    /// The axis (0, 1, 2) of a per-axis system, `None` for a full one.
    pub axis: Option<usize>,
    /// The Chebyshev order it was confirmed at (0: no discretisation: no
    /// delay, an eigenvalue; or the tree path, [`super::tree_roots`]).
    pub order: usize,
    /// Whether two Chebyshev orders agreed on it ([`roots::Found`]), or
    /// (tree path) the count of roots right of it certified it.
    pub converged: bool,
}

/// The closed loop linearised about synchronisation, with its delays.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearisation {
    part: Part,
    agents: usize,
    dt: f64,
    blocks: Vec<Block>,
    /// Scheme 2: every tracking root (`Im ≥ 0`), its agent and axis.
    tracking: Vec<(Complex<f64>, u32, Option<usize>)>,
}

impl Linearisation {
    /// The linearisation of `net` (schemes 2 and 3, continuous coupling,
    /// follower links with at most a constant delay).
    pub fn of(net: &Network) -> Result<Self, LinearError> {
        let first = net.agents.first().ok_or(LinearError::NoAgents)?;
        let (part, loop_gains) = match first.model.scheme {
            Scheme::ObserverTimeVarying { .. } => return Err(LinearError::TimeVarying),
            Scheme::ObserverConstant { observer, .. } => {
                (Part::Observer, (observer.k_r, observer.k_w))
            }
            Scheme::Observerless { control } => (Part::Observerless, (control.k_r, control.k_w)),
        };
        if let Coupling::Sampled { every } = net.coupling {
            return Err(LinearError::Sampled { every });
        }
        let index = net.index_by_id();
        for a in &net.agents {
            for nb in &a.model.neighbours {
                if !index.contains_key(&nb.id) {
                    return Err(LinearError::UnknownNeighbour {
                        agent: a.model.id,
                        neighbour: nb.id,
                    });
                }
                let Some(link) = nb.link else { continue };
                let what = if link.jitter > 0 {
                    Some(Impairment::Jitter { steps: link.jitter })
                } else if link.loss != Loss::None {
                    Some(Impairment::Loss)
                } else {
                    link.period.map(|steps| Impairment::Period { steps })
                };
                if let Some(what) = what {
                    return Err(LinearError::Impaired {
                        from: nb.id,
                        to: a.model.id,
                        what,
                    });
                }
            }
        }
        let split = net.agents.iter().all(|a| {
            let m = &a.model;
            diagonal(&m.inertia.j)
                && (part == Part::Observerless || diagonal(&m.a_bar))
                && m.leader_gain.as_ref().is_none_or(diagonal)
                && m.neighbours.iter().all(|n| diagonal(&n.a))
        });
        Self::build(net, part, loop_gains, split)
    }

    /// [`Self::of`] after the checks: per axis if `split`, else one system;
    /// dense while the discretisation fits ([`blocks::dense_size`]), else
    /// the tree path.
    fn build(
        net: &Network,
        part: Part,
        gains: (f64, f64),
        split: bool,
    ) -> Result<Self, LinearError> {
        let observer = part == Part::Observer;
        let size = blocks::dense_size(net, observer, split);
        let tree = (size > DENSE_PREFERRED && split && net.agents.len() <= TREE_LIMIT)
            .then(|| blocks::trees(net, observer, gains).ok())
            .flatten();
        let blocks = match tree {
            Some(trees) => trees,
            None if size <= DENSE_LIMIT => blocks::dense(net, observer, gains, split),
            None => {
                return Err(LinearError::TooLarge {
                    states: size,
                    limit: DENSE_LIMIT,
                });
            }
        };
        Ok(Self {
            part,
            agents: net.agents.len(),
            dt: net.dt,
            blocks,
            tracking: blocks::tracking(net, part == Part::Observer, split),
        })
    }

    /// The rightmost root of one block at `which` delays; `None` for a
    /// tree with no root right of `floor` (the rightmost found so far).
    fn block_rightmost(&self, blk: &Block, which: Delays, floor: Option<f64>) -> Option<Rightmost> {
        let (root, order, converged) = match &blk.body {
            Body::Dense(b) => {
                let dde = blk.dde(self.dt, which);
                let f = roots::rightmost_with(&dde, &b.profile, DENSE_LIMIT);
                (f.root, f.order, f.converged)
            }
            Body::Tree(t) => {
                let search = Search::new(&t.tree, t.taus(self.dt, which));
                if let Some(x) = floor {
                    if search.right_of(x).is_some_and(|r| r.count == 0) {
                        return None;
                    }
                }
                match search.rightmost() {
                    Some(z) => (z, 0, true),
                    None => (Complex::new(f64::NAN, f64::NAN), 0, false),
                }
            }
        };
        Some(Rightmost {
            root: Root::from(root),
            part: self.part,
            axis: blk.axis,
            order,
            converged,
        })
    }

    /// The rightmost of the blocks' roots at `which` delays and the
    /// tracking roots (not `converged` if a tree's search failed: its
    /// roots are unknown).
    fn rightmost_with(&self, which: Delays) -> Rightmost {
        let tracking = self.tracking.iter().map(|&(z, agent, axis)| Rightmost {
            root: Root::from(z),
            part: Part::Tracking { agent },
            axis,
            order: 0,
            converged: true,
        });
        let mut floor = tracking.clone().map(|r| r.root.re).reduce(f64::max);
        let mut best: Option<Rightmost> = None;
        let mut failed = false;
        let mut consider = |r: Rightmost| {
            if best.is_none_or(|b| r.root.re > b.root.re) {
                best = Some(r);
            }
        };
        for blk in &self.blocks {
            if let Some(r) = self.block_rightmost(blk, which, floor) {
                failed |= r.root.re.is_nan();
                if !r.root.re.is_nan() {
                    floor = Some(floor.map_or(r.root.re, |f| f.max(r.root.re)));
                    consider(r);
                }
            }
        }
        tracking.for_each(&mut consider);
        let mut out = best.unwrap_or(Rightmost {
            root: Root {
                re: if failed { f64::NAN } else { f64::NEG_INFINITY },
                im: 0.0,
            },
            part: self.part,
            axis: None,
            order: 0,
            converged: !failed,
        });
        out.converged &= !failed;
        out
    }

    /// The rightmost root of the closed loop at the network's own per-link
    /// delays, and where it came from.
    #[must_use]
    pub fn rightmost_detail(&self) -> Rightmost {
        self.rightmost_with(Delays::Own)
    }

    /// The rightmost root of the closed loop with every follower link
    /// delayed by `d` seconds (leader links do not matter), and where it
    /// came from. Panics unless `d` is finite and ≥ 0.
    #[must_use]
    pub fn rightmost_detail_at(&self, d: f64) -> Rightmost {
        assert!(
            d.is_finite() && d >= 0.0,
            "delay {d} must be finite and ≥ 0"
        );
        self.rightmost_with(Delays::Common(d))
    }

    /// The rightmost root (largest real part; `Im ≥ 0`) at the network's own
    /// per-link delays.
    #[must_use]
    pub fn rightmost(&self) -> Root {
        self.rightmost_detail().root
    }

    /// The rightmost root with every follower link delayed by `d` seconds.
    #[must_use]
    pub fn rightmost_at(&self, d: f64) -> Root {
        self.rightmost_detail_at(d).root
    }

    /// The delay margin: the smallest common delay of every follower link at
    /// which a root reaches the imaginary axis ([`margin::common_delay`] on
    /// each dense decoupled system, [`tree_margin::margin`] on each tree;
    /// scheme 2's tracking loops are delay-free).
    #[must_use]
    pub fn margin(&self) -> Margin {
        let tracking_unstable = self.tracking.iter().any(|(z, _, _)| z.re >= 0.0);
        let mut best: Option<Margin> = None;
        for blk in &self.blocks {
            let m = match &blk.body {
                Body::Dense(b) => margin::common_delay_with(&b.a0, &b.coupling(), &b.profile),
                Body::Tree(t) => {
                    let cap = match best {
                        Some(Margin::Crossing { delay, .. }) => Some(delay),
                        _ => None,
                    };
                    tree_margin::margin(&t.tree, || self.rightmost_at(0.0), cap)
                }
            };
            match m {
                Margin::UnstableWithoutDelay { .. } => {
                    return Margin::UnstableWithoutDelay {
                        rightmost: self.rightmost_at(0.0),
                    };
                }
                m @ Margin::Crossing { delay, .. } => {
                    let better = match best {
                        Some(Margin::Crossing { delay: b, .. }) => delay < b,
                        _ => true,
                    };
                    if better {
                        best = Some(m);
                    }
                }
                Margin::DelayIndependent => {}
            }
        }
        if tracking_unstable {
            return Margin::UnstableWithoutDelay {
                rightmost: self.rightmost_at(0.0),
            };
        }
        best.unwrap_or(Margin::DelayIndependent)
    }

    /// The dimension of the linear system: `6N` (scheme 3), `12N` (scheme 2:
    /// the observer's `6N` and the bodies' tracking errors `6N`).
    #[must_use]
    pub fn states(&self) -> usize {
        let per = 6 * self.agents;
        if self.part == Part::Observer {
            2 * per
        } else {
            per
        }
    }

    /// Whether the system split into 3 per-axis systems of `2N` states.
    #[must_use]
    pub fn per_axis(&self) -> bool {
        self.blocks.len() == 3
    }

    /// The loop with the delays: [`Part::Observer`] or [`Part::Observerless`].
    #[must_use]
    pub fn part(&self) -> Part {
        self.part
    }

    /// The distinct delays of the follower links, s, increasing (0 for an
    /// undelayed link).
    #[must_use]
    pub fn delays(&self) -> Vec<f64> {
        self.blocks
            .first()
            .map(|b| b.steps().iter().map(|&k| k as f64 * self.dt).collect())
            .unwrap_or_default()
    }

    /// The delay systems at the network's own delays (one per axis, or one).
    #[must_use]
    pub fn systems(&self) -> Vec<Dde> {
        self.blocks
            .iter()
            .map(|b| b.dde(self.dt, Delays::Own))
            .collect()
    }

    /// The delay systems with every follower link delayed by `d` seconds.
    #[must_use]
    pub fn systems_at(&self, d: f64) -> Vec<Dde> {
        self.blocks
            .iter()
            .map(|b| b.dde(self.dt, Delays::Common(d)))
            .collect()
    }

    /// [`Self::of`] without the split into axes (the same roots; a check).
    #[cfg(test)]
    pub(crate) fn of_full(net: &Network) -> Result<Self, LinearError> {
        let me = Self::of(net)?;
        Self::build(net, me.part, me.loop_gains(net), false)
    }

    /// [`Self::of`] on the dense path whatever the size (the reference the
    /// tree path is checked against).
    #[cfg(test)]
    pub(crate) fn of_dense(net: &Network) -> Result<Self, LinearError> {
        let me = Self::of(net)?;
        let split = me.per_axis();
        let observer = me.part == Part::Observer;
        let blocks = blocks::dense(net, observer, me.loop_gains(net), split);
        Ok(Self { blocks, ..me })
    }

    /// [`Self::of`] on the tree path whatever the size (a check against
    /// the dense path).
    #[cfg(test)]
    pub(crate) fn of_tree(net: &Network) -> Result<Self, LinearError> {
        let me = Self::of(net)?;
        let observer = me.part == Part::Observer;
        let blocks = blocks::trees(net, observer, me.loop_gains(net)).map_err(|_| {
            LinearError::TooLarge {
                states: 0,
                limit: 0,
            }
        })?;
        Ok(Self { blocks, ..me })
    }

    /// The trees of the tree path's blocks.
    #[cfg(test)]
    pub(crate) fn trees(&self) -> Vec<super::tree::Tree> {
        self.blocks
            .iter()
            .filter_map(|b| match &b.body {
                Body::Tree(t) => Some(t.tree.clone()),
                Body::Dense(_) => None,
            })
            .collect()
    }

    /// Whether every decoupled system is on the tree path.
    #[cfg(test)]
    pub(crate) fn on_trees(&self) -> bool {
        self.blocks.iter().all(|b| matches!(b.body, Body::Tree(_)))
    }

    #[cfg(test)]
    fn loop_gains(&self, net: &Network) -> (f64, f64) {
        match net.agents[0].model.scheme {
            Scheme::ObserverConstant { observer, .. } => (observer.k_r, observer.k_w),
            Scheme::Observerless { control } => (control.k_r, control.k_w),
            Scheme::ObserverTimeVarying { .. } => unreachable!(),
        }
    }
}
