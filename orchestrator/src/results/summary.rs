//! `summary.json` and the table printed at the end of a run.

use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// Per-agent results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AgentSummary {
    /// Agent id.
    pub id: u32,
    /// `|Rᵢ R₀ᵀ|_I` at the last sample.
    #[serde(deserialize_with = "f64_or_nan")]
    pub final_att_err: f64,
    /// `‖ωᵢ − ω₀‖` at the last sample, rad/s.
    #[serde(deserialize_with = "f64_or_nan")]
    pub final_angvel_err: f64,
    /// Observer attitude error at the last sample (schemes 1–2).
    pub final_obs_att_err: Option<f64>,
    /// Observer angular-velocity error at the last sample (schemes 1–2).
    pub final_obs_angvel_err: Option<f64>,
    /// Time after which `att_err` stays below 1e-3 (null: not by the end).
    #[serde(rename = "settle_time_1e-3")]
    pub settle_time_1e3: Option<f64>,
    /// Time after which `att_err` stays below 1e-6 (null: not by the end).
    #[serde(rename = "settle_time_1e-6")]
    pub settle_time_1e6: Option<f64>,
    /// Largest `‖τᵢ‖` applied at the start of any step, N·m.
    #[serde(deserialize_with = "f64_or_nan")]
    pub peak_torque: f64,
    /// Real-time mode: stages the agent started more than one step late.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub late_stages: Option<u64>,
    /// Real-time mode: the agent's largest lateness against the wall clock, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_lateness: Option<f64>,
    /// The program that ran this agent, if it was a plug-in.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plugin: Option<String>,
}

/// Counters of one directed link. Listed: impaired links, every link in
/// real-time mode (measured), and any link on which the receiver refused
/// invalid values; an unimpaired lockstep link is ideal and not listed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinkSummary {
    /// Sender id (0 = leader).
    pub from: u32,
    /// Receiver id.
    pub to: u32,
    /// Messages offered on the link.
    pub sent: u64,
    /// Messages delivered.
    pub delivered: u64,
    /// Messages lost.
    pub lost: u64,
    /// Mean age of information of the value the receiver used, over its stages, s.
    #[serde(deserialize_with = "f64_or_nan")]
    pub aoi_mean: f64,
    /// Largest age of information, s.
    #[serde(deserialize_with = "f64_or_nan")]
    pub aoi_max: f64,
    /// Messages the receiver refused (non-finite values, or an attitude that
    /// is not a rotation); it kept its previous value instead.
    #[serde(default)]
    pub rejected: u64,
}

/// The whole run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// attsync version that produced it.
    pub attsync_version: String,
    /// Scenario name.
    pub scenario: String,
    /// Engine used.
    pub engine: String,
    /// `scheme.law`: `corrected`, or `as-printed` (the negative control of
    /// erratum 1); absent in summaries written before it existed: corrected.
    #[serde(default)]
    pub law: attitude::control::ControlLaw,
    /// Whether the run reached its horizon.
    pub complete: bool,
    /// Why not, if not.
    pub incomplete_reason: Option<String>,
    /// The state that left the envelope, if the run diverged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diverged: Option<Diverged>,
    /// Integrator step, s.
    pub dt: f64,
    /// Requested horizon, s.
    pub duration: f64,
    /// Simulated time reached, s.
    pub t_end: f64,
    /// Steps done.
    pub steps: u64,
    /// Wall-clock time of the simulation, s (not deterministic).
    pub wall_seconds: f64,
    /// Largest final `att_err` over agents.
    #[serde(deserialize_with = "f64_or_nan")]
    pub max_final_att_err: f64,
    /// Per agent, ascending id.
    pub agents: Vec<AgentSummary>,
    /// Per listed link, by (from, to).
    pub links: Vec<LinkSummary>,
    /// Real-time factor (simulated s per wall s), `None` for lockstep.
    #[serde(default)]
    pub realtime: Option<f64>,
    /// Processes engine: what every node that finished reported (empty in-process).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub nodes: Vec<NodeSummary>,
    /// In-process engine: the threads that stepped the agents (absent for
    /// the processes engine).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threads: Option<usize>,
}

/// Where a run diverged: the first state outside the envelope
/// (`attitude::guard`), the same in both engines.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diverged {
    /// Simulated time of the state, s.
    pub t: f64,
    /// `leader` or `agent-<id>`.
    pub node: String,
    /// `r`, `omega`, `r_hat`, `omega_hat`, `sigma_hat` (agents), `r0`,
    /// `omega0`, `sigma0` (the leader).
    pub quantity: String,
    /// Its value: a norm, a non-finite entry (NaN written as `null`), or an
    /// attitude's orthogonality defect.
    #[serde(deserialize_with = "f64_or_nan")]
    pub value: f64,
}

impl Diverged {
    /// The summary of divergence `d` in a run of step `dt`.
    #[must_use]
    pub fn of(d: &attitude::guard::Divergence, dt: f64) -> Self {
        Self {
            t: d.step as f64 * dt,
            node: d.node_name(),
            quantity: d.violation.quantity.name().into(),
            value: d.violation.value,
        }
    }
}

