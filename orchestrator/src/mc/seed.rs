//! Per-trial seeds: trial `k` of a Monte Carlo with master seed `S` draws
//! from `ChaCha8Rng::seed_from_u64(trial_seed(S, k))`, so one trial is
//! reproducible from its seed alone, independently of every other trial
//! and of the number of workers.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// SplitMix64's increment (the golden ratio, 2⁶⁴/φ).
const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's output function (Steele, Lea & Flood 2014) of state `z`.
#[must_use]
pub fn mix(z: u64) -> u64 {
    let z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    let z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The seed of trial `k` (0-based): the (k+1)-th output of SplitMix64
/// seeded with `master`.
///
/// ```
/// // SplitMix64 seeded with 0: first output 0xE220A8397B1DCDAF.
/// assert_eq!(attsync::mc::trial_seed(0, 0), 0xE220_A839_7B1D_CDAF);
/// ```
#[must_use]
pub fn trial_seed(master: u64, k: u64) -> u64 {
    mix(master.wrapping_add(k.wrapping_add(1).wrapping_mul(GOLDEN)))
}

/// The random stream of a trial with seed `seed` (ChaCha with 8 rounds,
/// `rand_core`'s portable `seed_from_u64`).
#[must_use]
pub fn trial_rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_reference_outputs() {
        // The reference stream of SplitMix64 seeded with 1234567.
        let expected = [6457827717110365317_u64, 3203168211198807973];
        for (k, e) in expected.iter().enumerate() {
            assert_eq!(trial_seed(1234567, k as u64), *e);
        }
        assert_ne!(trial_seed(0, 1), trial_seed(1, 0));
    }
}
