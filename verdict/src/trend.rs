//! The envelope's exponential trend over the window, and what it amounts to.

use crate::envelope::Block;
use crate::fit::{Line, fit_line};
use crate::thresholds::Thresholds;

/// The least-squares line through `ln(peak)` of the blocks above the floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Trend {
    /// Slope of `ln(envelope)`, 1/s (negative = decaying).
    pub rate: f64,
    /// Its standard error, 1/s.
    pub rate_se: f64,
    /// `rate · window length`: the fitted change of `ln(envelope)` over the
    /// window.
    pub change: f64,
    /// `significance ·` the standard error of `change`.
    pub uncertainty: f64,
    /// The fitted envelope at the window's end.
    pub end: f64,
    /// The rates of the first and the last half of the points, when each
    /// half has at least 3 points.
    pub halves: Option<[f64; 2]>,
    /// Whether those rates differ significantly (by more than `significance`
    /// standard errors of the difference) and by more than `rate_agreement`
    /// times `|rate|`: the envelope is not one exponential over the window.
    pub bends: bool,
}

/// What a trend amounts to against the thresholds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Shape {
    /// Sign established, `|change| ≥ trend_change`, not bending; decaying.
    Decaying,
    /// Sign established, `|change| ≥ trend_change`, not bending; growing.
    Growing,
    /// `|change| + uncertainty < trend_change`, and either the sign is not
    /// established or `|change| < flat_change`.
    Flat,
    /// Sign established, `flat_change ≤ |change| < trend_change`.
    Slow,
    /// Sign established, `|change| ≥ trend_change`, but the rates of the
    /// window's two halves differ.
    Bending,
    /// Sign not established and a trend of `trend_change` not excluded.
    Unresolved,
}

impl Trend {
    /// Fits the blocks whose peak is above `th.floor` (at least 3 needed)
    /// over the window `[start, end]`.
    pub fn fit(blocks: &[Block], window: [f64; 2], th: &Thresholds) -> Option<Trend> {
        let pts: Vec<(f64, f64)> = blocks
            .iter()
            .filter(|b| b.peak > th.floor)
            .map(|b| (b.t, b.peak.ln()))
            .collect();
        if pts.len() < 3 {
            return None;
        }
        let line = fit_line(&pts)?;
        let span = window[1] - window[0];
        let halves = halves(&pts);
        let bends = halves.is_some_and(|[a, b]| {
            let diff = (a.slope - b.slope).abs();
            let se = a.slope_se.hypot(b.slope_se);
            diff > th.significance * se && diff > th.rate_agreement * line.slope.abs()
        });
        Some(Trend {
            rate: line.slope,
            rate_se: line.slope_se,
            change: line.slope * span,
            uncertainty: th.significance * line.slope_se * span,
            end: line.at(window[1]).exp(),
            halves: halves.map(|[a, b]| [a.slope, b.slope]),
            bends,
        })
    }

    /// Sorts the trend by the rules of [`Shape`].
    pub fn shape(&self, th: &Thresholds) -> Shape {
        let (a, u) = (self.change.abs(), self.uncertainty);
        let established = a > u;
        if established && a >= th.trend_change {
            match (self.bends, self.change < 0.0) {
                (true, _) => Shape::Bending,
                (false, true) => Shape::Decaying,
                (false, false) => Shape::Growing,
            }
        } else if a + u < th.trend_change && (!established || a < th.flat_change) {
            Shape::Flat
        } else if established {
            Shape::Slow
        } else {
            Shape::Unresolved
        }
    }
}

/// Lines through the first and the last `⌊n/2⌋` points, if that is ≥ 3.
fn halves(pts: &[(f64, f64)]) -> Option<[Line; 2]> {
    let m = pts.len() / 2;
    if m < 3 {
        return None;
    }
    Some([fit_line(&pts[..m])?, fit_line(&pts[pts.len() - m..])?])
}

#[cfg(test)]
mod tests {
    use super::{Shape, Trend};
    use crate::Thresholds;
    use crate::envelope::Block;

    fn trend(change: f64, uncertainty: f64, bends: bool) -> Trend {
        Trend {
            rate: change / 10.0,
            rate_se: uncertainty / 30.0,
            change,
            uncertainty,
            end: 1.0,
            halves: None,
            bends,
        }
    }

    #[test]
    fn shapes_by_the_rules() {
        let th = Thresholds::default();
        let shape = |c, u| trend(c, u, false).shape(&th);
        assert_eq!(shape(-0.5, 0.01), Shape::Decaying);
        assert_eq!(shape(0.5, 0.01), Shape::Growing);
        assert_eq!(shape(0.0, 0.0), Shape::Flat);
        assert_eq!(shape(0.005, 1e-9), Shape::Flat);
        assert_eq!(shape(0.03, 0.05), Shape::Flat);
        assert_eq!(shape(-0.04, 1e-9), Shape::Slow);
        assert_eq!(shape(0.03, 0.09), Shape::Unresolved);
        assert_eq!(shape(-0.5, 0.6), Shape::Unresolved);
        assert_eq!(shape(0.005, 0.2), Shape::Unresolved);
        assert_eq!(trend(0.5, 0.01, true).shape(&th), Shape::Bending);
    }

    fn blocks(f: impl Fn(f64) -> f64) -> Vec<Block> {
        (0..12)
            .map(|k| {
                let t = 50.0 + 5.0 * f64::from(k);
                Block {
                    t,
                    peak: f(t),
                    max: f(t),
                }
            })
            .collect()
    }

    #[test]
    fn one_exponential_does_not_bend_a_changing_rate_does() {
        let th = Thresholds::default();
        let w = [50.0, 110.0];
        let exp = Trend::fit(&blocks(|t| (-0.05 * t).exp()), w, &th).expect("fit");
        assert!(!exp.bends, "{exp:?}");
        assert!((exp.change + 3.0).abs() < 1e-9, "{exp:?}");
        // A hump: rising then falling.
        let hump = Trend::fit(&blocks(|t| (-((t - 70.0) / 30.0).powi(2)).exp()), w, &th);
        assert!(hump.expect("fit").bends);
        // Everything at the floor: no fit.
        assert_eq!(Trend::fit(&blocks(|_| 1e-15), w, &th), None);
    }
}
