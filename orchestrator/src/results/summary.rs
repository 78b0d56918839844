//! `summary.json` and the table printed at the end of a run.

use crate::failure::Failure;
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
    /// Settle times of this agent's errors ([`Settle`]).
    #[serde(flatten)]
    pub settle: Settle,
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

/// Settle times, s: for each quantity and threshold, the time after which
/// the quantity stays below the threshold to the end of the run
/// ([`attsync_verdict::settle_time`], the one definition `run`, `sweep` and
/// `mc` share; `null`: not by the end). The attitude error `|Rᵢ R₀ᵀ|_I` is
/// dimensionless, the angular-velocity error `‖ωᵢ − ω₀‖` in rad/s.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Settle {
    /// `|Rᵢ R₀ᵀ|_I < 1e-3`, s.
    #[serde(rename = "settle_att_1e-3_s", default)]
    pub att_1e3: Option<f64>,
    /// `|Rᵢ R₀ᵀ|_I < 1e-6`, s.
    #[serde(rename = "settle_att_1e-6_s", default)]
    pub att_1e6: Option<f64>,
    /// `‖ωᵢ − ω₀‖ < 1e-3 rad/s`, s.
    #[serde(rename = "settle_angvel_1e-3_s", default)]
    pub angvel_1e3: Option<f64>,
    /// `‖ωᵢ − ω₀‖ < 1e-6 rad/s`, s.
    #[serde(rename = "settle_angvel_1e-6_s", default)]
    pub angvel_1e6: Option<f64>,
}

impl Settle {
    /// The settle times of the attitude errors `att` and angular-velocity
    /// errors `angvel` sampled at `t`.
    #[must_use]
    pub fn of(t: &[f64], att: &[f64], angvel: &[f64]) -> Self {
        use attsync_verdict::settle_time;
        Self {
            att_1e3: settle_time(t, att, 1e-3),
            att_1e6: settle_time(t, att, 1e-6),
            angvel_1e3: settle_time(t, angvel, 1e-3),
            angvel_1e6: settle_time(t, angvel, 1e-6),
        }
    }

    /// The latest of several (`None` if any is `None`): when every one has settled.
    #[must_use]
    pub fn latest<'a>(all: impl IntoIterator<Item = &'a Settle>) -> Settle {
        let max = |a: Option<f64>, b: Option<f64>| a.zip(b).map(|(a, b)| a.max(b));
        all.into_iter().fold(
            Settle {
                att_1e3: Some(0.0),
                att_1e6: Some(0.0),
                angvel_1e3: Some(0.0),
                angvel_1e6: Some(0.0),
            },
            |m, s| Settle {
                att_1e3: max(m.att_1e3, s.att_1e3),
                att_1e6: max(m.att_1e6, s.att_1e6),
                angvel_1e3: max(m.angvel_1e3, s.angvel_1e3),
                angvel_1e6: max(m.angvel_1e6, s.angvel_1e6),
            },
        )
    }
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
    /// Median age of information, s, where measured (real time, within
    /// 3.2 %: a histogram's bin).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aoi_p50: Option<f64>,
    /// 99th percentile of the age of information, s, likewise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aoi_p99: Option<f64>,
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
    /// The `--set` overrides the run was given (`key.path=value`), in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub overrides: Vec<String>,
    /// Engine used.
    pub engine: String,
    /// `scheme.law`: `corrected`, or `as-printed` (the negative control of
    /// erratum 1); absent in summaries written before it existed: corrected.
    #[serde(default)]
    pub law: attitude::control::ControlLaw,
    /// Whether the run reached its horizon.
    pub complete: bool,
    /// Why not, if not (its text; read back: [`Failure::Recorded`]).
    pub incomplete_reason: Option<Failure>,
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
    /// Processes engine: the agents' processes that crashed and the ones
    /// that took over (`[[event]] action = "crash"`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub restarts: Vec<crate::outcome::Restart>,
    /// In-process engine: the threads that stepped the agents (absent for
    /// the processes engine).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threads: Option<usize>,
    /// The verdict on the run, read from the largest attitude error over
    /// agents over the whole run (`docs/verdicts.md`); absent in summaries
    /// written before verdicts existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verdict: Option<attsync_verdict::Verdict>,
    /// `--until settled`: how far the horizon was extended and why it stopped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub until: Option<super::until::UntilSummary>,
    /// A run across hosts (`--hosts`): the hosts and how the links were secured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hosts: Option<HostsSummary>,
    /// How the scenario leaves the paper's Assumption 1 (`[graph]
    /// assumptions = "off"`), each said in words; absent inside the theory.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outside_theory: Vec<String>,
    /// The scenario's `[[event]]`s in time order (`docs/events.md`);
    /// absent without.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<crate::scenario::resolve::Event>,
    /// Agents the events left unreachable from the leader, and when;
    /// absent when none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unreachable: Vec<crate::scenario::resolve::Isolation>,
}

/// The hosts of a run across machines, and its links' security.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct HostsSummary {
    /// The hosts' names, in the hosts file's order.
    pub hosts: Vec<String>,
    /// `mutual-tls` or `insecure` ([`crate::trust::Security::name`]).
    pub security: String,
    /// Why an insecure run is one ([`crate::trust::INSECURE_WARNING`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
}

