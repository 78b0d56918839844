//! What `errors.svg` draws when there is too much to draw line by line: a
//! large network as the band of its agents' errors (smallest, median and
//! largest at each sample), and a long run's lines thinned to the extremes
//! of each stretch of samples. Either way the drawing keeps what a reader
//! looks for — the worst agent's error and where it peaks — and its size no
//! longer grows with the number of agents or samples.

use super::Series;

/// Networks of at most this many agents are drawn one line per agent
/// (with a legend entry each); larger ones as their band.
pub const EACH_AGENT_UP_TO: usize = 16;

/// The most points a drawn line keeps ([`decimate`]).
pub const POINTS_PER_LINE: usize = 2000;

/// The agents' errors of one quantity at each sample: smallest, median and
/// largest over the agents with a finite value there.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Band {
    /// Sample times, s.
    pub t: Vec<f64>,
    /// Smallest error.
    pub min: Vec<f64>,
    /// Median error (the upper one of an even count).
    pub median: Vec<f64>,
    /// Largest error.
    pub max: Vec<f64>,
}

/// The band of `pick` over `series` (sample k taken from every series that
/// has one; samples where no agent has a finite value are left out).
#[must_use]
pub fn band(series: &[Series], pick: impl Fn(&Series) -> &[f64]) -> Band {
    let longest = series.iter().max_by_key(|s| pick(s).len());
    let Some(times) = longest.map(|s| &s.t) else {
        return Band::default();
    };
    let mut out = Band::default();
    let mut column: Vec<f64> = Vec::with_capacity(series.len());
    for (k, &t) in times.iter().enumerate() {
        column.clear();
        let at_k = series.iter().filter_map(|s| pick(s).get(k).copied());
        column.extend(at_k.filter(|v| v.is_finite()));
        if column.is_empty() {
            continue;
        }
        let mid = column.len() / 2;
        let (below, &mut median, above) = column.select_nth_unstable_by(mid, f64::total_cmp);
        let min = below.iter().copied().fold(median, f64::min);
        let max = above.iter().copied().fold(median, f64::max);
        out.t.push(t);
        out.min.push(min);
        out.median.push(median);
        out.max.push(max);
    }
    out
}

/// The finite points of the line (`t`, `y`), thinned to at most about
/// `budget` points: split into `budget / 2` stretches of consecutive
/// samples, each keeps its smallest and its largest value, in time order.
/// A line of at most `budget` points is kept whole.
#[must_use]
pub fn decimate(t: &[f64], y: &[f64], budget: usize) -> Vec<(f64, f64)> {
    let finite = t.iter().zip(y).map(|(&t, &y)| (t, y));
    let finite = finite.filter(|(_, y)| y.is_finite());
    if t.len().min(y.len()) <= budget {
        return finite.collect();
    }
    let stretch = t.len().min(y.len()).div_ceil((budget / 2).max(1));
    let points: Vec<(f64, f64)> = finite.collect();
    let mut out = Vec::with_capacity(budget + 2);
    for chunk in points.chunks(stretch) {
        let by_y = |a: &&(f64, f64), b: &&(f64, f64)| a.1.total_cmp(&b.1);
        let lo = chunk.iter().enumerate().min_by(|a, b| by_y(&a.1, &b.1));
        let hi = chunk.iter().enumerate().max_by(|a, b| by_y(&a.1, &b.1));
        let (Some((i, &lo)), Some((j, &hi))) = (lo, hi) else {
            continue;
        };
        match i.cmp(&j) {
            std::cmp::Ordering::Less => out.extend([lo, hi]),
            std::cmp::Ordering::Greater => out.extend([hi, lo]),
            std::cmp::Ordering::Equal => out.push(lo),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn agent(id: u32, att: Vec<f64>) -> Series {
        Series {
            id,
            t: (0..att.len()).map(|k| k as f64).collect(),
            att,
            ..Series::default()
        }
    }

    #[test]
    fn the_band_is_the_smallest_median_and_largest_finite_error_at_each_sample() {
        let series = [
            agent(1, vec![3.0, 1.0, f64::NAN]),
            agent(2, vec![1.0, 5.0, f64::NAN]),
            agent(3, vec![2.0, f64::NAN, f64::NAN]),
            agent(4, vec![4.0, 2.0]),
        ];
        let b = band(&series, |s| &s.att);
        assert_eq!(b.t, [0.0, 1.0], "the all-NaN sample is left out");
        assert_eq!(b.min, [1.0, 1.0]);
        assert_eq!(b.median, [3.0, 2.0]);
        assert_eq!(b.max, [4.0, 5.0]);
    }

    #[test]
    fn thinning_keeps_every_stretchs_extremes_in_time_order() {
        let n = 10_000;
        let t: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let mut y: Vec<f64> = t.iter().map(|t| (t * 0.01).sin()).collect();
        y[1234] = 50.0;
        y[8765] = -50.0;
        y[4000] = f64::NAN;
        let thin = decimate(&t, &y, 200);
        assert!(thin.len() <= 202, "{} points", thin.len());
        assert!(
            thin.windows(2).all(|w| w[0].0 < w[1].0),
            "not in time order"
        );
        assert!(thin.contains(&(1234.0, 50.0)) && thin.contains(&(8765.0, -50.0)));
        assert!(thin.iter().all(|p| p.1.is_finite()));
        let short = decimate(&t[..150], &y[..150], 200);
        assert_eq!(short.len(), 150, "a short line is kept whole");
    }
}
