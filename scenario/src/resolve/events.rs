//! `[[event]]` → the timeline in steps: link outages by directed link,
//! retunes and repoints, and what the report lists (each event, and the
//! agents a cut leaves unreachable from the leader).
//!
//! Events are taken in time order (file order at equal `t`). A cut must be
//! restored by a later `restore` of the same link (or lasts to the end);
//! restoring what is not cut, or cutting what is, is an error naming both
//! events.

use super::assemble::Timed;
use super::ctx::Ctx;
use super::graph::{Edges, LeaderLinks};
use super::ids::Ids;
use crate::event::{AgentAction, EventSpec, SetValue};
use crate::schema::ReferenceKind;
use attitude::network::Coupling;
use attitude::network::Scheme;
use attitude::timeline::{Crash, Outage, Repoint, Retune};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};

/// One event as the run reports it (`summary.json`'s `events`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// When, s.
    pub t: f64,
    /// The step it acts at (`t = step · dt`).
    pub step: u64,
    /// What happens.
    #[serde(flatten)]
    pub what: What,
}

impl std::fmt::Display for Event {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "t = {} s: {}", self.t, self.what)
    }
}

impl std::fmt::Display for What {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            What::Cut {
                link: [a, b],
                hold: true,
            } => write!(f, "cut {a}–{b}"),
            What::Cut {
                link: [a, b],
                hold: false,
            } => write!(f, "cut {a}–{b} (removed)"),
            What::Restore { link: [a, b] } => write!(f, "restore {a}–{b}"),
            What::Silence { agent, hold: true } => write!(f, "agent {agent} falls silent"),
            What::Silence { agent, hold: false } => {
                write!(f, "agent {agent} falls silent (removed)")
            }
            What::Resume { agent } => write!(f, "agent {agent} resumes"),
            What::Crash { agent } => write!(f, "agent {agent} crashes"),
            What::Restart {
                agent,
                initial: false,
            } => write!(f, "agent {agent} restarts from its last state"),
            What::Restart {
                agent,
                initial: true,
            } => write!(f, "agent {agent} restarts from its initial state"),
            What::Set {
                field,
                value: Some(x),
                ..
            } => write!(f, "{field} = {x}"),
            What::Set { field, .. } => write!(f, "{field} jumps (a re-pointing)"),
        }
    }
}

/// What an event does.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum What {
    /// A link goes down (`[0, j]`: the leader's link to j).
    Cut {
        /// Its ends, as written.
        link: [u32; 2],
        /// Whether receivers hold the last value (else the edge is removed).
        hold: bool,
    },
    /// A link comes back.
    Restore {
        /// Its ends, as written.
        link: [u32; 2],
    },
    /// None of the agent's messages is delivered.
    Silence {
        /// The agent.
        agent: u32,
        /// Whether receivers hold the last value (else its edges are removed).
        hold: bool,
    },
    /// The agent's messages are delivered again.
    Resume {
        /// The agent.
        agent: u32,
    },
    /// The agent's process ends.
    Crash {
        /// The agent.
        agent: u32,
    },
    /// A new process of the agent takes over.
    Restart {
        /// The agent.
        agent: u32,
        /// From its initial state (else from its state at the crash).
        initial: bool,
    },
    /// A field takes a new value.
    Set {
        /// Its path.
        field: String,
        /// A gain's new value.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        value: Option<f64>,
        /// The reference's new attitude (rows).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        attitude: Option<[[f64; 3]; 3]>,
    },
}

/// Agents unreachable from the leader during `[from, to)` s because of
/// the timeline (agents the static graph leaves unreachable are not listed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Isolation {
    /// Start, s.
    pub from: f64,
    /// End, s.
    pub to: f64,
    /// The agents, ascending.
    pub agents: Vec<u32>,
}

/// The timeline, resolved.
#[derive(Debug, Default)]
pub(super) struct Timeline {
    /// What the model runs: outages by directed link, retunes, repoints.
    pub(super) timed: Timed,
    /// The events, in time order.
    pub(super) events: Vec<Event>,
    /// Agents the timeline cuts off from the leader.
    pub(super) isolated: Vec<Isolation>,
}

/// What the events act on.
pub(super) struct World<'a> {
    pub(super) dt: f64,
    pub(super) steps: u64,
    pub(super) scheme: Option<Scheme>,
    pub(super) reference: ReferenceKind,
    pub(super) ids: &'a Ids,
    pub(super) edges: &'a Edges,
    pub(super) links: &'a LeaderLinks,
    pub(super) coupling: Option<Coupling>,
    /// Agents run by a plug-in (they cannot crash: the orchestrator cannot
    /// stop a plug-in at a step).
    pub(super) plugins: BTreeSet<u32>,
}

