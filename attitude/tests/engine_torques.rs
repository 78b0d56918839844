//! The in-process engine's samples carry every agent's torque at stage 0
//! of the sampled step (`Snapshot::torques`): the torque a node runtime's
//! agent reports after that stage (`Agent::torque`), bit for bit, on 1, 2
//! and 3 threads, continuous and sampled; NaN at the last step; and a run
//! extended past its horizon gets its former last sample's torques from
//! `InProcess::begin_step`, the rest of the run unchanged.

use attitude::agent::Agent;
use attitude::body::Inertia;
use attitude::control::ControlGains;
use attitude::engine::InProcess;
use attitude::guard::Envelope;
use attitude::network::{AgentModel, AgentSpec, AgentState, Coupling, Neighbour, Network, Scheme};
use attitude::reference::{Leader, LeaderState};
use attitude::so3::rot;
use nalgebra::{Matrix3, Vector3};

/// Step, s.
const DT: f64 = 0.01;
/// Steps of a run.
const STEPS: u64 = 60;
/// Steps between samples.
const EVERY: u64 = 5;

fn diag(c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(c, c + 1.0, c + 2.0))
}

/// A chain of `n` observerless agents (agent 1 hears the leader).
fn chain(n: u32, steps: u64, coupling: Coupling) -> Network {
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
                scheme: Scheme::Observerless {
                    control: ControlGains {
                        k_r: 8.0,
                        k_w: 13.0,
                    },
                },
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
                s_hat: Vector3::zeros(),
            };
            AgentSpec { model, initial }
        })
        .collect();
    let leader = LeaderState {
        r0: Matrix3::identity(),
        w0: Vector3::new(0.1, 0.2, 0.0),
        s0: Vector3::new(0.1, 0.0, 0.0),
    };
    Network {
        agents,
        p,
        leader,
        dt: DT,
        steps,
        coupling,
        sample_every: EVERY,
        guard: Envelope::default(),
        repoint: Vec::new(),
    }
}

/// A sample as bits: step, every agent's state, every agent's torque.
type Bits = (u64, Vec<u64>, Vec<u64>);

fn state_bits(states: &[AgentState]) -> Vec<u64> {
    let words = states.iter().flat_map(|a| {
        let x = a.r.iter().chain(&a.w).chain(&a.r_hat).chain(&a.w_hat);
        x.chain(&a.s_hat).copied().collect::<Vec<_>>()
    });
    words.map(f64::to_bits).collect()
}

fn torque_bits(torques: &[Vector3<f64>]) -> Vec<u64> {
    torques
        .iter()
        .flat_map(|t| t.iter().map(|v| v.to_bits()))
        .collect()
}

/// Every sample of `net` as node runtimes take them, one agent at a time:
/// the state at each sampled step's start and the torque each agent
/// reports after its stage 0 ([`Agent::torque`]), NaN at the last step.
fn one_by_one(net: &Network) -> Vec<Bits> {
    let mut leader = Leader::new(net.p, net.leader, net.dt);
    let mut agents: Vec<Agent> = (net.agents.iter())
        .map(|a| Agent::new(a.model.clone(), a.initial, net.dt))
        .collect();
    let index = net.neighbour_indices();
    let mut out = Vec::new();
    for n in 0..net.steps {
        let states: Vec<AgentState> = agents.iter().map(|a| *a.state()).collect();
        for s in 0..4 {
            if net.coupling.exchanges_at(n, s) {
                let sent: Vec<_> = (agents.iter_mut())
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
            if s == 0 && n % net.sample_every == 0 {
                let torques: Vec<_> = agents.iter().map(Agent::torque).collect();
                out.push((n, state_bits(&states), torque_bits(&torques)));
            }
        }
    }
    let states: Vec<AgentState> = agents.iter().map(|a| *a.state()).collect();
    let nan = vec![Vector3::repeat(f64::NAN); agents.len()];
    out.push((net.steps, state_bits(&states), torque_bits(&nan)));
    out
}

/// Every sample `engine` hands out until its horizon.
fn record(engine: &mut InProcess, out: &mut Vec<Bits>) {
    let diverged = engine.run(|snap| {
        assert_eq!(snap.torques.len(), snap.agents.len());
        let bits = torque_bits(snap.torques);
        out.push((snap.step, state_bits(snap.agents), bits));
        true
    });
    assert!(diverged.is_none());
}

const COUPLINGS: [Coupling; 2] = [Coupling::Continuous, Coupling::Sampled { every: 3 }];

#[test]
fn every_sample_carries_the_torques_of_its_stage_0_on_any_thread_count() {
    for coupling in COUPLINGS {
        let net = chain(7, STEPS, coupling);
        let reference = one_by_one(&net);
        assert_eq!(reference.len() as u64, STEPS / EVERY + 1);
        for threads in [1, 2, 3] {
            let mut engine = InProcess::new(&net).with_exact_threads(threads);
            let mut seen = Vec::new();
            record(&mut engine, &mut seen);
            assert_eq!(seen, reference, "{coupling:?}, {threads} threads");
        }
        let (first, last) = (&reference[0].2, &reference[reference.len() - 1].2);
        assert!(first.iter().all(|b| f64::from_bits(*b).is_finite()));
        assert!(last.iter().all(|b| f64::from_bits(*b).is_nan()));
    }
}

#[test]
fn an_extended_run_completes_its_former_last_sample_with_begin_step() {
    for coupling in COUPLINGS {
        let net = chain(7, STEPS, coupling);
        let reference = one_by_one(&net);
        for threads in [1, 3] {
            let mut short = net.clone();
            short.steps = 30;
            let mut engine = InProcess::new(&short).with_exact_threads(threads);
            let mut seen = Vec::new();
            record(&mut engine, &mut seen);
            assert!(engine.begin_step().is_none(), "at the horizon");
            engine.extend_to(STEPS);
            let torques = engine.begin_step().expect("a step to begin").to_vec();
            let at = seen.len() - 1;
            seen[at].2 = torque_bits(&torques);
            record(&mut engine, &mut seen);
            assert_eq!(seen, reference, "{coupling:?}, {threads} threads");
        }
    }
}

#[test]
fn a_run_stopped_by_its_sample_goes_on_bit_identically() {
    let net = chain(7, STEPS, Coupling::Continuous);
    let reference = one_by_one(&net);
    for threads in [1, 3] {
        let mut engine = InProcess::new(&net).with_exact_threads(threads);
        let mut seen = Vec::new();
        let diverged = engine.run(|snap| {
            seen.push((
                snap.step,
                state_bits(snap.agents),
                torque_bits(snap.torques),
            ));
            snap.step < 20
        });
        assert!(diverged.is_none());
        assert_eq!(engine.step_index(), 20, "stopped within step 20");
        record(&mut engine, &mut seen);
        // Step 20's sample is not handed out again: the run goes on from
        // its stage 1.
        assert_eq!(seen, reference, "{threads} threads");
    }
}
