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
use super::error::{Impairment, LinearError};
use super::margin::{self, Margin};
use super::profile::Profile;
use super::roots::{self, MIN_ORDER};
use super::system::Dde;
use crate::link::Loss;
use crate::network::{Coupling, Network, Scheme};
use crate::stiffness::{psi_gain, quadratic_roots};
use nalgebra::{Complex, DMatrix, Matrix3};
use std::collections::BTreeMap;

/// The largest dense pseudospectral matrix computed ([`roots::size`]); a
/// network whose first two orders do not fit is refused
/// ([`LinearError::TooLarge`]).
pub const DENSE_LIMIT: usize = 1000;

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
    /// The Chebyshev order it was confirmed at (0: no delay, an eigenvalue).
    pub order: usize,
    /// Whether two Chebyshev orders agreed on it ([`roots::Found`]).
    pub converged: bool,
}

/// One decoupled system: an axis (or all three), the own-state terms and,
/// per follower-link delay in steps, the coupling terms.
#[derive(Debug, Clone, PartialEq)]
struct Block {
    axis: Option<usize>,
    a0: DMatrix<f64>,
    links: BTreeMap<u64, DMatrix<f64>>,
    /// `G(ω)` of the common-delay system ([`Profile`]).
    profile: Profile,
}

impl Block {
    /// The delay system at the network's own per-link delays.
    fn own(&self, dt: f64) -> Dde {
        let delayed = self
            .links
            .iter()
            .map(|(&k, a)| (k as f64 * dt, a.clone()))
            .collect();
        Dde::new(self.a0.clone(), delayed)
    }

    /// Every coupling term together (`A₁`).
    fn coupling(&self) -> DMatrix<f64> {
        let n = self.a0.nrows();
        self.links
            .values()
            .fold(DMatrix::zeros(n, n), |acc, a| acc + a)
    }