/// Exchanges a node may publish that a crashed one never read: the
/// subscriber buffer of a state service (`msgs::Limits::state_buffer`),
/// which a restart must come after.
pub const RESTART_GAP_EXCHANGES: u64 = 64;

impl World<'_> {
    /// The fewest steps between a crash and its restart: more than
    /// [`RESTART_GAP_EXCHANGES`] exchanges.
    fn restart_gap(&self) -> u64 {
        match self.coupling {
            Some(Coupling::Sampled { every }) => (RESTART_GAP_EXCHANGES + 1) * every,
            _ => RESTART_GAP_EXCHANGES / 4 + 1,
        }
    }

    /// The directed links `[a, b]` names: both ways for a follower edge,
    /// one for a one-way edge (either order) or a leader link; `None` if
    /// it is none of them.
    fn arcs_of(&self, [a, b]: [u32; 2]) -> Option<Vec<(u32, u32)>> {
        let (lo, hi) = (a.min(b), a.max(b));
        if lo == 0 {
            let linked = self
                .ids
                .rank(hi)
                .is_some_and(|r| self.links.gain[r].is_some());
            return linked.then(|| vec![(0, hi)]);
        }
        if self.edges.pairs.contains(&(lo, hi)) {
            return Some(vec![(lo, hi), (hi, lo)]);
        }
        let arcs: Vec<_> = (self.edges.arcs.iter())
            .filter(|&&(f, t)| (f, t) == (a, b) || (f, t) == (b, a))
            .copied()
            .collect();
        (!arcs.is_empty()).then_some(arcs)
    }

    /// Every directed link out of agent `id`.
    fn arcs_out(&self, id: u32) -> Vec<(u32, u32)> {
        let pairs = self.edges.pairs.iter().flat_map(|&(a, b)| [(a, b), (b, a)]);
        pairs
            .chain(self.edges.arcs.iter().copied())
            .filter(|&(f, _)| f == id)
            .collect()
    }

    /// Every directed link of the network.
    fn all_arcs(&self) -> Vec<(u32, u32)> {
        let pairs = self.edges.pairs.iter().flat_map(|&(a, b)| [(a, b), (b, a)]);
        let leader = self.links.linked().map(|r| (0, self.ids.id(r)));
        pairs
            .chain(self.edges.arcs.iter().copied())
            .chain(leader)
            .collect()
    }
}

/// `[[event]]` over `world`.
pub(super) fn events(c: &mut Ctx, specs: &[EventSpec], world: &World<'_>) -> Timeline {
    let mut order: Vec<(u64, usize)> = Vec::new();
    for (k, e) in specs.iter().enumerate() {
        if let Some(step) = when(c, k, e, world) {
            if one_action(c, k, e) {
                order.push((step, k));
            }
        }
    }
    order.sort_unstable();
    let mut walk = Walk::new(world);
    for &(step, k) in &order {
        walk.event(c, k, &specs[k], step);
    }
    walk.finish(c)
}

/// `event[k].t` as a step, if valid.
fn when(c: &mut Ctx, k: usize, e: &EventSpec, w: &World<'_>) -> Option<u64> {
    let field = format!("event[{k}].t");
    if !(c.finite(&field, e.t) && w.dt > 0.0 && w.dt.is_finite()) {
        return None;
    }
    let duration = w.steps as f64 * w.dt;
    if e.t < 0.0 || e.t >= duration {
        c.err(
            field,
            format!(
                "must be in [0, {duration}) s (simulation.duration), got {}",
                e.t
            ),
        );
        return None;
    }
    if e.t == 0.0 {
        return Some(0);
    }
    c.multiple_of_dt(field.as_str(), e.t, w.dt)
}

