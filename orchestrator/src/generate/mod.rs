//! Generated scenarios: `attsync gen tree` builds a random tree of agents
//! with seeded, reproducible values (ChaCha8 stream), then picks scheme 1's
//! `k_ω` and `k_σ` (Theorem 1's condition with a margin, balanced), `dt`
//! (RK4's stable step) so that the scenario validates and stays finite, and
//! the duration (the slowest linear mode, within the step limit) so that it
//! converges; the file is written as it is made, and `check` accepts it.
//!
//! # Layout
//! - `draw` — the random draws (agents, edges, leader links, in the seed's
//!   order) and the paper's gains and reference per scheme;
//! - `pick` — `k_ω`, `k_σ`, `dt` and the duration, from one resolve;
//! - `write` — the file: header, notes and the scenario as TOML, streamed
//!   ([`write_file`], [`write_scenario`]: the bytes of `toml::to_string`).

mod draw;
mod error;
mod pick;
mod write;

pub use error::TreeError;
pub use pick::{CONVERGE_MULTIPLE, DEFAULT_DURATION, DT_FRACTION, K_SIGMA_MARGIN};
pub use write::{WriteError, write_file, write_scenario};

use crate::scenario::resolve::{kind_name, timing_issues};
use crate::scenario::schema::{CouplingKind, EdgeSpec, Output, Scenario, SchemeKind, Simulation};
use draw::{diag, paper_scheme_and_leader, random_agent, random_leader_links};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Parameters of a random tree.
#[derive(Debug, Clone)]
pub struct TreeParams {
    /// Number of agents (≥ 1).
    pub agents: u32,
    /// Number of agents that hear the leader (1..=agents).
    pub leader_links: u32,
    /// RNG seed.
    pub seed: u64,
    /// Scheme (gains are the paper's for that scheme).
    pub scheme: SchemeKind,
    /// Horizon, s (`None`: [`DEFAULT_DURATION`] or longer, as the slowest
    /// linear mode needs; see [`CONVERGE_MULTIPLE`]).
    pub duration: Option<f64>,
}

impl TreeParams {
    /// `gen tree`'s `--agents` (≥ 1), `--leader-links` (1..=agents) and
    /// `--duration` (finite, > 0).
    ///
    /// # Errors
    /// The first option out of its range.
    pub fn check(&self) -> Result<(), crate::options::OptionError> {
        use crate::options::{count, positive};
        count("--agents", u64::from(self.agents), 1, u64::MAX)?;
        let links = u64::from(self.leader_links);
        count("--leader-links", links, 1, u64::from(self.agents))?;
        self.duration.map_or(Ok(()), |d| positive("--duration", d))
    }
}

impl TreeParams {
    /// The command that generates this tree, every parameter given (the
    /// first line of the file `attsync gen tree` writes).
    #[must_use]
    pub fn command_line(&self) -> String {
        let mut c = format!(
            "attsync gen tree --agents {} --leader-links {} --seed {} --scheme {}",
            self.agents,
            self.leader_links,
            self.seed,
            kind_name(self.scheme)
        );
        if let Some(d) = self.duration {
            c.push_str(&format!(" --duration {d}"));
        }
        c
    }
}

/// `P` of the paper's experiment: a decaying mode and an oscillating pair `±i/√2`.
pub const PAPER_P: [[f64; 3]; 3] = [
    [-1.0, 0.0, 0.0],
    [0.0, 0.0, -std::f64::consts::FRAC_1_SQRT_2],
    [0.0, std::f64::consts::FRAC_1_SQRT_2, 0.0],
];

/// A generated scenario and why its `k_σ` and `dt` are what they are.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The scenario.
    pub scenario: Scenario,
    /// One line per choice made to keep it valid and stable (the file's
    /// header comments).
    pub notes: Vec<String>,
    /// Set when the duration is shorter than the estimate of the time to
    /// converge: an explicit `--duration`, or the horizon clamped to the
    /// step limit (`attsync gen` prints it on stderr).
    pub warning: Option<String>,
}

