//! The in-process engine keeps each sender's published value once, on its
//! board, as every receiver holds it (the last trusted value: a receiver
//! refuses an untrusted one and keeps what it had), where the node
//! runtime's agent keeps its own copy (`Agent::receive_neighbour`). Both
//! give the same trajectories and refusal counts, bit for bit: checked on a
//! chain that diverges (its stage states turn untrusted and are refused
//! before the guard stops the run), continuous and sampled, on 1, 2 and 3
//! threads, against agents stepped one by one as a node runtime steps them.

use attitude::agent::Agent;
use attitude::body::Inertia;
use attitude::control::ControlGains;
use attitude::engine::InProcess;
use attitude::guard::Envelope;
use attitude::network::{AgentModel, AgentSpec, AgentState, Coupling, Neighbour, Network, Scheme};
use attitude::reference::{Leader, LeaderState};
use attitude::so3::rot;
use nalgebra::{Matrix3, Vector3};

/// Step, s: far too large, so the chain blows up within a few steps.
const DT: f64 = 0.3;
/// The gains, times the paper's.
const GAIN: f64 = 1.0;

fn diag(c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(c, c + 1.0, c + 2.0))
}

/// Scheme 3 (the body is published, and it is what blows up) with gains
/// `gain` times the paper's.
fn scheme(gain: f64) -> Scheme {
    let control = ControlGains {
        k_r: 8.0 * gain,
        k_w: 13.0 * gain,
    };
    Scheme::Observerless { control }
}

/// A chain of `n` agents (agent 1 hears the leader), `steps` steps of `dt`,
/// a sample every step, an envelope wide enough that only non-finite
/// states stop it.
fn chain(n: u32, dt: f64, steps: u64, coupling: Coupling) -> Network {
    let p = Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, -0.7, 0.0, 0.7, 0.0);
    let axis = Vector3::new(1.0, 2.0, -0.5).normalize();
    let agents = (1..=n)
        .map(|id| {
            let nbr = |j: u32| Neighbour {
                id: j,
                a: diag(1.0 + f64::from(j % 2)),
                link: None,
            };
            let neighbours = [id - 1, id + 1]
                .into_iter()
                .filter(|&j| j >= 1 && j <= n)
                .map(nbr)
                .collect();
            let model = AgentModel {
                id,
                inertia: Inertia::new(diag(0.1 * f64::from(id))),
                a_bar: diag(1.0),
                neighbours,
                leader_gain: (id == 1).then(|| diag(4.0)),
                leader_link: None,
                scheme: scheme(GAIN),
                p,
                law: Default::default(),
                timeline: Default::default(),
                effects: None,
            };
            let r = rot(0.5 + 0.7 * f64::from(id), &axis);
            let initial = AgentState {
                r,
                w: Vector3::new(0.3, -0.2, 0.1) * f64::from(id),
                r_hat: r.transpose(),
                w_hat: Vector3::zeros(),
                s_hat: Vector3::new(0.0, 0.1, 0.0),
            };
            AgentSpec { model, initial }
        })
        .collect();
    let leader = LeaderState {
        r0: Matrix3::identity(),
        w0: Vector3::new(0.1, 0.2, 0.0),
        s0: Vector3::new(0.1, 0.0, 0.0),
    };
    let wide = f64::MAX;
    Network {
        agents,
        p,
        leader,
        dt,
        steps,
        coupling,
        sample_every: 1,
        guard: Envelope {
            omega: wide,
            omega_hat: wide,
            sigma_hat: wide,
        },
        repoint: Vec::new(),
    }
}

/// The bits of every agent's state.
fn bits(states: impl Iterator<Item = AgentState>) -> Vec<u64> {
    states
        .flat_map(|a| {
            let x = a.r.iter().chain(&a.w).chain(&a.r_hat).chain(&a.w_hat);
            x.chain(&a.s_hat).map(|v| v.to_bits()).collect::<Vec<_>>()
        })
        .collect()
}

/// Per agent, values refused on each input.
fn refusals(agents: &[Agent]) -> Vec<Vec<(u32, u64)>> {
    let stats = agents.iter().map(|a| a.link_stats());
    stats
        .map(|s| s.into_iter().map(|(id, l)| (id, l.rejected)).collect())
        .collect()
}