/// Whether `event[k]` has exactly one action, well formed.
fn one_action(c: &mut Ctx, k: usize, e: &EventSpec) -> bool {
    let f = format!("event[{k}]");
    let given = [
        e.cut.is_some(),
        e.restore.is_some(),
        e.agent.is_some(),
        e.set.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        c.err(f, "give exactly one of cut = [i, j], restore = [i, j], agent = ID (with action), set = { FIELD = value }");
        return false;
    }
    match (e.agent, e.action) {
        (Some(_), None) => c.err(
            format!("{f}.action"),
            "is required with agent (crash, restart, silence, resume)",
        ),
        (None, Some(_)) => c.err(
            format!("{f}.action"),
            "is only for an agent event (agent = ID)",
        ),
        _ => {}
    }
    if e.hold.is_some() && e.cut.is_none() && e.action != Some(AgentAction::Silence) {
        c.err(format!("{f}.hold"), "is only for cut = [i, j] and action = \"silence\" (restore and resume end what they started)");
    }
    if e.state.is_some() && e.action != Some(AgentAction::Restart) {
        c.err(format!("{f}.state"), "is only for action = \"restart\"");
    }
    if e.set
        .as_ref()
        .is_some_and(|s| SetValue::flatten(s).is_empty())
    {
        c.err(
            format!("{f}.set"),
            "sets nothing: give at least one FIELD = value",
        );
        return false;
    }
    e.agent.is_none() || e.action.is_some()
}

/// The events in time order, with what is down so far.
struct Walk<'a, 'w> {
    world: &'a World<'w>,
    /// Links cut now: since (step, event index, forget).
    cut: BTreeMap<[u32; 2], (u64, usize, bool)>,
    /// Agents silent now: since (step, event index, forget).
    silent: BTreeMap<u32, (u64, usize, bool)>,
    /// Agents down now: since (step, event index).
    crashed: BTreeMap<u32, (u64, usize)>,
    scheme: Option<Scheme>,
    out: Timeline,
}

impl<'a, 'w> Walk<'a, 'w> {
    fn new(world: &'a World<'w>) -> Self {
        Self {
            world,
            cut: BTreeMap::new(),
            silent: BTreeMap::new(),
            crashed: BTreeMap::new(),
            scheme: world.scheme,
            out: Timeline::default(),
        }
    }

    fn event(&mut self, c: &mut Ctx, k: usize, e: &EventSpec, step: u64) {
        let f = format!("event[{k}]");
        let report = |what| Event { t: e.t, step, what };
        let forget = e.hold == Some(false);
        if let Some(link) = e.cut.or(e.restore) {
            let up = e.restore.is_some();
            if self.link(c, &f, link, (step, k, forget), up) {
                let what = if up {
                    What::Restore { link }
                } else {
                    What::Cut {
                        link,
                        hold: !forget,
                    }
                };
                self.out.events.push(report(what));
            }
        } else if let (Some(agent), Some(AgentAction::Crash | AgentAction::Restart)) =
            (e.agent, e.action)
        {
            let initial = e.state == Some(crate::event::RestartState::Initial);
            if let Some(what) = self.crash(
                c,
                &f,
                agent,
                e.action == Some(AgentAction::Restart),
                (step, k, initial),
            ) {
                self.out.events.push(report(what));
            }
        } else if let (Some(agent), Some(action)) = (e.agent, e.action) {
            if self.agent(c, &f, agent, action, (step, k, forget)) {
                let what = match action {
                    AgentAction::Silence => What::Silence {
                        agent,
                        hold: !forget,
                    },
                    _ => What::Resume { agent },
                };
                self.out.events.push(report(what));
            }
        } else if let Some(set) = &e.set {
            for (field, value) in SetValue::flatten(set) {
                if let Some(what) = self.set(c, &format!("{f}.set.{field}"), &field, value, step) {
                    self.out.events.push(report(what));
                }
            }
        }
    }

    /// `cut` (`up` false) or `restore` (`up` true) of `link`.
    fn link(
        &mut self,
        c: &mut Ctx,
        f: &str,
        link: [u32; 2],
        (step, k, forget): (u64, usize, bool),
        up: bool,
    ) -> bool {
        let key = if up { "restore" } else { "cut" };
        let field = format!("{f}.{key}");
        let Some(arcs) = self
            .unknown_ids(c, &field, link)
            .then(|| self.world.arcs_of(link))
            .flatten()
        else {
            if self.unknown_ids_silent(link) {
                c.err(
                    field,
                    format!(
                        "{}–{} is neither a follower edge nor a leader link (the leader is 0)",
                        link[0], link[1]
                    ),
                );
            }
            return false;
        };
        let name = [link[0].min(link[1]), link[0].max(link[1])];
        let [a, b] = link;
        let t = step as f64 * self.world.dt;
        match switch(&mut self.cut, name, up, (step, k, forget)) {
            Ok(Some(o)) => self.down(&arcs, o),
            Ok(None) => {}
            Err(Conflict::Already(since)) => {
                c.err(field, format!("{a}–{b} is already cut (event[{since}])"));
                return false;
            }
            Err(Conflict::NotDown) => {
                c.err(field, format!("{a}–{b} is not cut at t = {t} s"));
                return false;
            }
        }
        true
    }

