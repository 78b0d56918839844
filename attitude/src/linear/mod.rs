//! The closed loop linearised about synchronisation **with communication
//! delays**: the rightmost characteristic roots of the linear delay system
//! and its exact delay margin.
//!
//! A network of scheme 2 (eqs. `16a`–`16b` with `controlconstantestimate`)
//! or scheme 3 (eq. `districontrol`) whose follower links delay by constant
//! whole steps linearises, at `Rᵢ = R₀` (`R̂ᵢ = R₀`), into a linear retarded
//! delay system ([`Dde`])
//!
//! ```text
//! z'(t) = A₀ z(t) + Σ_k A_k z(t − τ_k)
//! ```
//!
//! ([`Linearisation::of`]; the equations are in [`model`]'s docs). Then
//! - [`Linearisation::rightmost`]: its rightmost root at the network's own
//!   delays (pseudospectral discretisation + Newton, [`roots`]), and
//!   [`Linearisation::rightmost_at`] with every follower link delayed by `d`;
//! - [`Linearisation::margin`]: the smallest common delay at which a root
//!   reaches the imaginary axis (frequency sweep, [`margin`]).
//!
//! Refused ([`LinearError`]): scheme 1 (time-varying error dynamics),
//! sampled coupling (a hold, not a delay), a follower link with jitter, loss
//! or a period; networks whose decoupled system is too large for dense
//! matrices and that cannot take the tree path.
//!
//! # Large networks: the tree path
//! Where the dense discretisation would exceed [`model::DENSE_LIMIT`], a
//! network that splits per axis (diagonal inertias and gains) and whose
//! graph is a forest (Assumption 1) is analysed without any matrix of size
//! beyond `N`: per axis, `Δ(s)` is tree-structured ([`tree`]), so
//! `ln det Δ(s)` and its derivatives cost `O(N)` (leaves-first elimination,
//! no fill-in). The rightmost root is bracketed by counting roots right of
//! `Re s = σ` with the argument principle ([`contour`]) and found by Newton
//! on `ln det Δ` ([`tree_roots`]); the margin is where that count at
//! `σ = 0` first leaves 0 as the common delay grows, the crossing then
//! solved for `(ω, d)` by Newton ([`tree_margin`]). Up to
//! [`model::TREE_LIMIT`] agents; otherwise [`LinearError::TooLarge`].
//!
//! # Layout
//! - [`model`]: [`Linearisation`] from a [`crate::network::Network`].
//! - [`system`]: [`Dde`], its characteristic matrix and Newton's method.
//! - [`roots`]: the pseudospectral rightmost roots.
//! - [`margin`]: the delay margin by a frequency sweep.
//! - [`profile`]: `G(ω) = (iωI − A₀)⁻¹A₁` over frequency (the sweep's samples; how far the root search must resolve).
//! - [`cheb`]: Chebyshev nodes, differentiation, barycentric interpolation.
//! - [`eig`]: dense eigenvalues (real and complex QR with an iteration limit).
//! - [`error`]: why a network is refused.
//! - [`tree`]: one axis's `Δ(s)` on a forest, `ln det Δ` in `O(N)`.
//! - [`contour`]: counting zeros in a box by the argument principle.
//! - [`tree_roots`]: the rightmost root on the tree path.
//! - [`tree_margin`]: the delay margin on the tree path.

mod blocks;
pub mod cheb;
pub mod contour;
pub mod eig;
pub mod error;
pub mod margin;
pub mod model;
pub mod profile;
pub mod roots;
pub mod system;
pub mod tree;
pub mod tree_margin;
pub mod tree_roots;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tree_tests;

pub use error::{Impairment, LinearError};
pub use margin::Margin;
pub use model::{Linearisation, Part, Rightmost};
pub use system::Dde;

use nalgebra::Complex;

/// A characteristic root `re + i·im`, s⁻¹.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root {
    /// Real part: the decay (< 0) or growth (> 0) rate, s⁻¹.
    pub re: f64,
    /// Imaginary part: the angular frequency, rad/s.
    pub im: f64,
}

impl From<Complex<f64>> for Root {
    fn from(z: Complex<f64>) -> Self {
        Self { re: z.re, im: z.im }
    }
}

impl From<Root> for Complex<f64> {
    fn from(r: Root) -> Self {
        Complex::new(r.re, r.im)
    }
}

impl std::fmt::Display for Root {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.im == 0.0 {
            write!(f, "{:.6e}", self.re)
        } else {
            write!(f, "{:.6e} ± {:.6e}i", self.re, self.im.abs())
        }
    }
}
