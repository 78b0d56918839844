//! The engine's verdict on an agent's own published value
//! (`Agent::stage_exchange_judged`, proven within a step by
//! `attitude::verdict`) is exactly `Exchanged::trust().is_ok()` at every
//! stage: for a network that converges, for one whose `dt` is far too large
//! (its states blow up, turn non-finite, and its attitudes stop being
//! rotations), and for each scheme; with the guard's check of each step's
//! start or without; and for an observerless agent publishing what noisy
//! sensors measure, small errors (proven) and huge ones (checked).

use attitude::agent::Agent;
use attitude::body::Inertia;
use attitude::control::ControlGains;
use attitude::effects::Effects;
use attitude::guard::Envelope;
use attitude::network::{AgentModel, AgentState, Exchanged, Neighbour, Scheme};
use attitude::observer::ObserverGains;
use attitude::reference::{Leader, LeaderState};
use attitude::sensor::{Noise, Sensor};
use attitude::so3::rot;
use nalgebra::{Matrix3, Vector3};

fn diag(c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(c, c + 1.0, c + 2.0))
}

fn schemes(gain: f64) -> [Scheme; 3] {
    let observer = ObserverGains {
        k_r: 9.0 * gain,
        k_w: 14.0 * gain,
        k_sigma: 12.0 * gain,
    };
    let control = ControlGains {
        k_r: 8.0 * gain,
        k_w: 13.0 * gain,
    };
    [
        Scheme::ObserverTimeVarying { observer, control },
        Scheme::ObserverConstant { observer, control },
        Scheme::Observerless { control },
    ]
}

/// How the chain is run: sensors' attitude noise (rad) and the guard.
#[derive(Clone, Copy, Default)]
struct Variant {
    attitude_noise: Option<f64>,
    guard: bool,
}

/// Sensors of attitude noise `std` (and a bias on both quantities).
fn sensors(std: f64, id: u32) -> Box<Effects> {
    Box::new(Effects {
        sensor: Some(Sensor {
            attitude: Noise {
                std,
                bias: [0.0, 1e-3, 0.0],
            },
            rate: Noise {
                std: 1e-3,
                bias: [0.0, 0.0, 1e-4],
            },
            seed: 17 + u64::from(id),
        }),
        ..Effects::default()
    })
}

/// A chain of `n` agents (agent 1 hears the leader) under `scheme`.
fn chain(n: u32, scheme: Scheme, dt: f64, v: Variant) -> (Leader, Vec<Agent>) {
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
                scheme,
                p,
                law: Default::default(),
                timeline: Default::default(),
                effects: v.attitude_noise.map(|std| sensors(std, id)),
            };
            let r = rot(0.5 + 0.7 * f64::from(id), &axis);
            let initial = AgentState {
                r,
                w: Vector3::new(0.3, -0.2, 0.1) * f64::from(id),
                r_hat: r.transpose(),
                w_hat: Vector3::zeros(),
                s_hat: Vector3::new(0.0, 0.1, 0.0),
            };
            Agent::new(model, initial, dt)
        })
        .collect();
    let leader = LeaderState {
        r0: Matrix3::identity(),
        w0: Vector3::new(0.1, 0.2, 0.0),
        s0: Vector3::new(0.1, 0.0, 0.0),
    };
    (Leader::new(p, leader, dt), agents)
}

/// Steps the chain for `steps` steps, continuous coupling, checking every
/// published verdict; returns how many values were trusted and refused.
fn check(scheme: Scheme, dt: f64, steps: usize, v: Variant) -> (usize, usize) {
    let (mut leader, mut agents) = chain(5, scheme, dt, v);
    let (mut yes, mut no) = (0, 0);
    for stage in 0..steps * 4 {
        if v.guard && stage % 4 == 0 {
            for a in &mut agents {
                let _ = a.check(&Envelope::default());
            }
        }
        let mut published: Vec<(Exchanged, bool)> = Vec::new();
        for a in &mut agents {
            let (x, trusted) = a.stage_exchange_judged();
            assert_eq!(trusted, x.trust().is_ok(), "{scheme:?}, {x:?}");
            if trusted {
                yes += 1
            } else {
                no += 1
            }
            published.push((x, trusted));
        }
        let from_leader = leader.stage_exchange();
        for (k, a) in agents.iter_mut().enumerate() {
            let ids: Vec<usize> = (a.model().neighbours.iter())
                .map(|n| n.id as usize - 1)
                .collect();
            for (m, j) in ids.into_iter().enumerate() {
                let (x, trusted) = published[j];
                a.receive_neighbour_judged(m, x, trusted);
            }
            if k == 0 {
                a.receive_leader(from_leader);
            }
            a.advance();
        }
        leader.advance();
    }
    (yes, no)
}

#[test]
fn verdicts_equal_trust_while_converging() {
    for scheme in schemes(1.0) {
        for guard in [false, true] {
            let v = Variant {
                guard,
                ..Variant::default()
            };
            let (yes, no) = check(scheme, 1e-3, 2_000, v);
            assert_eq!((yes, no), (5 * 4 * 2_000, 0), "{scheme:?}");
        }
    }
}

#[test]
fn verdicts_equal_trust_while_diverging() {
    for scheme in schemes(50.0) {
        for guard in [false, true] {
            let v = Variant {
                guard,
                ..Variant::default()
            };
            let (yes, no) = check(scheme, 0.2, 60, v);
            assert!(yes > 0 && no > 0, "{scheme:?}: {yes} trusted, {no} refused");
        }
    }
}

#[test]
fn verdicts_equal_trust_for_what_sensors_measure() {
    let [.., observerless] = schemes(1.0);
    // 1e-3 rad: every ‖η‖² ≤ 1, proven; 2 rad: many beyond, checked in full
    for (std, guard) in [(1e-3, false), (1e-3, true), (2.0, false), (2.0, true)] {
        let v = Variant {
            attitude_noise: Some(std),
            guard,
        };
        let (yes, no) = check(observerless, 1e-3, 500, v);
        assert_eq!((yes, no), (5 * 4 * 500, 0), "std {std}, guard {guard}");
    }
    let [.., observerless] = schemes(50.0);
    for guard in [false, true] {
        let v = Variant {
            attitude_noise: Some(1e-3),
            guard,
        };
        let (yes, no) = check(observerless, 0.2, 60, v);
        assert!(yes > 0 && no > 0, "{yes} trusted, {no} refused");
    }
}
