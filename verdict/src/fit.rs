//! Least-squares straight line with the slope's standard error.

/// `y ≈ y_mean + slope·(t − t_mean)`, fitted by least squares.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Line {
    /// Fitted slope.
    pub slope: f64,
    /// Standard error of the slope (infinite with only two points).
    pub slope_se: f64,
    t_mean: f64,
    y_mean: f64,
}

impl Line {
    /// The line's value at `t`.
    pub fn at(&self, t: f64) -> f64 {
        self.y_mean + self.slope * (t - self.t_mean)
    }
}

/// Fits a line through the points `(t, y)`; `None` with fewer than two
/// points or when every `t` is the same.
pub(crate) fn fit_line(pts: &[(f64, f64)]) -> Option<Line> {
    let n = pts.len();
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let t_mean = pts.iter().map(|p| p.0).sum::<f64>() / nf;
    let y_mean = pts.iter().map(|p| p.1).sum::<f64>() / nf;
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for &(t, y) in pts {
        sxx += (t - t_mean) * (t - t_mean);
        sxy += (t - t_mean) * (y - y_mean);
    }
    if sxx.is_nan() || sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let mut line = Line {
        slope,
        slope_se: f64::INFINITY,
        t_mean,
        y_mean,
    };
    if n > 2 {
        let ssr: f64 = pts.iter().map(|&(t, y)| (y - line.at(t)).powi(2)).sum();
        line.slope_se = (ssr / (nf - 2.0) / sxx).sqrt();
    }
    Some(line)
}

#[cfg(test)]
mod tests {
    use super::fit_line;
    use approx::assert_relative_eq;

    #[test]
    fn exact_line_has_zero_error() {
        let pts: Vec<_> = (0..10)
            .map(|i| (f64::from(i), 2.0 - 0.5 * f64::from(i)))
            .collect();
        let l = fit_line(&pts).expect("fit");
        assert_relative_eq!(l.slope, -0.5, epsilon = 1e-12);
        assert_relative_eq!(l.at(4.0), 0.0, epsilon = 1e-12);
        assert!(l.slope_se < 1e-12);
    }

    #[test]
    fn standard_error_of_a_known_scatter() {
        // Residuals ±1 about y = t on t = 0..3: ssr = 4, sxx = 5,
        // se = sqrt(4 / 2 / 5).
        let pts = [(0.0, 1.0), (1.0, 0.0), (2.0, 3.0), (3.0, 2.0)];
        let l = fit_line(&pts).expect("fit");
        assert_relative_eq!(l.slope, 0.6, epsilon = 1e-12);
        let ssr: f64 = pts.iter().map(|&(t, y)| (y - l.at(t)).powi(2)).sum();
        assert_relative_eq!(l.slope_se, (ssr / 2.0 / 5.0).sqrt(), epsilon = 1e-12);
    }

    #[test]
    fn degenerate_inputs() {
        assert!(fit_line(&[(1.0, 1.0)]).is_none());
        assert!(fit_line(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
        let two = fit_line(&[(0.0, 0.0), (1.0, 2.0)]).expect("fit");
        assert_eq!(two.slope_se, f64::INFINITY);
    }
}