/// A random tree: agent k ≥ 2 attaches to a uniformly chosen agent < k;
/// `leader_links` distinct agents hear the leader. Inertias, initial states
/// and gain offsets are drawn uniformly; every gain matrix is
/// `diag(c+m, c+1+m, c+2+m)` like the paper's, so it is SPD with distinct
/// eigenvalues. The reference excites P's oscillating mode (σ₀(0) = [0.2, 1, 0]).
/// Scheme 1's `k_ω`, `k_σ` satisfy Theorem 1's gain condition with a margin
/// ([`K_SIGMA_MARGIN`], `pick_gains`), and `dt` is within RK4's stable step
/// ([`DT_FRACTION`]), so the scenario passes `attsync check` and stays
/// finite; without `p.duration` the horizon is long enough for the slowest
/// linear mode to decay (`pick_duration`, [`CONVERGE_MULTIPLE`]), or as long
/// as `check`'s step limit allows.
///
/// # Errors
/// Parameters out of range, or a given duration `check` would refuse with
/// the picked `dt` (not a whole multiple of it, or beyond the step limit).
pub fn tree(p: &TreeParams) -> Result<Generated, TreeError> {
    if p.agents == 0 {
        return Err(TreeError::NoAgents);
    }
    if p.leader_links == 0 || p.leader_links > p.agents {
        return Err(TreeError::LeaderLinks { agents: p.agents });
    }
    let mut scenario = draw_tree(p);
    let (notes, warning) = match pick::Analysis::of(&mut scenario) {
        Some(a) => pick::pick(&mut scenario, &a, p.duration),
        None => (Vec::new(), None),
    };
    if let Some(issue) = timing_issues(&scenario.simulation, &scenario.output).first() {
        let dt = scenario.simulation.dt;
        let issue = issue.to_string();
        return Err(match p.duration {
            Some(duration) => TreeError::Duration {
                duration,
                issue,
                dt,
            },
            None => TreeError::TooFine { issue, dt },
        });
    }
    Ok(Generated {
        scenario,
        notes,
        warning,
    })
}

/// The drawn scenario (`dt` = 1 ms, the paper's gains; the draws, in this
/// order, are the seed's contract: agents, edges, links).
fn draw_tree(p: &TreeParams) -> Scenario {
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let has_obs = p.scheme != SchemeKind::Observerless;
    let agents = (1..=p.agents)
        .map(|id| random_agent(&mut rng, id, p.scheme))
        .collect();
    let (c_edge, c_link) = if has_obs { (10.0, 14.0) } else { (3.0, 5.0) };
    let edges = (2..=p.agents)
        .map(|k| EdgeSpec {
            agents: Some([rng.random_range(1..k), k]),
            from: None,
            to: None,
            gain: diag(c_edge, rng.random_range(0.0..5.0)),
        })
        .collect();
    let leader_links = random_leader_links(&mut rng, p, c_link);
    let (scheme, leader) = paper_scheme_and_leader(p.scheme);
    Scenario {
        name: Some(format!(
            "tree-{}-{}-seed{}",
            p.agents, p.leader_links, p.seed
        )),
        description: Some(format!(
            "Random tree: {} agents, {} leader links, seed {} (attsync gen tree).",
            p.agents, p.leader_links, p.seed
        )),
        simulation: Simulation {
            dt: pick::PAPER_DT,
            duration: p.duration.unwrap_or(DEFAULT_DURATION),
            coupling: CouplingKind::Continuous,
            period: None,
        },
        output: Output::default(),
        scheme,
        leader,
        leader_links,
        agents,
        edges,
        network: Default::default(),
        actuator: None,
        disturbances: Vec::new(),
        sensor: None,
        controller: None,
        graph: Default::default(),
        guard: Default::default(),
        monte_carlo: None,
        events: Vec::new(),
    }
}
