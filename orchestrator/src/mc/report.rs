//! A Monte Carlo's files and table: `trials.csv` (one row per trial),
//! `initial.csv` (the draws, one row per trial and node), `mc.json`
//! ([`McSummary`]) and the summary table printed on stdout. Every number is
//! written in Rust's shortest round-trip form; nothing depends on `--jobs`
//! or on the wall clock, so the files are identical for any `--jobs`.

use super::dispersion::{Dispersion, LeaderDispersion, Quantity};
use super::draws::Draws;
use super::outcome::{Outcome, TrialResult};
use super::stats;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The exact header of `trials.csv`.
pub const TRIALS_HEADER: &str = "trial,seed,outcome,decay_rate_per_s,final_max_att_err,\
final_max_angvel_err_rad_s,t_end_s,settle_att_1e-3_s,settle_att_1e-6_s,settle_angvel_1e-3_s,settle_angvel_1e-6_s";

/// The exact header of `initial.csv`.
pub const INITIAL_HEADER: &str = "trial,agent,q_w,q_x,q_y,q_z,omega_x,omega_y,omega_z,qhat_w,qhat_x,qhat_y,qhat_z,omegahat_x,omegahat_y,omegahat_z,sigmahat_x,sigmahat_y,sigmahat_z";

/// Confidence of the bounds in `mc.json`.
pub const CONFIDENCE: f64 = 0.95;

/// Trials listed in `mc.json` `slowest`.
pub const SLOWEST: usize = 10;

fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| v.to_string())
}

/// The header of `trials.csv`: [`TRIALS_HEADER`], then one column per
/// `[[monte_carlo.param]]` field, named by its path.
#[must_use]
pub fn trials_header(dispersion: &Dispersion) -> String {
    let mut s = TRIALS_HEADER.to_string();
    for p in &dispersion.params {
        s.push(',');
        s += &p.field;
    }
    s
}

/// One `trials.csv` row (no newline).
#[must_use]
pub fn trial_row(r: &TrialResult) -> String {
    let mut row = format!(
        "{},{},{},{},{},{},{},{},{},{},{}",
        r.trial,
        r.seed,
        r.outcome.name(),
        opt(r.decay_rate),
        r.final_max_att_err,
        r.final_max_angvel_err,
        r.t_end,
        opt(r.settle.att_1e3),
        opt(r.settle.att_1e6),
        opt(r.settle.angvel_1e3),
        opt(r.settle.angvel_1e6)
    );
    cells(&mut row, &r.params, true);
    row
}

/// `trials.csv`.
#[must_use]
pub fn trials_csv(dispersion: &Dispersion, results: &[TrialResult]) -> String {
    trials_csv_under(&trials_header(dispersion), results)
}

/// `trials.csv` under the header `header` ([`trials_header`]).
#[must_use]
pub fn trials_csv_under(header: &str, results: &[TrialResult]) -> String {
    let mut s = format!("{header}\n");
    for r in results {
        s += &trial_row(r);
        s.push('\n');
    }
    s
}

/// Why a `trials.csv` row cannot be read back.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("column {column}: {reason}")]
pub struct RowError {
    /// The column's name.
    pub column: String,
    /// What is wrong.
    pub reason: String,
}

/// Reads back a row [`trial_row`] wrote under `header` (its exact header,
/// [`trials_header`]): every number is in its shortest round-trip form, so
/// the result is the one written, bit for bit, except `reason` (not in
/// the file: `None`).
///
/// # Errors
/// A cell that is missing or is not what its column holds.
pub fn parse_row(header: &str, row: &str) -> Result<TrialResult, RowError> {
    let names: Vec<&str> = header.split(',').collect();
    let cells: Vec<&str> = row.split(',').collect();
    let column = |k: usize| names.get(k).copied().unwrap_or("?").to_string();
    if cells.len() != names.len() || names.len() < 11 {
        return Err(RowError {
            column: column(cells.len().min(names.len())),
            reason: format!("{} cells under a header of {}", cells.len(), names.len()),
        });
    }
    let bad = |k: usize, what: &str| RowError {
        column: column(k),
        reason: format!("{:?} is not {what}", cells[k]),
    };
    let int = |k: usize| cells[k].parse::<u64>().map_err(|_| bad(k, "an integer"));
    let num = |k: usize| cells[k].parse::<f64>().map_err(|_| bad(k, "a number"));
    let opt = |k: usize| match cells[k] {
        "" => Ok(None),
        _ => num(k).map(Some),
    };
    Ok(TrialResult {
        trial: int(0)?,
        seed: int(1)?,
        outcome: Outcome::named(cells[2]).ok_or_else(|| bad(2, "an outcome"))?,
        decay_rate: opt(3)?,
        final_max_att_err: num(4)?,
        final_max_angvel_err: num(5)?,
        t_end: num(6)?,
        settle: crate::results::summary::Settle {
            att_1e3: opt(7)?,
            att_1e6: opt(8)?,
            angvel_1e3: opt(9)?,
            angvel_1e6: opt(10)?,
        },
        reason: None,
        params: (11..cells.len()).map(num).collect::<Result<_, _>>()?,
    })
}

