//! `attsync margin`: the closed loop linearised about synchronisation with
//! every link delayed as the engine delays it ([`attitude::linear`]), its
//! delay margin (the smallest common delay at which a characteristic root
//! reaches the imaginary axis), the crossing frequency, and the rightmost
//! root at the scenario's own delays — the decay rate a run should show
//! (`docs/verdicts.md`).

use crate::scenario::Loaded;
use attitude::linear::{LinearError, Linearisation, Margin, Part, Root};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;
use thiserror::Error;

/// The scenario cannot be linearised (exit code 2, nothing written).
#[derive(Debug, Error)]
#[error("{}: {}{reason}", file.display(), field.map_or(String::new(), |f| format!("{f}: ")))]
pub struct MarginError {
    /// The scenario file.
    pub file: PathBuf,
    /// The field to blame, where one is.
    pub field: Option<&'static str>,
    /// Why.
    pub reason: LinearError,
}

/// What `attsync margin` found.
#[derive(Debug, Clone, PartialEq)]
pub struct MarginReport {
    /// The scenario's name.
    pub scenario: String,
    /// The margin.
    pub margin: Margin,
    /// The rightmost root at the scenario's own delays.
    pub rightmost: Root,
    /// Where it came from.
    pub part: Part,
    /// The scenario's distinct follower-link delays, s.
    pub delays: Vec<f64>,
    /// Dimension of the linear system.
    pub states: usize,
    /// Wall time of the analysis, s.
    pub seconds: f64,
}

/// `--json`: `margin`, `omega` and `rightmost` (names fixed).
#[derive(Debug, Clone, Serialize)]
pub struct MarginJson {
    /// The scenario's name.
    pub scenario: String,
    /// The delay margin, s: `null` when stable for every delay; 0 when
    /// unstable without delay.
    pub margin: Option<f64>,
    /// The crossing frequency, rad/s (`null` without a crossing).
    pub omega: Option<f64>,
    /// The rightmost root at the scenario's own delays, 1/s (`re < 0`:
    /// the error decays like `e^{re·t}`; `im`: its angular frequency, rad/s,
    /// the one with `im ≥ 0` of a conjugate pair).
    pub rightmost: RootJson,
    /// `crossing`, `delay-independent` or `unstable-without-delay`.
    pub kind: &'static str,
    /// Where the rightmost root comes from: `observer`, `observerless`,
    /// `tracking-<agent>`.
    pub rightmost_part: String,
    /// The scenario's distinct follower-link delays, s.
    pub delays: Vec<f64>,
    /// Dimension of the linear system.
    pub states: usize,
}

/// A root as JSON.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RootJson {
    /// Real part, 1/s.
    pub re: f64,
    /// Imaginary part, rad/s.
    pub im: f64,
}

/// Linearises `loaded` and computes its margin and rightmost root.
///
/// # Errors
/// The scenario cannot be linearised: scheme 1, sampled coupling, a link
/// with jitter, loss or a period, or a network too large.
pub fn margin(loaded: &Loaded) -> Result<MarginReport, MarginError> {
    let started = Instant::now();
    let lin = Linearisation::of(&loaded.resolved.network).map_err(|reason| MarginError {
        file: loaded.file.clone(),
        field: reason.field(),
        reason,
    })?;
    let detail = lin.rightmost_detail();
    let margin = lin.margin();
    Ok(MarginReport {
        scenario: loaded.name(),
        margin,
        rightmost: detail.root,
        part: detail.part,
        delays: lin.delays().into_iter().map(clean).collect(),
        states: lin.states(),
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// A delay `k · dt` without binary noise (0.35, not 0.35000000000000003).
fn clean(d: f64) -> f64 {
    format!("{d:.12}").parse().unwrap_or(d)
}

fn part_name(p: Part) -> String {
    match p {
        Part::Observer => "observer".into(),
        Part::Observerless => "observerless".into(),
        Part::Tracking { agent } => format!("tracking-{agent}"),
    }
}

impl MarginReport {
    /// The `--json` document.
    #[must_use]
    pub fn json(&self) -> MarginJson {
        let (margin, omega, kind) = match self.margin {
            Margin::Crossing { delay, omega, .. } => (Some(delay), Some(omega), "crossing"),
            Margin::DelayIndependent => (None, None, "delay-independent"),
            Margin::UnstableWithoutDelay { .. } => (Some(0.0), None, "unstable-without-delay"),
        };
        MarginJson {
            scenario: self.scenario.clone(),
            margin,
            omega,
            rightmost: RootJson {
                re: self.rightmost.re,
                im: self.rightmost.im.abs(),
            },
            kind,
            rightmost_part: part_name(self.part),
            delays: self.delays.clone(),
            states: self.states,
        }
    }

    /// What `attsync margin` prints.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "{}: the closed loop linearised about synchronisation ({} states), every follower link delayed by d\n",
            self.scenario, self.states
        );
        s += &match self.margin {
            Margin::Crossing { delay, omega, .. } => format!(
                "delay margin: d = {delay:.6} s (stable for every common delay below it; there a pair of roots crosses the imaginary axis at ±{omega:.6}i rad/s, period {:.4} s)\n",
                std::f64::consts::TAU / omega
            ),
            Margin::DelayIndependent => {
                "delay margin: none — stable for every delay (no root ever reaches the imaginary axis)\n".into()
            }
            Margin::UnstableWithoutDelay { rightmost } => format!(
                "delay margin: 0 — unstable already without delay (rightmost root {rightmost})\n"
            ),
        };
        let delays: Vec<String> = self.delays.iter().map(|d| format!("{d}")).collect();
        let r = self.rightmost;
        s += &format!(
            "rightmost root at the scenario's delay ({} s): {r} 1/s ({})\n",
            if delays.is_empty() {
                "0".into()
            } else {
                delays.join(", ")
            },
            part_name(self.part)
        );
        s += &if r.re < 0.0 {
            format!(
                "  the error should decay like e^({:.6} t): time constant {:.3} s, a factor 10 every {:.3} s\n",
                r.re,
                -1.0 / r.re,
                -std::f64::consts::LN_10 / r.re
            )
        } else {
            "  the error should not decay (Re ≥ 0)\n".into()
        };
        s
    }
}
