//! The sampler of initial conditions: rotations Haar-uniform on SO(3) and
//! vectors with a uniform direction and a bounded norm. Pure: every
//! function takes the random stream.
//!
//! # NOTE
//! The common recipe "uniform axis, uniform angle in [0, π]" is **not**
//! uniform on SO(3): under the Haar measure the angle θ has the density
//! `(1 − cos θ)/π` (small rotations are rare), which that recipe
//! over-samples; Euler angles drawn uniformly (Basilisk's
//! `UniformEulerAngleMRPDispersion`) are not uniform either. A unit
//! quaternion uniform on S³ is Haar-uniform on SO(3) (S³ double-covers
//! SO(3) and both measures are the invariant ones); [`haar_quaternion`]
//! draws one exactly by Shoemake's subgroup algorithm.

use rand::Rng;
use std::f64::consts::TAU;

/// A unit quaternion `[w, x, y, z]` uniform on S³ (so its rotation is
/// Haar-uniform on SO(3)), with `w ≥ 0` (`q` and `−q` are one rotation).
///
/// # Equation
/// ```text
/// u₁, u₂, u₃ ~ U[0, 1)
/// q = ( √(1−u₁) sin 2πu₂, √(1−u₁) cos 2πu₂, √u₁ sin 2πu₃, √u₁ cos 2πu₃ )
/// ```
/// Source: K. Shoemake, "Uniform random rotations", Graphics Gems III (1992).
///
/// ```
/// use rand::SeedableRng;
/// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
/// let q = attsync::mc::haar_quaternion(&mut rng);
/// let norm: f64 = q.iter().map(|x| x * x).sum::<f64>().sqrt();
/// assert!((norm - 1.0).abs() < 1e-15 && q[0] >= 0.0);
/// ```
pub fn haar_quaternion(rng: &mut impl Rng) -> [f64; 4] {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let q = [
        b * (TAU * u3).cos(),
        a * (TAU * u2).sin(),
        a * (TAU * u2).cos(),
        b * (TAU * u3).sin(),
    ];
    if q[0] < 0.0 { q.map(|x| -x) } else { q }
}

/// A unit vector uniform on the sphere S² (Archimedes: `z` uniform in
/// [−1, 1], azimuth uniform).
pub fn unit_vector(rng: &mut impl Rng) -> [f64; 3] {
    let (u, v): (f64, f64) = (rng.random(), rng.random());
    let z = 1.0 - 2.0 * u;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * v;
    [r * phi.cos(), r * phi.sin(), z]
}

/// A vector with a direction uniform on S² and a norm uniform in
/// `[0, max]` (`max ≥ 0`; units those of `max`, e.g. rad/s).
pub fn bounded_vector(rng: &mut impl Rng, max: f64) -> [f64; 3] {
    debug_assert!(max >= 0.0);
    let u = unit_vector(rng);
    let norm = max * rng.random::<f64>();
    u.map(|x| x * norm)
}

/// The rotation angle θ ∈ [0, π] of unit quaternion `q = [w, x, y, z]`.
#[must_use]
pub fn angle_of(q: &[f64; 4]) -> f64 {
    let v = (q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    2.0 * v.atan2(q[0].abs())
}
