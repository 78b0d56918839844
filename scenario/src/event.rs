//! `[[event]]`: what happens at a simulated time `t` (the file's form; the
//! resolved timeline is `resolve/events.rs`, the model's
//! `attitude::timeline`). See `docs/events.md`.

use crate::schema::RotationSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// `[[event]]`: one action at time `t`. Exactly one of `cut`, `restore`,
/// `agent` (with `action`) and `set` is given.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventSpec {
    /// When, s (a whole multiple of `simulation.dt`, in `[0, duration)`).
    pub t: f64,
    /// A link goes down: `[i, j]`, a follower edge, or `[0, j]` the leader's
    /// link to agent j.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut: Option<[u32; 2]>,
    /// A link cut earlier comes back.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restore: Option<[u32; 2]>,
    /// The agent `action` acts on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub agent: Option<u32>,
    /// What happens to `agent`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub action: Option<AgentAction>,
    /// With `cut` or `action = "silence"`: whether the receivers hold the
    /// last value they had while the link is down (`true`, the default: a
    /// lost message) or leave the input out of their law (`false`: the
    /// edge is removed, a switching graph).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hold: Option<bool>,
    /// With `action = "restart"`: the state it restarts from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<RestartState>,
    /// Fields that take a new value from `t` on: `{ "scheme.control.k_r" =
    /// 2.0 }`, `{ "leader.attitude" = { axis = …, angle_deg = … } }`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set: Option<BTreeMap<String, SetValue>>,
}

/// `action` of an agent event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AgentAction {
    /// The agent's process ends.
    Crash,
    /// The agent's process starts again.
    Restart,
    /// The agent runs on, but none of its messages is delivered.
    Silence,
    /// Its messages are delivered again.
    Resume,
}

impl AgentAction {
    /// The name as written in the file.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Crash => "crash",
            Self::Restart => "restart",
            Self::Silence => "silence",
            Self::Resume => "resume",
        }
    }
}

/// `state` of a restart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RestartState {
    /// The state at t = 0.
    Initial,
    /// The state the agent had when it crashed.
    Last,
}

/// A value of `set`: a number (a gain), a rotation (the reference), or a
/// table of either (`set = { scheme.control.k_r = 2.0 }` unquoted is a
/// nested table; it means the same as the quoted path).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number, a rotation table (axis + angle, quaternion or matrix), or a table of them"
)]
pub enum SetValue {
    /// A gain.
    Number(f64),
    /// An attitude.
    Rotation(RotationSpec),
    /// A nested table (an unquoted dotted key).
    Table(BTreeMap<String, SetValue>),
}

impl SetValue {
    /// Every `(path, value)` of `set`, nested tables flattened into dotted
    /// paths, in key order.
    #[must_use]
    pub fn flatten(set: &BTreeMap<String, SetValue>) -> Vec<(String, &SetValue)> {
        let mut out = Vec::new();
        for (k, v) in set {
            match v {
                SetValue::Table(t) => out.extend(
                    SetValue::flatten(t)
                        .into_iter()
                        .map(|(p, v)| (format!("{k}.{p}"), v)),
                ),
                v => out.push((k.clone(), v)),
            }
        }
        out
    }
}