/// The cells of `values` if `drawn`, else as many empty cells.
fn cells(s: &mut String, values: &[f64], drawn: bool) {
    for v in values {
        s.push(',');
        if drawn {
            let _ = write!(s, "{v}");
        }
    }
}

/// `initial.csv` rows of one trial: one per agent (its id) and, if the
/// leader is dispersed, one for it (agent 0; `sigmahat_*` hold `σ₀(0)`).
/// A value that is not dispersed is left empty (it is the scenario's).
pub fn initial_rows(s: &mut String, trial: u64, ids: &[u32], d: &Dispersion, draws: &Draws) {
    for (id, a) in ids.iter().zip(&draws.agents) {
        let _ = write!(s, "{trial},{id}");
        cells(s, &a.attitude, d.has(Quantity::Attitude));
        cells(s, &a.omega, d.has(Quantity::Omega));
        cells(s, &a.attitude_hat, d.has(Quantity::AttitudeHat));
        cells(s, &a.omega_hat, d.has(Quantity::OmegaHat));
        cells(s, &a.sigma_hat, d.has(Quantity::SigmaHat));
        s.push('\n');
    }
    if d.leader != LeaderDispersion::None {
        let l = &draws.leader;
        let state = d.leader == LeaderDispersion::State;
        let _ = write!(s, "{trial},0");
        cells(s, &l.attitude, true);
        cells(s, &l.omega, state);
        cells(s, &l.attitude_hat, false);
        cells(s, &l.omega_hat, false);
        cells(s, &l.sigma_hat, state);
        s.push('\n');
    }
}

/// Counts of each outcome.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Converged.
    pub converged: u64,
    /// Converging (decaying, not below the tolerance by the end).
    pub converging: u64,
    /// Synchronised among themselves, not to the leader.
    pub synchronised_apart: u64,
    /// Persistent.
    pub persistent: u64,
    /// Diverging (growing, or a state left the envelope).
    pub diverging: u64,
    /// Undecided.
    pub undecided: u64,
    /// Failed (a process).
    pub failed: u64,
}

impl Counts {
    /// The counts of `results`.
    #[must_use]
    pub fn of(results: &[TrialResult]) -> Self {
        let mut c = Counts::default();
        for r in results {
            *c.get_mut(r.outcome) += 1;
        }
        c
    }

    fn get_mut(&mut self, o: Outcome) -> &mut u64 {
        match o {
            Outcome::Converged => &mut self.converged,
            Outcome::Converging => &mut self.converging,
            Outcome::Synchronised => &mut self.synchronised_apart,
            Outcome::Persistent => &mut self.persistent,
            Outcome::Diverging => &mut self.diverging,
            Outcome::Undecided => &mut self.undecided,
            Outcome::Failed => &mut self.failed,
        }
    }

    /// The count of outcome `o`.
    #[must_use]
    pub fn get(&self, o: Outcome) -> u64 {
        match o {
            Outcome::Converged => self.converged,
            Outcome::Converging => self.converging,
            Outcome::Synchronised => self.synchronised_apart,
            Outcome::Persistent => self.persistent,
            Outcome::Diverging => self.diverging,
            Outcome::Undecided => self.undecided,
            Outcome::Failed => self.failed,
        }
    }
}

/// `mc.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct McSummary {
    /// attsync's version.
    pub attsync_version: String,
    /// The scenario's name.
    pub scenario: String,
    /// Engine of the trials.
    pub engine: String,
    /// The master seed.
    pub seed: u64,
    /// Trials asked for.
    pub trials: u64,
    /// Trials that ran to an outcome (fewer if interrupted).
    pub trials_run: u64,
    /// Whether every trial asked for ran (of a shard: every trial of its slice).
    pub complete: bool,
    /// `--shard K/N`: the slice of the trials this directory holds
    /// (`attsync mc merge` joins the slices).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<super::shard::ShardRange>,
    /// Simulated horizon of each trial, s (the scenario's; `--until
    /// settled` may extend a trial's: its `t_end`).
    pub duration: f64,
    /// The tolerance of `converged` on the largest attitude error over agents.
    pub tolerance: f64,
    /// `--until settled`: the longest horizon of a trial, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub until: Option<f64>,
    /// The criterion, in words.
    pub criterion: String,
    /// What was dispersed.
    pub dispersion: Dispersion,
    /// Trials of each outcome.
    pub counts: Counts,
    /// Trials that are neither converged nor converging.
    pub failures: u64,
    /// `failures / trials_run`.
    pub failure_rate: f64,
    /// The exact one-sided 95 % Clopper–Pearson upper bound of the failure rate.
    pub failure_rate_upper_95: f64,
    /// The exact two-sided 95 % Clopper–Pearson interval of the failure rate.
    pub failure_rate_interval_95: [f64; 2],
    /// Indices of the trials that failed (neither converged nor converging).
    pub failed_trials: Vec<u64>,
    /// The slowest trials (latest settle time to 1e-6; never settled first).
    pub slowest: Vec<TrialResult>,
}

