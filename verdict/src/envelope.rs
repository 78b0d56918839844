//! The error's envelope: one point per block of the trailing window.

/// One block of the window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Block {
    /// Time of the block's envelope point.
    pub t: f64,
    /// The block's envelope point: its highest local peak, or its largest
    /// sample if it has no local peak (a monotone stretch).
    pub peak: f64,
    /// The block's largest sample.
    pub max: f64,
}

/// Splits the samples `start..` of `(t, x)` into `blocks` blocks of equal
/// duration and returns each non-empty block's envelope point.
///
/// A local peak (`x[i−1] < x[i] ≥ x[i+1]`, neighbours outside the block
/// included) lies on the envelope of an oscillation; a block's first or last
/// sample, on a flank, lies below it. For `A·e^{λt}·p(t)` with a periodic `p`
/// and blocks longer than its period, every block's point is the same peak
/// of `p` scaled by `e^{λt}`, so the points lie on a line of slope `λ` in
/// `ln x`; for a monotone signal they are samples of the signal itself.
pub(crate) fn blocks(t: &[f64], x: &[f64], start: usize, blocks: usize) -> Vec<Block> {
    let n = t.len().min(x.len());
    let mut out = Vec::with_capacity(blocks);
    if start >= n || blocks == 0 {
        return out;
    }
    let (t0, len) = (t[start], (t[n - 1] - t[start]) / blocks as f64);
    let mut cur = Acc::default();
    let mut cur_k = 0;
    for i in start..n {
        let k = if len > 0.0 {
            (((t[i] - t0) / len) as usize).min(blocks - 1)
        } else {
            0
        };
        if k != cur_k {
            out.extend(cur.finish());
            (cur, cur_k) = (Acc::default(), k);
        }
        cur.add(t[i], x[i], is_local_peak(&x[..n], i));
    }
    out.extend(cur.finish());
    out
}

/// `x[i−1] < x[i] ≥ x[i+1]` (the first sample of a flat top counts).
fn is_local_peak(x: &[f64], i: usize) -> bool {
    i > 0 && i + 1 < x.len() && x[i] > x[i - 1] && x[i] >= x[i + 1]
}

/// A block being read: its largest sample and its highest local peak.
#[derive(Default)]
struct Acc {
    max: Option<(f64, f64)>,
    peak: Option<(f64, f64)>,
}

impl Acc {
    fn add(&mut self, t: f64, x: f64, local_peak: bool) {
        if self.max.is_none_or(|m| x > m.1) {
            self.max = Some((t, x));
        }
        if local_peak && self.peak.is_none_or(|p| x > p.1) {
            self.peak = Some((t, x));
        }
    }

    fn finish(&self) -> Option<Block> {
        let max = self.max?;
        let (t, peak) = self.peak.unwrap_or(max);
        Some(Block {
            t,
            peak,
            max: max.1,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::blocks;
    use approx::assert_relative_eq;

    #[test]
    fn a_monotone_decay_gives_each_block_start() {
        let t: Vec<f64> = (0..100).map(f64::from).collect();
        let x: Vec<f64> = t.iter().map(|&t| (-0.1 * t).exp()).collect();
        let b = blocks(&t, &x, 50, 5);
        assert_eq!(b.len(), 5);
        assert_eq!(b[0].t, 50.0);
        assert_eq!(b[1].t, 60.0);
        assert_eq!(b[0].peak, b[0].max);
    }

    #[test]
    fn a_flank_at_a_block_start_is_not_the_envelope() {
        // Block starts just after a peak: its first sample is higher than
        // its interior peak, but the interior peak is the envelope point.
        let x = [0.0, 1.0, 0.9, 0.0, 0.8, 0.0, 0.6, 0.0];
        let t: Vec<f64> = (0..8).map(f64::from).collect();
        let b = blocks(&t, &x, 2, 2);
        assert_eq!(b.len(), 2);
        assert_relative_eq!(b[0].peak, 0.8);
        assert_relative_eq!(b[0].max, 0.9);
        assert_relative_eq!(b[0].t, 4.0);
    }
}