    /// Whether both ends of `link` are known (the leader is 0); reports those that are not.
    fn unknown_ids(&self, c: &mut Ctx, field: &str, link: [u32; 2]) -> bool {
        let mut ok = true;
        for id in link
            .into_iter()
            .filter(|&id| id != 0 && !self.world.ids.contains(id))
        {
            c.err(field.to_string(), format!("agent {id} does not exist"));
            ok = false;
        }
        if link[0] == link[1] {
            c.err(
                field.to_string(),
                format!("{}–{} is not a link", link[0], link[1]),
            );
            ok = false;
        }
        ok
    }

    /// Whether `link`'s ids are all known and distinct (its problems already reported otherwise).
    fn unknown_ids_silent(&self, link: [u32; 2]) -> bool {
        link[0] != link[1]
            && link
                .iter()
                .all(|&id| id == 0 || self.world.ids.contains(id))
    }

    /// `agent = id` with `action = "silence"` or `"resume"`.
    fn agent(
        &mut self,
        c: &mut Ctx,
        f: &str,
        id: u32,
        action: AgentAction,
        (step, k, forget): (u64, usize, bool),
    ) -> bool {
        if !self.world.ids.contains(id) {
            c.err(format!("{f}.agent"), format!("agent {id} does not exist"));
            return false;
        }
        let field = format!("{f}.action");
        let t = step as f64 * self.world.dt;
        let up = action != AgentAction::Silence;
        match switch(&mut self.silent, id, up, (step, k, forget)) {
            Ok(Some(o)) => {
                let arcs = self.world.arcs_out(id);
                self.down(&arcs, o);
            }
            Ok(None) => {}
            Err(Conflict::Already(since)) => {
                c.err(
                    field,
                    format!("agent {id} is already silent (event[{since}])"),
                );
                return false;
            }
            Err(Conflict::NotDown) => {
                c.err(field, format!("agent {id} is not silent at t = {t} s"));
                return false;
            }
        }
        true
    }

    /// `agent = id` with `action = "crash"` (`up` false) or `"restart"`
    /// (`up` true): its receivers' outage (holding) over the time it is
    /// down, and its own crash.
    fn crash(
        &mut self,
        c: &mut Ctx,
        f: &str,
        id: u32,
        up: bool,
        (step, k, initial): (u64, usize, bool),
    ) -> Option<What> {
        if !self.world.ids.contains(id) {
            c.err(format!("{f}.agent"), format!("agent {id} does not exist"));
            return None;
        }
        let field = format!("{f}.action");
        if self.world.plugins.contains(&id) {
            c.err(field, format!("agent {id} is a plug-in: only a built-in agent can crash and restart (the orchestrator cannot stop a plug-in at a step; silence and resume model a plug-in that stops talking)"));
            return None;
        }
        let t = step as f64 * self.world.dt;
        if !up {
            if let Some(&(_, since)) = self.crashed.get(&id) {
                c.err(
                    field,
                    format!("agent {id} is down already (event[{since}])"),
                );
                return None;
            }
            self.crashed.insert(id, (step, k));
            return Some(What::Crash { agent: id });
        }
        let Some((from, _)) = self.crashed.remove(&id) else {
            c.err(field, format!("agent {id} has not crashed by t = {t} s"));
            return None;
        };
        let gap = self.world.restart_gap();
        if step - from < gap {
            c.err(field, format!("restarts agent {id} {} steps after its crash: a restart comes at least {gap} steps ({} s) after it, more than {RESTART_GAP_EXCHANGES} exchanges (what the crashed process may have left unread in its buffers)", step - from, gap as f64 * self.world.dt));
            return None;
        }
        if let Some(Coupling::Sampled { every }) = self.world.coupling
            && step % every != 0
        {
            c.err(field, format!("restarts agent {id} at step {step}, between exchanges: with coupling = \"sampled\" a restart falls on an exchange (a multiple of {every} steps)"));
            return None;
        }
        self.down(
            &self.world.arcs_out(id),
            Outage {
                from,
                to: step,
                forget: false,
            },
        );
        let crash = Crash {
            from,
            to: Some(step),
            initial,
        };
        self.out.timed.crashes.entry(id).or_default().push(crash);
        Some(What::Restart { agent: id, initial })
    }