/// The summary of `results` (by trial index).
#[must_use]
pub fn summarise(head: McSummary, results: &[TrialResult]) -> McSummary {
    let counts = Counts::of(results);
    let n = results.len() as u64;
    let failures = results.iter().filter(|r| r.outcome.is_failure()).count() as u64;
    let alpha = 1.0 - CONFIDENCE;
    let (upper, interval) = if n == 0 {
        (1.0, [0.0, 1.0])
    } else {
        let (lo, hi) = stats::interval(failures, n, alpha);
        (stats::upper_bound(failures, n, alpha), [lo, hi])
    };
    let mut slowest: Vec<TrialResult> = results.to_vec();
    let key = |r: &TrialResult| r.settle.att_1e6.unwrap_or(f64::INFINITY);
    slowest.sort_by(|a, b| key(b).total_cmp(&key(a)).then(a.trial.cmp(&b.trial)));
    slowest.truncate(SLOWEST);
    McSummary {
        trials_run: n,
        failures,
        failure_rate: if n == 0 {
            0.0
        } else {
            failures as f64 / n as f64
        },
        failure_rate_upper_95: upper,
        failure_rate_interval_95: interval,
        failed_trials: (results.iter())
            .filter(|r| r.outcome.is_failure())
            .map(|r| r.trial)
            .collect(),
        slowest,
        counts,
        ..head
    }
}

/// Median and maximum (with its trial) of the known values of `pick`.
fn spread(results: &[TrialResult], pick: impl Fn(&TrialResult) -> Option<f64>) -> String {
    let mut v: Vec<(f64, u64)> = results
        .iter()
        .filter_map(|r| Some((pick(r)?, r.trial)))
        .collect();
    if v.is_empty() {
        return "never".into();
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (max, k) = v[v.len() - 1];
    let never = results.len() - v.len();
    format!(
        "median {:.2} s, max {max:.2} s (trial {k}){}",
        v[v.len() / 2].0,
        if never > 0 {
            format!(", never in {never}")
        } else {
            String::new()
        }
    )
}

/// The table printed at the end of `attsync mc`.
#[must_use]
pub fn table(s: &McSummary, results: &[TrialResult]) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{}: {} of {} trials ({} engine), seed {}, {} s each{}, tolerance {:e}",
        s.scenario,
        s.trials_run,
        s.trials,
        s.engine,
        s.seed,
        s.duration,
        s.until.map_or(String::new(), |m| format!(
            " (--until settled, at most {m} s)"
        )),
        s.tolerance
    );
    let _ = writeln!(t, "{:<18} {:>8}", "outcome", "trials");
    for o in Outcome::ALL {
        let _ = writeln!(t, "{:<18} {:>8}", o.name(), s.counts.get(o));
    }
    let [lo, hi] = s.failure_rate_interval_95;
    let _ = writeln!(
        t,
        "failure rate {}/{} = {:.4}; 95 % upper bound {:.4} (one-sided Clopper–Pearson), 95 % interval [{:.4}, {:.4}]",
        s.failures, s.trials_run, s.failure_rate, s.failure_rate_upper_95, lo, hi
    );
    let _ = writeln!(
        t,
        "settle att < 1e-3: {}",
        spread(results, |r| r.settle.att_1e3)
    );
    let _ = writeln!(
        t,
        "settle att < 1e-6: {}",
        spread(results, |r| r.settle.att_1e6)
    );
    let _ = writeln!(
        t,
        "settle angvel < 1e-3 rad/s: {}",
        spread(results, |r| r.settle.angvel_1e3)
    );
    let worst = results
        .iter()
        .map(|r| r.final_max_att_err)
        .fold(0.0, f64::max);
    let _ = writeln!(t, "largest final att_err: {worst:.3e}");
    if !s.failed_trials.is_empty() {
        let list: Vec<String> = s
            .failed_trials
            .iter()
            .take(20)
            .map(u64::to_string)
            .collect();
        let more = if s.failed_trials.len() > 20 {
            ", …"
        } else {
            ""
        };
        let _ = writeln!(
            t,
            "failed (neither converged nor converging): trials {}{more}",
            list.join(", ")
        );
    }
    t
}
