//! Generated scenarios: `attsync gen tree` builds a random tree of agents
//! with seeded, reproducible values (ChaCha8 stream).

use crate::scenario::schema::{
    AgentSpec, ControlGainsSpec, CouplingKind, EdgeSpec, LeaderLinkSpec, LeaderSpec, MatrixSpec,
    ObserverGainsSpec, ObserverInit, Output, ReferenceKind, RotationSpec, Scenario, SchemeKind,
    SchemeSpec, Simulation,
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
    /// Horizon, s.
    pub duration: f64,
}

/// `P` of the paper's experiment: a decaying mode and an oscillating pair `±i/√2`.
pub const PAPER_P: [[f64; 3]; 3] = [
    [-1.0, 0.0, 0.0],
    [0.0, 0.0, -std::f64::consts::FRAC_1_SQRT_2],
    [0.0, std::f64::consts::FRAC_1_SQRT_2, 0.0],
];

/// A random tree: agent k ≥ 2 attaches to a uniformly chosen agent < k;
/// `leader_links` distinct agents hear the leader. Inertias, initial states
/// and gain offsets are drawn uniformly; every gain matrix is
/// `diag(c+m, c+1+m, c+2+m)` like the paper's, so it is SPD with distinct
/// eigenvalues. The reference excites P's oscillating mode (σ₀(0) = [0.2, 1, 0]).
pub fn tree(p: &TreeParams) -> Result<Scenario, String> {
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
            duration: p.duration,
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
    };
    raise_k_sigma_until_theorem_1_holds(&mut scenario);
    Ok(scenario)
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

/// For scheme 1, doubles `k_σ` until the matrix F of Appendix D is positive
/// definite (so that Theorem 1 covers the generated network). Deep trees
/// need a larger `k_σ` than the paper's 12.
fn raise_k_sigma_until_theorem_1_holds(s: &mut Scenario) {
    for _ in 0..20 {
        let Ok(r) = crate::scenario::resolve::resolve(s) else {
            return;
        };
        match (r.appendix_d_min_eig, s.scheme.observer.as_mut()) {
            (Some(m), Some(o)) if m <= 0.0 => {
                o.k_sigma = o.k_sigma.map(|k| k * 2.0);
            }
            _ => return,
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