/// `steps` steps of `net` as node runtimes take them: every agent keeps
/// what it receives ([`Agent::receive_neighbour_judged`]); the state bits
/// after every step.
fn one_by_one(net: &Network, steps: u64) -> (Vec<Vec<u64>>, Vec<Agent>) {
    let mut leader = Leader::new(net.p, net.leader, net.dt);
    let mut agents: Vec<Agent> = (net.agents.iter())
        .map(|a| Agent::new(a.model.clone(), a.initial, net.dt))
        .collect();
    let index = net.neighbour_indices();
    let mut out = Vec::new();
    for n in 0..steps {
        for s in 0..4 {
            if net.coupling.exchanges_at(n, s) {
                let sent: Vec<_> = agents
                    .iter_mut()
                    .map(|a| a.stage_exchange_judged())
                    .collect();
                let from_leader = leader.stage_exchange();
                for (a, nbrs) in agents.iter_mut().zip(&index) {
                    for (m, &j) in nbrs.iter().enumerate() {
                        a.receive_neighbour_judged(m, sent[j].0, sent[j].1);
                    }
                    a.receive_leader(from_leader);
                }
            }
            leader.advance();
            agents.iter_mut().for_each(|a| {
                a.advance();
            });
        }
        out.push(bits(agents.iter().map(|a| *a.state())));
    }
    (out, agents)
}

#[test]
fn the_board_holds_what_every_receiver_would() {
    let couplings = [Coupling::Continuous, Coupling::Sampled { every: 3 }];
    for coupling in couplings {
        let net = chain(7, DT, 600, coupling);
        for threads in [1, 2, 3] {
            let mut engine = InProcess::new(&net).with_exact_threads(threads);
            let mut seen = Vec::new();
            let diverged = engine.run(|snap| {
                seen.push(bits(snap.agents.iter().copied()));
                true
            });
            let stopped = diverged.map_or(net.steps, |d| d.step);
            assert!(stopped > 1, "{coupling:?}: the chain runs a while");
            let (reference, agents) = one_by_one(&net, stopped);
            // Samples at t = 0 and after every step before the stop.
            assert_eq!(
                seen[1..],
                reference[..seen.len() - 1],
                "{coupling:?}, {threads}"
            );
            let last = bits(engine.agents().iter().map(|a| *a.state()));
            assert_eq!(
                last,
                reference[reference.len() - 1],
                "{coupling:?}, {threads}"
            );
            let refused = refusals(&agents);
            assert_eq!(
                refusals(engine.agents()),
                refused,
                "{coupling:?}, {threads}"
            );
            let total: u64 = refused.iter().flatten().map(|(_, r)| r).sum();
            // Between exchanges nothing is published, and a step's first
            // value passed the guard: only continuous coupling refuses.
            if coupling == Coupling::Continuous {
                assert!(total > 0, "{coupling:?}: some values were refused");
            }
        }
    }
}

/// `neighbour_indices` (one id map, linear in the edges) gives, for agents
/// stored in any order, what looking each neighbour up by a scan gives:
/// here the chain's agents stored in a shuffled order.
#[test]
fn neighbour_indices_follow_the_ids_in_any_storage_order() {
    let mut net = chain(40, DT, 1, Coupling::Continuous);
    // A fixed permutation: k ↦ 17k mod 40 (17 and 40 coprime).
    let mut shuffled = net.agents.clone();
    for (k, a) in net.agents.iter().enumerate() {
        shuffled[(17 * k) % 40] = a.clone();
    }
    net.agents = shuffled;
    let by_scan: Vec<Vec<usize>> = (net.agents.iter())
        .map(|a| {
            let ids = a.model.neighbours.iter().map(|n| n.id);
            ids.map(|id| net.index_of(id).expect("a known id"))
                .collect()
        })
        .collect();
    assert_eq!(net.neighbour_indices(), by_scan);
    let index = net.index_by_id();
    assert_eq!(index.len(), 40);
    for (k, a) in net.agents.iter().enumerate() {
        assert_eq!(index[&a.model.id], k);
    }
}