    /// `set` of `path` (its field in the file: `field`) to `value`: a
    /// scheme gain or the constant reference.
    fn set(
        &mut self,
        c: &mut Ctx,
        field: &str,
        path: &str,
        value: &SetValue,
        step: u64,
    ) -> Option<What> {
        let what = |value, attitude| What::Set {
            field: path.to_string(),
            value,
            attitude,
        };
        if path == "leader.attitude" {
            let SetValue::Rotation(spec) = value else {
                c.err(
                    field.to_string(),
                    "must be a rotation (axis + angle, quaternion or matrix)",
                );
                return None;
            };
            if self.world.reference != ReferenceKind::Constant {
                c.err(
                    field.to_string(),
                    "only a constant reference (leader.reference = \"constant\") can be re-pointed",
                );
                return None;
            }
            let r0 = c.rotation(field, spec)?;
            self.out.timed.repoint.push(Repoint { step, r0 });
            return Some(what(None, Some(r0.transpose().into())));
        }
        let SetValue::Number(x) = *value else {
            c.err(
                field.to_string(),
                format!("must be a number ({path} is a gain)"),
            );
            return None;
        };
        let scheme = retuned(c, field, path, self.scheme?, x)?;
        self.scheme = Some(scheme);
        self.out.timed.retune.push(Retune { step, scheme });
        Some(what(Some(x), None))
    }

    fn down(&mut self, arcs: &[(u32, u32)], o: Outage) {
        if o.from < o.to {
            for a in arcs {
                self.out.timed.down.entry(*a).or_default().push(o);
            }
        }
    }

    /// The links and agents still down at the end: down to the last step;
    /// outages merged; the agents they cut off.
    fn finish(mut self, c: &mut Ctx) -> Timeline {
        let end = self.world.steps;
        let open = |(from, _, forget): (u64, usize, bool)| Outage {
            from,
            to: end,
            forget,
        };
        for (link, since) in std::mem::take(&mut self.cut) {
            let arcs = self.world.arcs_of(link).unwrap_or_default();
            self.down(&arcs, open(since));
        }
        for (id, since) in std::mem::take(&mut self.silent) {
            let arcs = self.world.arcs_out(id);
            self.down(&arcs, open(since));
        }
        for (id, (from, _)) in std::mem::take(&mut self.crashed) {
            let arcs = self.world.arcs_out(id);
            self.down(
                &arcs,
                Outage {
                    from,
                    to: end,
                    forget: false,
                },
            );
            let crash = Crash {
                from,
                to: None,
                initial: false,
            };
            self.out.timed.crashes.entry(id).or_default().push(crash);
        }
        for outages in self.out.timed.down.values_mut() {
            *outages = merged(std::mem::take(outages));
        }
        self.out.isolated = isolated(self.world, &self.out.timed.down);
        for i in &self.out.isolated {
            let ids: Vec<String> = i.agents.iter().map(u32::to_string).collect();
            let s = if ids.len() == 1 { "" } else { "s" };
            c.warn(
                "event",
                format!(
                    "agent{s} {} unreachable from the leader during [{}, {}) s",
                    ids.join(", "),
                    i.from,
                    i.to
                ),
            );
        }
        self.out
    }
}

/// Why an event cannot start or end an outage.
enum Conflict {
    /// It is down already, since this event.
    Already(usize),
    /// It is not down.
    NotDown,
}

/// Starts (`up` false) or ends (`up` true) the outage of `key` among the
/// `open` ones (each: since (step, event index, forget)) at `step`, by
/// event `k`: the outage it ends, if it ends one.
fn switch<K: Ord>(
    open: &mut BTreeMap<K, (u64, usize, bool)>,
    key: K,
    up: bool,
    (step, k, forget): (u64, usize, bool),
) -> Result<Option<Outage>, Conflict> {
    match (up, open.get(&key).copied()) {
        (false, Some((_, since, _))) => Err(Conflict::Already(since)),
        (false, None) => {
            open.insert(key, (step, k, forget));
            Ok(None)
        }
        (true, None) => Err(Conflict::NotDown),
        (true, Some((from, _, forget))) => {
            open.remove(&key);
            Ok(Some(Outage {
                from,
                to: step,
                forget,
            }))
        }
    }
}

