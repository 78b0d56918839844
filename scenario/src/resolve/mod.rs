//! Scenario → [`Network`]: converts units and representations, and checks
//! everything the paper assumes before anything runs. Every problem is an
//! [`Issue`] naming the field (TOML path, 0-based array index) and the reason.
//!
//! [`resolve`] runs one phase per table, each collecting its problems in a
//! shared context; messages come in the order of the phases below.
//!
//! # Layout
//! - `ctx` — the context (errors, warnings) and the checks tables share
//!   (finite, SPD, gain matrices, multiples of `dt`); `rotation` — rotation specs;
//! - `simulation` — `name`, `[simulation]`, `[output]`;
//! - `scheme` — `[scheme]` (with `scheme.law`, the printed law's warning);
//!   `leader` — `[leader]`; `agents` — `[[agent]]`;
//! - `ids` — agent ids and their ranks (per-agent data is kept by rank);
//! - `graph` — `[[edge]]`, `[[leader_link]]` (the forest check), the
//!   adjacency by rank;
//! - `checks` — reachability from the leader, spectrum (sparse: extremes
//!   and count; every eigenvalue only for small N), Appendix D;
//! - `network` — `[network]`, `[[network.link]]`;
//! - `guard` — `[guard]`, the envelope of a sane state;
//! - `assemble` — the [`Network`] from the parts, once there are no errors;
//! - `stiffness` — on the assembled network: `simulation.dt` against RK4's
//!   largest stable step ([`stable_dt`], [`REFUSE_FACTOR`], [`WARN_FROM`]).

mod agents;
mod assemble;
mod body;
mod checks;
mod ctx;
mod events;
mod graph;
mod guard;
mod ids;
mod leader;
mod network;
mod rotation;
mod scheme;
mod simulation;
mod stiffness;
mod theory;

pub use ctx::MAX_STEPS;
pub use events::{Event, Isolation, What};
pub use stiffness::{REFUSE_FACTOR, StiffnessCheck, WARN_FROM, stable_dt};
pub use theory::Departure;

use super::schema::{Output, Scenario, SchemeKind, Simulation};
use attitude::network::{Network, Scheme};
use attitude::stiffness::{Estimate, Interval};
use ctx::Ctx;
use std::collections::BTreeMap;
use std::fmt;

/// One problem in a scenario: the field and what is wrong with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Issue {
    /// TOML path, e.g. `edge[2].gain` (arrays 0-based, in file order).
    pub field: String,
    /// Why it is wrong.
    pub reason: String,
}

impl fmt::Display for Issue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.reason)
    }
}

/// A validated scenario, ready to run.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The network every engine runs.
    pub network: Network,
    /// Problems that do not stop a run (e.g. the gain condition of Appendix D).
    pub warnings: Vec<Issue>,
    /// Follower edges as agent-id pairs (smaller id first), in file order.
    pub edges: Vec<(u32, u32)>,
    /// One-way follower edges (sender, receiver), in file order (`[graph]
    /// assumptions = "off"` only).
    pub arcs: Vec<(u32, u32)>,
    /// Agents that hear the leader, ascending.
    pub leader_links: Vec<u32>,
    /// Eigenvalues of `Ξ + LLᵀ`, ascending, only up to 50 agents (empty
    /// beyond: see `spectrum_extremes`).
    pub spectrum: Vec<f64>,
    /// `(λmin, λmax)` of `Ξ + LLᵀ` (its order is the number of agents).
    pub spectrum_extremes: (f64, f64),
    /// Smallest eigenvalue of Appendix D's `F` (scheme 1 only).
    pub appendix_d_min_eig: Option<f64>,
    /// The fastest linear mode of each loop and RK4's largest stable step
    /// (`None` without agents).
    pub stiffness: Option<Estimate>,
    /// Agents run by the user's own programs.
    pub plugins: Vec<super::plugin::Plugin>,
    /// How the scenario leaves Assumption 1 (`[graph] assumptions =
    /// "off"`); empty inside the paper's theory.
    pub outside_theory: Vec<Departure>,
    /// The `[[event]]`s, in time order, as the run reports them.
    pub events: Vec<Event>,
    /// Agents the events cut off from the leader, and when.
    pub isolated: Vec<Isolation>,
}

/// Validates `s` and resolves it into a [`Network`], refusing a
/// `simulation.dt` clearly beyond the largest stable step. Returns every
/// error found (not only the first).
pub fn resolve(s: &Scenario) -> Result<Resolved, Vec<Issue>> {
    resolve_with(s, StiffnessCheck::Refuse)
}

