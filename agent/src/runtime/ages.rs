//! The ages of information of one input in real time, binned for their
//! quantiles: 16 bins to an octave (each within 3.2 % of its midpoint)
//! from 2⁻³⁰ s (about 1 ns) to 2¹⁰ s, found from the bits of the age
//! (its exponent and the first four bits of its mantissa), so a stage pays
//! an increment, not a logarithm.

/// Octaves covered.
const OCTAVES: i64 = 40;
/// The first octave's exponent: 2⁻³⁰ s.
const LOWEST: i64 = -30;
/// Bins per octave (the mantissa's first `BITS` bits).
const BITS: u32 = 4;
const PER_OCTAVE: i64 = 1 << BITS;
const BINS: usize = (OCTAVES * PER_OCTAVE) as usize;

/// A histogram of ages, s.
#[derive(Debug, Clone)]
pub(crate) struct Ages {
    /// Ages below the first bin (zero included).
    below: u64,
    bins: Vec<u64>,
    count: u64,
}

impl Default for Ages {
    fn default() -> Self {
        Self {
            below: 0,
            bins: vec![0; BINS],
            count: 0,
        }
    }
}

impl Ages {
    /// Counts `age` (s; beyond the last bin counts in the last).
    pub(crate) fn record(&mut self, age: f64) {
        self.count += 1;
        match bin(age) {
            Some(i) => self.bins[i.min(BINS - 1)] += 1,
            None => self.below += 1,
        }
    }

    /// The `q`-quantile (0 < q ≤ 1): the midpoint of the bin holding the
    /// ⌈q·count⌉-th smallest age; `None` before any age.
    pub(crate) fn quantile(&self, q: f64) -> Option<f64> {
        if self.count == 0 {
            return None;
        }
        let rank = ((q * self.count as f64).ceil() as u64).clamp(1, self.count);
        let mut seen = self.below;
        if seen >= rank {
            return Some(0.0);
        }
        for (i, &n) in self.bins.iter().enumerate() {
            seen += n;
            if seen >= rank {
                return Some(midpoint(i));
            }
        }
        Some(midpoint(BINS - 1))
    }
}

/// The bin of `age`: `None` below 2⁻³⁰ s (or not a number).
fn bin(age: f64) -> Option<usize> {
    if age.is_nan() || age < f64::powi(2.0, LOWEST as i32) {
        return None;
    }
    let bits = age.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mantissa = ((bits >> (52 - BITS)) & (PER_OCTAVE as u64 - 1)) as i64;
    usize::try_from((exponent - LOWEST) * PER_OCTAVE + mantissa).ok()
}

/// The middle of bin `i`, s.
fn midpoint(i: usize) -> f64 {
    let (octave, m) = (i as i64 / PER_OCTAVE, i as i64 % PER_OCTAVE);
    let low = f64::powi(2.0, (octave + LOWEST) as i32);
    low * (1.0 + (m as f64 + 0.5) / PER_OCTAVE as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_are_within_their_bins_width_of_the_sorted_ages() {
        // ages from 1 µs to 50 ms, spread over octaves, in a scrambled order
        let mut ages: Vec<f64> = (0..20_000u64)
            .map(|i| 1e-6 * (1.0 + ((i * 7919) % 20_000) as f64 * 2.5))
            .collect();
        let mut h = Ages::default();
        ages.iter().for_each(|&a| h.record(a));
        ages.sort_by(f64::total_cmp);
        for q in [0.01, 0.5, 0.9, 0.99, 1.0] {
            let exact = ages[((q * ages.len() as f64).ceil() as usize).max(1) - 1];
            let got = h.quantile(q).unwrap();
            assert!(
                (got / exact - 1.0).abs() < 1.0 / 32.0 + 1e-12,
                "q {q}: {got} vs {exact}"
            );
        }
    }

    #[test]
    fn no_age_has_no_quantile_and_zero_ages_are_zero() {
        let mut h = Ages::default();
        assert_eq!(h.quantile(0.5), None);
        h.record(0.0);
        h.record(0.0);
        h.record(3e-3);
        assert_eq!(h.quantile(0.5), Some(0.0));
        let p99 = h.quantile(0.99).unwrap();
        assert!((p99 / 3e-3 - 1.0).abs() < 1.0 / 32.0, "{p99}");
        h.record(1e9); // beyond the last bin: counted in it
        assert!(h.quantile(1.0).unwrap() > 512.0);
    }
}