/// One node process of a processes-engine run, from its `Done` report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NodeSummary {
    /// Node id (0 = the leader).
    pub id: u32,
    /// `leader` or `agent-<id>`.
    pub name: String,
    /// Peak resident set size of the process, kB.
    pub peak_rss_kb: u64,
    /// Wall time it began stepping, ns since the Unix epoch.
    pub started_unix_ns: u64,
    /// Wall time it finished its last step, ns since the Unix epoch.
    pub done_unix_ns: u64,
}

impl LinkSummary {
    /// The summary of link `from` → `to` with counters `st`.
    #[must_use]
    pub fn of(from: u32, to: u32, st: &attitude::link::LinkStats) -> Self {
        Self {
            from,
            to,
            sent: st.sent,
            delivered: st.delivered,
            lost: st.lost,
            aoi_mean: if st.evaluations > 0 {
                st.age_sum / st.evaluations as f64
            } else {
                0.0
            },
            aoi_max: st.age_max,
            rejected: st.rejected,
        }
    }
}

impl NodeSummary {
    /// The summary of node `id` (`name`) from its `Done` report.
    #[must_use]
    pub fn of(id: u32, name: &str, d: &msgs::Done) -> Self {
        Self {
            id,
            name: name.to_owned(),
            peak_rss_kb: d.peak_rss_kb,
            started_unix_ns: d.started_unix_ns,
            done_unix_ns: d.done_unix_ns,
        }
    }
}

/// `summary.json` holds a NaN (a diverged state) as `null`: read it back as NaN.
fn f64_or_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Time after which `err` stays below `threshold`: the sample after the last
/// one at or above it; `Some(t[0])` if always below; `None` if the last
/// sample is not below.
#[must_use]
pub fn settle_time(t: &[f64], err: &[f64], threshold: f64) -> Option<f64> {
    match err.iter().rposition(|&e| e >= threshold || e.is_nan()) {
        None => t.first().copied(),
        Some(k) if k + 1 < t.len() => Some(t[k + 1]),
        Some(_) => None,
    }
}

impl Summary {
    /// A fixed-width table of the per-agent results.
    #[must_use]
    pub fn table(&self) -> String {
        let mut s = String::new();
        let opt = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.3e}"));
        let time = |x: Option<f64>| x.map_or("never".to_string(), |v| format!("{v:.2}"));
        let _ = writeln!(
            s,
            "{:>5} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>10}",
            "agent",
            "att_err",
            "angvel_err",
            "obs_att",
            "obs_angvel",
            "t<1e-3",
            "t<1e-6",
            "peak_tau"
        );
        for a in &self.agents {
            let _ = writeln!(
                s,
                "{:>5} {:>10.3e} {:>10.3e} {:>10} {:>10} {:>9} {:>9} {:>10.3e}",
                a.id,
                a.final_att_err,
                a.final_angvel_err,
                opt(a.final_obs_att_err),
                opt(a.final_obs_angvel_err),
                time(a.settle_time_1e3),
                time(a.settle_time_1e6),
                a.peak_torque
            );
        }
        for l in &self.links {
            let _ = writeln!(
                s,
                "link {:>3} → {:<3} sent {:>8} delivered {:>8} lost {:>7} rejected {:>5} AoI mean {:.3e} s max {:.3e} s",
                l.from, l.to, l.sent, l.delivered, l.lost, l.rejected, l.aoi_mean, l.aoi_max
            );
        }
        let mode = match self.realtime {
            Some(f) => format!(" real-time ×{f}"),
            None => String::new(),
        };
        let _ = write!(
            s,
            "{}{mode} run of {}: t = {} s of {} s ({} steps, {:.2} s wall){}",
            self.engine,
            self.scenario,
            super::fmt_time(self.steps, self.dt),
            super::fmt_time((self.duration / self.dt).round() as u64, self.dt),
            self.steps,
            self.wall_seconds,
            if self.complete {
                String::new()
            } else {
                format!(
                    " INCOMPLETE: {}",
                    self.incomplete_reason.as_deref().unwrap_or("?")
                )
            }
        );
        s
    }
}

#[cfg(test)]
mod nan_tests {
    use super::*;

    #[test]
    fn a_nan_written_as_null_reads_back_as_nan() {
        let a = AgentSummary {
            id: 1,
            final_att_err: f64::NAN,
            final_angvel_err: 0.5,
            final_obs_att_err: None,
            final_obs_angvel_err: None,
            settle_time_1e3: None,
            settle_time_1e6: None,
            peak_torque: f64::NAN,
            late_stages: None,
            max_lateness: None,
            plugin: None,
        };
        let text = serde_json::to_string(&a).unwrap();
        assert!(text.contains("\"final_att_err\":null"), "{text}");
        let b: AgentSummary = serde_json::from_str(&text).unwrap();
        assert!(b.final_att_err.is_nan() && b.peak_torque.is_nan());
        assert_eq!(b.final_angvel_err, 0.5);
    }
}

#[cfg(test)]
mod tests {
    use super::settle_time;

    #[test]
    fn settle_time_is_the_sample_after_the_last_excursion() {
        let t = [0.0, 1.0, 2.0, 3.0];
        assert_eq!(settle_time(&t, &[1.0, 1e-4, 2e-3, 1e-4], 1e-3), Some(3.0));
        assert_eq!(settle_time(&t, &[1e-4; 4], 1e-3), Some(0.0));
        assert_eq!(settle_time(&t, &[1e-4, 1e-4, 1e-4, 1.0], 1e-3), None);
    }
}
