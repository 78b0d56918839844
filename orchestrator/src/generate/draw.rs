//! The random draws of a tree (ChaCha8 stream, in the seed's order) and
//! the paper's gains and reference for each scheme.

use super::PAPER_P;
use super::TreeParams;
use crate::scenario::schema::{
    AgentSpec, ControlGainsSpec, LeaderLinkSpec, LeaderSpec, MatrixSpec, ObserverGainsSpec,
    ObserverInit, ReferenceKind, RotationSpec, SchemeKind, SchemeSpec,
};
use rand::Rng;
use rand::seq::index::sample;
use rand_chacha::ChaCha8Rng;

/// A gain matrix like the paper's: `diag(c+m, c+1+m, c+2+m)` (SPD, distinct eigenvalues).
pub(super) fn diag(c: f64, m: f64) -> MatrixSpec {
    MatrixSpec::Diagonal([c + m, c + 1.0 + m, c + 2.0 + m])
}

/// Agent `id` with a random inertia, initial state and (observer schemes)
/// control gain and observer initial state.
pub(super) fn random_agent(rng: &mut ChaCha8Rng, id: u32, scheme: SchemeKind) -> AgentSpec {
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
        actuator: None,
        sensor: None,
        controller: None,
    }
}

/// `p.leader_links` distinct agents that hear the leader, with gains `diag(c, …)`.
pub(super) fn random_leader_links(
    rng: &mut ChaCha8Rng,
    p: &TreeParams,
    c: f64,
) -> Vec<LeaderLinkSpec> {
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
pub(super) fn paper_scheme_and_leader(kind: SchemeKind) -> (SchemeSpec, LeaderSpec) {
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
