//! Generated scenarios: `attsync gen tree` builds a random tree of agents
//! with seeded, reproducible values (ChaCha8 stream), then picks scheme 1's
//! `k_ω` and `k_σ` (Theorem 1's condition with a margin, balanced), `dt`
//! (RK4's stable step) so that the scenario validates and stays finite, and
//! the duration (the slowest linear mode) so that it converges.

use crate::options::StiffnessCheck;
use crate::scenario::resolve::{kind_name, stable_dt};
use crate::scenario::schema::{
    AgentSpec, ControlGainsSpec, CouplingKind, EdgeSpec, LeaderLinkSpec, LeaderSpec, MatrixSpec,
    ObserverGainsSpec, ObserverInit, Output, ReferenceKind, RotationSpec, Scenario, SchemeKind,
    SchemeSpec, Simulation,
};
use attitude::spectrum::{
    appendix_d_balanced_gain, appendix_d_k_sigma_threshold, appendix_d_min_eigenvalue_from_extremes,
};
use rand::seq::index::sample;
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
    /// Set when an explicit `--duration` is shorter than the estimate of
    /// the time to converge (`attsync gen` prints it on stderr).
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
/// linear mode to decay (`pick_duration`, [`CONVERGE_MULTIPLE`]).
pub fn tree(p: &TreeParams) -> Result<Generated, String> {
    if p.agents == 0 {
        return Err("--agents must be ≥ 1".into());
    }
    if p.leader_links == 0 || p.leader_links > p.agents {
        return Err(format!("--leader-links must be in 1..={}", p.agents));
    }
    // The draws, in this order, are the seed's contract: agents, edges, links.
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let has_obs = p.scheme != SchemeKind::Observerless;
    let agents = (1..=p.agents)
        .map(|id| random_agent(&mut rng, id, p.scheme))
        .collect();
    let (c_edge, c_link) = if has_obs { (10.0, 14.0) } else { (3.0, 5.0) };
    let edges = (2..=p.agents)
        .map(|k| EdgeSpec {
            agents: [rng.random_range(1..k), k],
            gain: diag(c_edge, rng.random_range(0.0..5.0)),
        })
        .collect();
    let leader_links = random_leader_links(&mut rng, p, c_link);
    let (scheme, leader) = paper_scheme_and_leader(p.scheme);
    let mut scenario = Scenario {
        name: Some(format!(
            "tree-{}-{}-seed{}",
            p.agents, p.leader_links, p.seed
        )),
        description: Some(format!(
            "Random tree: {} agents, {} leader links, seed {} (attsync gen tree).",
            p.agents, p.leader_links, p.seed
        )),
        simulation: Simulation {
            dt: 0.001,
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
        guard: Default::default(),
        monte_carlo: None,
    };
    let mut notes: Vec<String> = [pick_gains(&mut scenario), pick_dt(&mut scenario)]
        .into_iter()
        .flatten()
        .collect();
    let (note, warning) = pick_duration(&mut scenario, p.duration);
    notes.extend(note);
    Ok(Generated {
        scenario,
        notes,
        warning,
    })
}

/// A gain matrix like the paper's: `diag(c+m, c+1+m, c+2+m)` (SPD, distinct eigenvalues).
fn diag(c: f64, m: f64) -> MatrixSpec {
    MatrixSpec::Diagonal([c + m, c + 1.0 + m, c + 2.0 + m])
}

/// Agent `id` with a random inertia, initial state and (observer schemes)
/// control gain and observer initial state.
fn random_agent(rng: &mut ChaCha8Rng, id: u32, scheme: SchemeKind) -> AgentSpec {
    let has_obs = scheme != SchemeKind::Observerless;
    let inertia = MatrixSpec::Diagonal([
        rng.random_range(0.1..1.0),
        rng.random_range(0.1..1.0),
        rng.random_range(0.1..1.0),
    ]);
    let attitude = random_rotation(rng);
    let omega = random_vec(rng, 1.0);
    let control_gain = has_obs.then(|| diag(10.0, rng.random_range(0.0..5.0)));
    let observer = has_obs.then(|| ObserverInit {
        attitude: random_rotation(rng),
        omega: random_vec(rng, 1.0),
        sigma: (scheme == SchemeKind::ObserverTimeVarying).then(|| random_vec(rng, 0.5)),
    });
    AgentSpec {
        id,
        inertia,
        attitude,
        omega,
        control_gain,
        observer,
        command: None,
        env: None,
    }
}

/// `p.leader_links` distinct agents that hear the leader, with gains `diag(c, …)`.
fn random_leader_links(rng: &mut ChaCha8Rng, p: &TreeParams, c: f64) -> Vec<LeaderLinkSpec> {
    let mut linked: Vec<u32> = sample(rng, p.agents as usize, p.leader_links as usize)
        .into_iter()
        .map(|i| i as u32 + 1)
        .collect();
    linked.sort_unstable();
    linked
        .into_iter()
        .map(|agent| LeaderLinkSpec {
            agent,
            gain: diag(c, rng.random_range(0.0..5.0)),
        })
        .collect()
}

/// The paper's gains and reference for `kind`.
fn paper_scheme_and_leader(kind: SchemeKind) -> (SchemeSpec, LeaderSpec) {
    let scheme = |observer, k_r, k_omega| SchemeSpec {
        kind,
        observer,
        control: ControlGainsSpec { k_r, k_omega },
        law: Default::default(),
    };
    match kind {
        SchemeKind::ObserverTimeVarying => (
            scheme(
                Some(ObserverGainsSpec {
                    k_r: 9.0,
                    k_omega: 14.0,
                    k_sigma: Some(12.0),
                }),
                8.0,
                13.0,
            ),
            LeaderSpec {
                reference: ReferenceKind::TimeVarying,
                p: Some(PAPER_P),
                attitude: RotationSpec {
                    axis: Some([1.0, 4.0, 2.0]),
                    angle_pi: Some(0.8),
                    ..Default::default()
                },
                omega: Some([1.0, 2.0, 0.0]),
                sigma: Some([0.2, 1.0, 0.0]),
            },
        ),
        SchemeKind::ObserverConstant => (
            scheme(
                Some(ObserverGainsSpec {
                    k_r: 14.0,
                    k_omega: 12.0,
                    k_sigma: None,
                }),
                13.0,
                11.0,
            ),
            constant_leader(),
        ),
        SchemeKind::Observerless => (scheme(None, 1.9, 1.9), constant_leader()),
    }
}

/// Margin of the generated `k_σ` over the smallest one for which the matrix
/// F of Appendix D is positive definite.
pub const K_SIGMA_MARGIN: f64 = 1.25;

/// The generated `dt` is at most this fraction of the largest stable RK4
/// step (`docs/stiffness.md`), rounded down to `0.001 / n`.
pub const DT_FRACTION: f64 = 0.5;

/// The paper's step, s; a generated `dt` is it divided by a round number.
const PAPER_DT: f64 = 0.001;

/// For scheme 1, Theorem 1's gain condition (`F > 0`, Appendix D). The
/// paper's gains when `k_σ = 12 ≥ K_SIGMA_MARGIN · k_σ*(k_ω = 14)`
/// ([`appendix_d_k_sigma_threshold`]); otherwise `k_ω = k_σ = k`, the
/// smallest equal pair with `k_σ ≥ K_SIGMA_MARGIN · k_σ*(k_ω = k)` (the
/// condition is on the product, [`appendix_d_balanced_gain`]: equal gains
/// keep the fastest mode, `∝ max(k_ω, k_σ)`, and so the step, as large as
/// possible). Confirmed by the exact test. Returns the reason, for the
/// file's header.
fn pick_gains(s: &mut Scenario) -> Option<String> {
    let r = crate::scenario::resolve::resolve_with(s, StiffnessCheck::Warn).ok()?;
    let o = s.scheme.observer.as_mut()?;
    let paper = o.k_sigma?;
    let p = r.network.p;
    // The thresholds are decreasing in λ > 0: λmin decides them.
    let ext = r.spectrum_extremes;
    let paper_ok = K_SIGMA_MARGIN * appendix_d_k_sigma_threshold(ext, o.k_omega, &p) <= paper;
    let (mut k_w, mut k_s) = if paper_ok {
        (o.k_omega, paper)
    } else {
        let k = appendix_d_balanced_gain(ext, &p, K_SIGMA_MARGIN).max(o.k_omega.max(paper));
        (k, k)
    };
    // The exact test, once: a round-off at the boundary only ever asks for more.
    for _ in 0..8 {
        if appendix_d_min_eigenvalue_from_extremes(ext, k_w, k_s, &p) > 0.0 {
            break;
        }
        (k_w, k_s) = (k_w * 2.0, k_s * 2.0);
    }
    (o.k_omega, o.k_sigma) = (k_w, Some(k_s));
    let threshold = appendix_d_k_sigma_threshold(ext, k_w, &p);
    Some(if paper_ok {
        format!(
            "k_sigma = {k_s}, k_omega = {k_w} (the paper's): F of Appendix D (Theorem 1's gain condition) is positive definite iff k_sigma > {threshold:.4e}, and {K_SIGMA_MARGIN} × that <= {paper}"
        )
    } else {
        format!(
            "k_sigma = k_omega = {k_s:.4}: F of Appendix D (Theorem 1's gain condition) is positive definite iff k_sigma > {threshold:.4e} at this k_omega; the condition is on the product k_sigma·k_omega, so both are raised together to the smallest equal pair with k_sigma >= {K_SIGMA_MARGIN} × that (the paper's {paper} is too small for this graph; docs/stiffness.md)"
        )
    })
}

/// `dt ≤ DT_FRACTION · dt_max` as `0.001 / n` (so that the default sample
/// period and any duration in ms stay whole multiples). Returns the reason.
fn pick_dt(s: &mut Scenario) -> Option<String> {
    let r = crate::scenario::resolve::resolve_with(s, StiffnessCheck::Warn).ok()?;
    let est = r.stiffness?;
    let b = est.binding()?.clone();
    let dt = stable_dt(PAPER_DT, DT_FRACTION * est.dt_max);
    s.simulation.dt = dt;
    Some(format!(
        "dt = {dt} s: the largest stable RK4 step of the linearised loops is {:.3e} s ({} loop, fastest mode {:.3e} 1/s; docs/stiffness.md); generated as {PAPER_DT}/n <= {DT_FRACTION} × that",
        est.dt_max, b.name, b.fastest_rate
    ))
}

/// The duration when `--duration` is not given, at least, s.
pub const DEFAULT_DURATION: f64 = 40.0;

/// The estimated time to converge is this multiple of the slowest linear
/// mode's time to decay by 1e6 (`ln(1e6) / rate`): the linear estimate
/// ignores the nonlinear transient from large initial errors
/// (`docs/stiffness.md`, "How long a generated network needs").
pub const CONVERGE_MULTIPLE: f64 = 4.0;

/// The estimated time for every loop to converge, s:
/// `CONVERGE_MULTIPLE · ln(1e6) / slowest_rate`, and the loop and rate.
fn converge_time(s: &Scenario) -> Option<(f64, &'static str, f64)> {
    let r = crate::scenario::resolve::resolve_with(s, StiffnessCheck::Warn).ok()?;
    let slow = r.stiffness?.slowest()?.clone();
    let t = CONVERGE_MULTIPLE * 1e6f64.ln() / slow.slowest_rate;
    t.is_finite().then_some((t, slow.name, slow.slowest_rate))
}

/// `simulation.duration`: the given one, with a note and a warning when the
/// estimate says it is too short to converge; else
/// `max(DEFAULT_DURATION, the estimate)` rounded up to a whole 10 s (a
/// whole multiple of every generated `dt`). Returns (note, warning).
fn pick_duration(s: &mut Scenario, given: Option<f64>) -> (Option<String>, Option<String>) {
    let Some((t, name, rate)) = converge_time(s) else {
        return (None, None);
    };
    let why = format!(
        "the slowest linear mode ({name} loop) decays at {rate:.3e} 1/s, so converging needs about {CONVERGE_MULTIPLE} × ln(1e6)/rate = {t:.0} s (docs/stiffness.md)"
    );
    match given {
        Some(d) if d < t => {
            let w = format!(
                "duration = {d} s (as given) is shorter than the estimate: {why}; the run may not converge"
            );
            (Some(w.clone()), Some(w))
        }
        Some(d) => (Some(format!("duration = {d} s (as given): {why}")), None),
        None => {
            let d = DEFAULT_DURATION.max((t / 10.0).ceil() * 10.0);
            s.simulation.duration = d;
            (
                Some(format!(
                    "duration = {d} s: {why}; generated as max({DEFAULT_DURATION}, that) rounded up to 10 s"
                )),
                None,
            )
        }
    }
}

fn constant_leader() -> LeaderSpec {
    LeaderSpec {
        reference: ReferenceKind::Constant,
        p: None,
        attitude: RotationSpec {
            axis: Some([1.0, 4.0, 2.0]),
            angle_pi: Some(0.8),
            ..Default::default()
        },
        omega: None,
        sigma: None,
    }
}

fn random_vec(rng: &mut ChaCha8Rng, a: f64) -> [f64; 3] {
    [
        rng.random_range(-a..a),
        rng.random_range(-a..a),
        rng.random_range(-a..a),
    ]
}

fn random_rotation(rng: &mut ChaCha8Rng) -> RotationSpec {
    let mut axis = random_vec(rng, 1.0);
    if axis.iter().all(|x| x.abs() < 1e-3) {
        axis = [0.0, 0.0, 1.0];
    }
    RotationSpec {
        axis: Some(axis),
        angle_deg: Some(rng.random_range(0.0..170.0)),
        ..Default::default()
    }
}
