//! Pure model of leader-follower attitude synchronisation of rigid bodies on
//! SO(3), after "Leader-follower attitude synchronization of rigid-body
//! systems on SO(3)" (equation labels in the docs are that paper's
//! `\label{}` names; see `docs/paper.md` for the plain notation, a table of
//! the labels and where each is implemented, and the errata this crate
//! implements). `PROTOCOL.md` § 10 gives the arithmetic to the bit.
//!
//! No clock, no I/O, no transport: time and every input are parameters.
//!
//! # Layout
//! - [`so3`]: hat, vex, ψ, exp, log, `Rot(θ,u)`, `|R|_I`, `dexp⁻¹`.
//! - [`integrate`]: RKMK4 on SO(3)ⁿ × ℝ³ᵐ, driven stage by stage.
//! - [`body`]: rigid-body dynamics (eq. `followeri`).
//! - [`mod@reference`]: the leader (eq. `leader`).
//! - [`observer`]: eqs. `7a`–`7c`, `16a`–`16b`.
//! - [`control`]: eqs. `control` (corrected `sigmai`, `gammai`),
//!   `controlconstantestimate`, `districontrol`; the printed `sigmai`,
//!   `gammai` as a negative control ([`control::ControlLaw`]).
//! - [`actuator`]: actuator limits (the torque a body can apply);
//!   [`disturbance`]: torques from outside; [`sensor`]: what the law
//!   measures of its own body; [`effects`]: a body's non-ideal effects,
//!   grouped (with the inertia the law assumes), and their state.
//! - [`random`]: the seeded streams (SplitMix64, normal deviates).
//! - [`network`]: the resolved network every engine runs.
//! - [`link`]: delay, jitter, loss and per-link period, on the receiving side.
//! - [`timeline`]: events in steps: link outages, retunes, repoints.
//! - [`agent`]: one follower as a stage-by-stage stepper (the exchange protocol).
//! - [`verdict`]: the verdict on a follower's own published values, proven within a step.
//! - [`schedule`]: the stages `(n, s)` of a run and which are exchanges (every loop walks it).
//! - [`engine`]: all nodes in one process, in lockstep.
//! - [`guard`]: the envelope of a sane state; divergence as a typed failure.
//! - [`metrics`]: the reported errors.
//! - [`checks`]: the paper's conditions on gains and on `P`.
//! - [`stiffness`]: the fastest linear modes of each loop and RK4's largest stable `dt`.
//! - [`spectrum`]: extremes of `Ξ + LLᵀ` and Appendix `appenD`'s `F ≻ 0`, sparse (no dense matrix).
//! - [`linear`]: the closed loop linearised with communication delays: rightmost characteristic roots, exact delay margin.
//! - [`sparse`]: sparse symmetric `LDLᵀ` / block Cholesky in a minimum-degree order (no fill-in on a forest).

pub mod actuator;
pub mod agent;
pub mod body;
pub mod checks;
pub mod control;
pub mod disturbance;
pub mod effects;
pub mod engine;
pub mod guard;
pub mod integrate;
pub mod law;
pub mod linear;
pub mod link;
pub mod metrics;
pub mod network;
pub mod observer;
pub mod random;
pub mod reference;
pub mod schedule;
pub mod sensor;
pub mod so3;
pub mod sparse;
pub mod spectrum;
pub mod stiffness;
pub mod timeline;
pub mod verdict;
