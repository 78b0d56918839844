//! The model's seeded random streams: SplitMix64 (links, disturbances,
//! sensors) and the normal deviates drawn from it. `PROTOCOL.md` § 10.9
//! and § 10.12 give the arithmetic to the bit.

/// SplitMix64: a small, well-mixed, seedable stream (Steele et al. 2014).
#[derive(Debug, Clone, PartialEq)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate (Box–Muller, the cosine branch only; two
    /// draws): `√(−2 ln(1 − u₁)) · cos(2π u₂)`.
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.unit();
        let u2 = self.unit();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// Three standard normal deviates, x then y then z.
    pub fn normal3(&mut self) -> [f64; 3] {
        [self.normal(), self.normal(), self.normal()]
    }
}

/// Mixes a scenario seed with agent `agent`'s `k`-th random effect (its
/// disturbances in order, then its sensor) into that effect's seed. Kept
/// apart from [`crate::link::link_seed`]'s streams by the rotation.
#[must_use]
pub fn effect_seed(seed: u64, agent: u32, k: u32) -> u64 {
    let mut s = SplitMix64(seed ^ (u64::from(agent) << 32 | u64::from(k)).rotate_left(41));
    s.next_u64()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_deviates_have_the_moments_of_a_standard_normal() {
        let mut s = SplitMix64(7);
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|_| s.normal()).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.01, "variance {var}");
        let beyond = xs.iter().filter(|x| x.abs() > 1.959_964).count() as f64 / n as f64;
        assert!((beyond - 0.05).abs() < 0.003, "P(|x| > 1.96) = {beyond}");
    }

    #[test]
    fn effect_seeds_differ_per_agent_and_effect() {
        let a = effect_seed(1, 2, 0);
        assert_ne!(a, effect_seed(1, 2, 1));
        assert_ne!(a, effect_seed(1, 3, 0));
        assert_ne!(a, effect_seed(2, 2, 0));
    }
}