impl HostsSummary {
    /// Of the hosts `names`, reached as `security` says.
    #[must_use]
    pub fn of(names: Vec<String>, security: &crate::trust::Security) -> Self {
        let insecure = *security == crate::trust::Security::Insecure;
        Self {
            hosts: names,
            security: security.name().into(),
            warning: insecure.then(|| crate::trust::INSECURE_WARNING.into()),
        }
    }
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
            aoi_p50: st.age_p50,
            aoi_p99: st.age_p99,
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

impl Summary {
    /// A fixed-width table of the per-agent results.
    #[must_use]
    pub fn table(&self) -> String {
        let mut s = String::new();
        self.write_agents(&mut s);
        self.write_links(&mut s);
        self.write_run(&mut s);
        s
    }

    /// The agents' rows under a two-line header.
    fn write_agents(&self, s: &mut String) {
        let opt = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.3e}"));
        let time = |x: Option<f64>| x.map_or("never".to_string(), |v| format!("{v:.2}"));
        for head in [
            [
                "agent",
                "att_err",
                "angvel_err",
                "obs_att",
                "obs_angvel",
                "settle_att",
                "settle_att",
                "settle_angvel",
                "peak_tau",
            ],
            [
                "",
                "[1]",
                "[rad/s]",
                "[1]",
                "[rad/s]",
                "<1e-3 [s]",
                "<1e-6 [s]",
                "<1e-3 rad/s [s]",
                "[N m]",
            ],
        ] {
            let [a, b, c, d, e, f, g, h, i] = head;
            let _ = writeln!(
                s,
                "{a:>5} {b:>10} {c:>12} {d:>10} {e:>12} {f:>14} {g:>14} {h:>16} {i:>12}"
            );
        }
        for a in &self.agents {
            let _ = writeln!(
                s,
                "{:>5} {:>10.3e} {:>12.3e} {:>10} {:>12} {:>14} {:>14} {:>16} {:>12.3e}",
                a.id,
                a.final_att_err,
                a.final_angvel_err,
                opt(a.final_obs_att_err),
                opt(a.final_obs_angvel_err),
                time(a.settle.att_1e3),
                time(a.settle.att_1e6),
                time(a.settle.angvel_1e3),
                a.peak_torque
            );
        }
    }

    /// A line per listed link.
    fn write_links(&self, s: &mut String) {
        for l in &self.links {
            let _ = write!(
                s,
                "link {:>3} → {:<3} sent {:>8} delivered {:>8} lost {:>7} rejected {:>5} AoI mean {:.3e} s max {:.3e} s",
                l.from, l.to, l.sent, l.delivered, l.lost, l.rejected, l.aoi_mean, l.aoi_max
            );
            if let (Some(p50), Some(p99)) = (l.aoi_p50, l.aoi_p99) {
                let _ = write!(s, " p50 {p50:.3e} s p99 {p99:.3e} s");
            }
            s.push('\n');
        }
    }

    /// The run's line, then its verdict, a hosts warning and `--until`.
    fn write_run(&self, s: &mut String) {
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
                    (self.incomplete_reason.as_ref()).map_or("?".into(), ToString::to_string)
                )
            }
        );
        if let Some(v) = &self.verdict {
            let _ = write!(s, "\nverdict: {}", verdict_line(v));
        }
        if let Some(w) = self.hosts.as_ref().and_then(|h| h.warning.as_ref()) {
            let _ = write!(s, "\nwarning: {w}");
        }
        if let Some(u) = &self.until {
            let _ = write!(s, "\n--until settled: {}", until_line(u));
        }
    }
}

/// How `--until settled` ended, for [`Summary::table`].
fn until_line(u: &super::until::UntilSummary) -> String {
    let how = match u.stopped {
        super::until::Stopped::VerdictFinal => "stopped when the verdict was final".to_string(),
        super::until::Stopped::MaxDuration => format!(
            "stopped at --max-duration {} s before the verdict was final",
            u.max_duration
        ),
        super::until::Stopped::RunEnded => "stopped when the run ended".to_string(),
    };
    format!("{} s in {} chunk(s), {how}", u.duration, u.chunks)
}

/// One line for a verdict: its kind, the decay rate and what follows from it.
#[must_use]
pub fn verdict_line(v: &attsync_verdict::Verdict) -> String {
    use attsync_verdict::Kind;
    let rate = v
        .decay_rate
        .map_or(String::new(), |r| format!(", decay rate {r:.4} /s"));
    let extra = match v.kind {
        Kind::Converged => v.settle_time.map_or(String::new(), |t| {
            format!(", below {:e} from t = {t} s", v.tolerance)
        }),
        Kind::Converging => v.projected_time.map_or(String::new(), |t| {
            format!(
                ", projected below {:e} at t ≈ {t:.1} s (--until settled runs on)",
                v.tolerance
            )
        }),
        Kind::Persistent => format!(
            ", amplitude {}{}",
            v.amplitude.map_or("?".into(), |a| format!("{a:.3e}")),
            v.period
                .map_or(String::new(), |p| format!(", period {p:.3} s"))
        ),
        Kind::Diverging | Kind::Undecided => String::new(),
    };
    format!("{}{rate}{extra} — {}", v.kind.name(), v.reason)
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
            settle: Settle::default(),
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