/// As [`resolve`], with the stiffness verdict `check` (the step-size phase
/// runs last, on an otherwise valid scenario).
pub fn resolve_with(s: &Scenario, check: StiffnessCheck) -> Result<Resolved, Vec<Issue>> {
    let mut c = Ctx {
        theory_off: s.graph.assumptions == crate::schema::Assumptions::Off,
        ..Ctx::default()
    };
    let kind = s.scheme.kind;
    simulation::name(&mut c, s.name.as_ref());
    let time = simulation::simulation(&mut c, &s.simulation, &s.output);
    let scheme = scheme::scheme(&mut c, &s.scheme);
    let law = scheme::law(&mut c, &s.scheme);
    let leader = leader::leader(&mut c, &s.leader, kind);
    let ids = agents::ids(&mut c, &s.agents);
    let bodies = agents::bodies(&mut c, &s.agents, kind, &ids);
    let actuators = agents::actuators(&mut c, s.actuator.as_ref(), &s.agents, &ids);
    let sources = body::Sources {
        agents: &s.agents,
        disturbances: &s.disturbances,
        sensor: s.sensor.as_ref(),
        controller: s.controller.as_ref(),
        seed: s.network.seed,
        dt: time.dt,
        steps: time.steps.unwrap_or(0),
        kind,
    };
    let effects = body::effects(&mut c, &sources, &ids, actuators);
    let edges = graph::edges(&mut c, &s.edges, &ids);
    let links = graph::leader_links(&mut c, &s.leader_links, &ids);
    let ranked = edges.ranks(&ids);
    let arcs = edges.arc_ranks(&ids);
    let adjacency = graph::Adjacency::new(ids.len(), &ranked);
    let any_link = !s.leader_links.is_empty();
    checks::reachability(&mut c, &ids, (&adjacency, &arcs), &links, any_link);
    // One-way edges count once in the spectrum's graph (its undirected skeleton).
    let skeleton = graph::skeleton(&ranked, &arcs);
    let spectrum = checks::spectrum(&mut c, &skeleton, &links, scheme.as_ref(), &leader.p);
    let impaired = if time.dt > 0.0 && time.dt.is_finite() {
        network::network(&mut c, &s.network, time.dt, &edges, &links, &ids)
    } else {
        BTreeMap::new()
    };
    let envelope = guard::guard(&mut c, &s.guard);
    let world = events::World {
        dt: time.dt,
        steps: time.steps.unwrap_or(0),
        scheme,
        reference: s.leader.reference,
        ids: &ids,
        edges: &edges,
        links: &links,
        coupling: time.coupling,
        plugins: (s.agents.iter())
            .filter(|a| a.command.is_some())
            .map(|a| a.id)
            .collect(),
    };
    let timeline = events::events(&mut c, &s.events, &world);
    if !c.errors.is_empty() {
        return Err(c.errors);
    }
    let parts = assemble::Parts {
        scheme,
        time,
        leader,
        bodies,
        impaired,
        guard: envelope,
        law,
        effects,
        timeline: timeline.timed,
    };
    let incoming = edges.incoming(&ids);
    let wiring = assemble::Graph {
        ids: &ids,
        edges: &edges,
        adjacency: &adjacency,
        incoming: &incoming,
        links: &links,
    };
    let network = assemble::network(parts, &wiring);
    // The extremes of Ξ + LLᵀ are all the estimate needs (none without agents).
    let extremes = [spectrum.lambda_min, spectrum.lambda_max];
    let ends = if network.agents.is_empty() {
        &[][..]
    } else {
        &extremes[..]
    };
    let estimate = stiffness::stiffness(&mut c, &network, ends, check);
    if !c.errors.is_empty() {
        return Err(c.errors);
    }
    c.warnings.extend(theory::warning(&c.departures));
    Ok(Resolved {
        network,
        warnings: c.warnings,
        leader_links: links.linked().map(|r| ids.id(r)).collect(),
        edges: edges.pairs,
        arcs: edges.arcs,
        spectrum: spectrum.eigenvalues,
        spectrum_extremes: (spectrum.lambda_min, spectrum.lambda_max),
        appendix_d_min_eig: spectrum.appendix_d_min_eig,
        stiffness: estimate,
        plugins: Vec::new(),
        outside_theory: c.departures,
        events: timeline.events,
        isolated: timeline.isolated,
    })
}

/// The problems `[simulation]` and `[output]` alone have (the first phase
/// of [`resolve`]): a step, horizon, period or sample period `check` refuses.
#[must_use]
pub fn timing_issues(sim: &Simulation, out: &Output) -> Vec<Issue> {
    let mut c = Ctx::default();
    simulation::simulation(&mut c, sim, out);
    c.errors
}

/// The stiffness estimate of `r`'s network under `scheme` (the network's
/// own scheme with other gains, say), as [`resolve`] would give it for the
/// scenario with those gains; `None` without agents.
#[must_use]
pub fn stiffness_with(r: &Resolved, scheme: Scheme) -> Option<Estimate> {
    let (min, max) = r.spectrum_extremes;
    let graph = Interval { min, max };
    let loops = stiffness::loops(&r.network, scheme, graph)?;
    Some(attitude::stiffness::estimate(&loops))
}

impl Resolved {
    /// The warning that `scheme.law = "as-printed"` runs a law known to be
    /// wrong (a negative control), if it does.
    #[must_use]
    pub fn law_warning(&self) -> Option<&Issue> {
        self.warnings.iter().find(|w| w.field == scheme::LAW_FIELD)
    }

    /// The warning that the scenario is outside the paper's theory
    /// (`[graph] assumptions = "off"` and a departure), if it is.
    #[must_use]
    pub fn theory_warning(&self) -> Option<&Issue> {
        self.warnings.iter().find(|w| w.field == theory::FIELD)
    }
}

/// The name of a scheme as written in scenario files.
pub fn kind_name(k: SchemeKind) -> &'static str {
    match k {
        SchemeKind::ObserverTimeVarying => "observer-time-varying",
        SchemeKind::ObserverConstant => "observer-constant",
        SchemeKind::Observerless => "observerless",
    }
}