    /// The delay system with every follower link delayed by `d`.
    fn common(&self, d: f64) -> Dde {
        Dde::new(self.a0.clone(), vec![(d, self.coupling())])
    }
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

/// Whether `m` is diagonal (off-diagonal entries exactly 0).
fn diagonal(m: &Matrix3<f64>) -> bool {
    (0..3).all(|i| (0..3).all(|j| i == j || m[(i, j)] == 0.0))
}

/// Adds `v` to the `b × b` block of `m` at block row `r`, block column `c`.
fn add(m: &mut DMatrix<f64>, b: usize, r: usize, c: usize, v: &DMatrix<f64>) {
    let mut blk = m.view_mut((r * b, c * b), (b, b));
    blk += v;
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

    /// [`Self::of`] after the checks: per axis if `split`, else one system.
    fn build(
        net: &Network,
        part: Part,
        (k_r, k_w): (f64, f64),
        split: bool,
    ) -> Result<Self, LinearError> {
        let n_agents = net.agents.len();
        let b = if split { 1 } else { 3 };
        let states = 2 * b * n_agents;
        let index = net.index_by_id();
        let axes: Vec<Option<usize>> = if split {
            vec![Some(0), Some(1), Some(2)]
        } else {
            vec![None]
        };
        let mut blocks = Vec::with_capacity(axes.len());
        for &axis in &axes {
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
                let scale = if part == Part::Observerless {
                    if split {
                        Matrix3::from_diagonal(&m.inertia.j.diagonal().map(|j| 1.0 / j))
                    } else {
                        m.inertia.j_inv
                    }
                } else {
                    Matrix3::identity()
                };
                let mut stiff = m.leader_gain.as_ref().map_or(Matrix3::zeros(), psi_gain);
                let mut damp = if m.leader_gain.is_some() && part == Part::Observer {
                    1.0
                } else {
                    0.0
                };
                for nb in &m.neighbours {
                    stiff += psi_gain(&nb.a);
                    if part == Part::Observer {
                        damp += 1.0;
                    }
                    let q = index[&nb.id];
                    let steps = nb.link.map_or(0, |l| l.delay);
                    let c = links
                        .entry(steps)
                        .or_insert_with(|| DMatrix::zeros(states, states));
                    add(c, b, vel, 2 * q, &proj(&(scale * psi_gain(&nb.a) * k_r)));
                    if part == Part::Observer {
                        add(c, b, vel, 2 * q + 1, &(&eye * k_w));
                    }
                }
                add(&mut a0, b, pos, vel, &eye);
                add(&mut a0, b, vel, pos, &proj(&(scale * stiff * -k_r)));
                let damping = if part == Part::Observerless {
                    proj(&(scale * -k_w))
                } else {
                    &eye * (-k_w * damp)
                };
                add(&mut a0, b, vel, vel, &damping);
            }
            let coupling = links
                .values()
                .fold(DMatrix::zeros(states, states), |acc, a| acc + a);
            let common = Dde::new(a0.clone(), vec![(1.0, coupling.clone())]);
            let size = roots::size(&common, MIN_ORDER + MIN_ORDER / 2);
            if size > DENSE_LIMIT {
                return Err(LinearError::TooLarge {
                    states: size,
                    limit: DENSE_LIMIT,
                });
            }
            let profile = Profile::of(&a0, &coupling);
            blocks.push(Block {
                axis,
                a0,
                links,
                profile,
            });
        }
        let mut tracking = Vec::new();
        if part == Part::Observer {
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
        Ok(Self {
            part,
            agents: n_agents,
            dt: net.dt,
            blocks,
            tracking,
        })
    }

    /// The rightmost of the blocks' roots (each from `dde_of`) and the
    /// tracking roots.
    fn rightmost_with(&self, dde_of: impl Fn(&Block) -> Dde) -> Rightmost {
        let mut best: Option<Rightmost> = None;
        let mut consider = |r: Rightmost| {
            if best.is_none_or(|b| r.root.re > b.root.re) {
                best = Some(r);
            }
        };
        for blk in &self.blocks {
            let f = roots::rightmost_with(&dde_of(blk), &blk.profile, DENSE_LIMIT);
            consider(Rightmost {
                root: Root::from(f.root),
                part: self.part,
                axis: blk.axis,
                order: f.order,
                converged: f.converged,
            });
        }
        for &(z, agent, axis) in &self.tracking {
            consider(Rightmost {
                root: Root::from(z),
                part: Part::Tracking { agent },
                axis,
                order: 0,
                converged: true,
            });
        }
        best.unwrap_or(Rightmost {
            root: Root {
                re: f64::NEG_INFINITY,
                im: 0.0,
            },
            part: self.part,
            axis: None,
            order: 0,
            converged: true,
        })
    }

    /// The rightmost root of the closed loop at the network's own per-link
    /// delays, and where it came from.
    #[must_use]
    pub fn rightmost_detail(&self) -> Rightmost {
        self.rightmost_with(|b| b.own(self.dt))
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
        self.rightmost_with(|b| b.common(d))
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
    /// each decoupled system; scheme 2's tracking loops are delay-free).
    #[must_use]
    pub fn margin(&self) -> Margin {
        let tracking_unstable = self.tracking.iter().any(|(z, _, _)| z.re >= 0.0);
        let mut best: Option<Margin> = None;
        for blk in &self.blocks {
            match margin::common_delay_with(&blk.a0, &blk.coupling(), &blk.profile) {
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
            .map(|b| b.links.keys().map(|&k| k as f64 * self.dt).collect())
            .unwrap_or_default()
    }

    /// The delay systems at the network's own delays (one per axis, or one).
    #[must_use]
    pub fn systems(&self) -> Vec<Dde> {
        self.blocks.iter().map(|b| b.own(self.dt)).collect()
    }

    /// The delay systems with every follower link delayed by `d` seconds.
    #[must_use]
    pub fn systems_at(&self, d: f64) -> Vec<Dde> {
        self.blocks.iter().map(|b| b.common(d)).collect()
    }

    /// [`Self::of`] without the split into axes (the same roots; a check).
    #[cfg(test)]
    pub(crate) fn of_full(net: &Network) -> Result<Self, LinearError> {
        let me = Self::of(net)?;
        Self::build(net, me.part, me.loop_gains(net), false)
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