/// `outages` sorted by (mode, start), overlapping or touching ones of the
/// same mode joined (a step may be in a holding and a forgetting outage).
fn merged(mut outages: Vec<Outage>) -> Vec<Outage> {
    outages.sort_unstable_by_key(|o| (o.forget, o.from, o.to));
    let mut out: Vec<Outage> = Vec::with_capacity(outages.len());
    for o in outages {
        match out.last_mut() {
            Some(last) if o.forget == last.forget && o.from <= last.to => {
                last.to = last.to.max(o.to)
            }
            _ => out.push(o),
        }
    }
    out
}

/// The agents reachable from the leader over the links up at step `n`.
fn reached(
    arcs: &[(u32, u32)],
    down: &BTreeMap<(u32, u32), Vec<Outage>>,
    n: Option<u64>,
) -> BTreeSet<u32> {
    let up = |a: &(u32, u32)| {
        n.is_none_or(|n| !down.get(a).is_some_and(|os| os.iter().any(|o| o.covers(n))))
    };
    let mut out: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for a in arcs.iter().filter(|a| up(a)) {
        out.entry(a.0).or_default().push(a.1);
    }
    let mut seen = BTreeSet::new();
    let mut stack = vec![0];
    while let Some(x) = stack.pop() {
        for &y in out.get(&x).into_iter().flatten() {
            if seen.insert(y) {
                stack.push(y);
            }
        }
    }
    seen
}

/// The intervals in which the outages leave agents unreachable that the
/// whole graph reaches, consecutive intervals with the same agents joined.
fn isolated(world: &World<'_>, down: &BTreeMap<(u32, u32), Vec<Outage>>) -> Vec<Isolation> {
    if down.is_empty() {
        return Vec::new();
    }
    let arcs = world.all_arcs();
    let always = reached(&arcs, down, None);
    let mut bounds: BTreeSet<u64> = down
        .values()
        .flatten()
        .flat_map(|o| [o.from, o.to])
        .collect();
    bounds.insert(world.steps);
    let bounds: Vec<u64> = bounds.into_iter().filter(|&b| b <= world.steps).collect();
    let mut out: Vec<Isolation> = Vec::new();
    for w in bounds.windows(2) {
        let now = reached(&arcs, down, Some(w[0]));
        let agents: Vec<u32> = always.difference(&now).copied().collect();
        let (from, to) = (w[0] as f64 * world.dt, w[1] as f64 * world.dt);
        match out.last_mut() {
            Some(last) if last.agents == agents && last.to == from => last.to = to,
            _ if agents.is_empty() => {}
            _ => out.push(Isolation { from, to, agents }),
        }
    }
    out
}

/// `scheme` with gain `path` set to `x`; `None` (with an error) if the
/// scheme has no such gain or `x` is not a gain.
fn retuned(c: &mut Ctx, field: &str, path: &str, mut scheme: Scheme, x: f64) -> Option<Scheme> {
    let gain = match (&mut scheme, path) {
        (
            Scheme::ObserverTimeVarying { control, .. }
            | Scheme::ObserverConstant { control, .. }
            | Scheme::Observerless { control },
            "scheme.control.k_r",
        ) => &mut control.k_r,
        (
            Scheme::ObserverTimeVarying { control, .. }
            | Scheme::ObserverConstant { control, .. }
            | Scheme::Observerless { control },
            "scheme.control.k_omega",
        ) => &mut control.k_w,
        (
            Scheme::ObserverTimeVarying { observer, .. }
            | Scheme::ObserverConstant { observer, .. },
            "scheme.observer.k_r",
        ) => &mut observer.k_r,
        (
            Scheme::ObserverTimeVarying { observer, .. }
            | Scheme::ObserverConstant { observer, .. },
            "scheme.observer.k_omega",
        ) => &mut observer.k_w,
        (Scheme::ObserverTimeVarying { observer, .. }, "scheme.observer.k_sigma") => {
            &mut observer.k_sigma
        }
        _ => {
            c.err(
                field.to_string(),
                format!(
                    "{path} cannot be set by an event of this scenario: settable are {SETTABLE}"
                ),
            );
            return None;
        }
    };
    if !(x.is_finite() && x > 0.0) {
        c.err(
            field.to_string(),
            format!("must be a finite gain > 0, got {x}"),
        );
        return None;
    }
    *gain = x;
    Some(scheme)
}

/// What `set` can change, as the error says it.
const SETTABLE: &str = "scheme.control.k_r, scheme.control.k_omega, scheme.observer.k_r, scheme.observer.k_omega, scheme.observer.k_sigma (the scheme's own gains) and leader.attitude (a constant reference)";
