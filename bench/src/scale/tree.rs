//! A network of any size built directly (no scenario file, no validation:
//! a binary tree is connected and every gain here is SPD with distinct
//! eigenvalues by construction).
//!
//! Agent k ≥ 2 hangs below agent k / 2 (ids from 1), agent 1 hears the
//! leader; gains and inertias follow the paper's pattern
//! (`diag(c, c+1, c+2)`), initial attitudes `Rot(0.1 + 0.01·(k mod 100), u)`
//! rad about a fixed axis. The gains are the paper's (Section `simulation`)
//! with smaller edge gains, so a tree of any depth stays non-stiff at
//! `dt = 1 ms`.

use attitude::body::Inertia;
use attitude::control::ControlGains;
use attitude::network::{AgentModel, AgentSpec, AgentState, Coupling, Neighbour, Network, Scheme};
use attitude::observer::ObserverGains;
use attitude::reference::LeaderState;
use attitude::so3::rot;
use nalgebra::{Matrix3, Vector3};

/// The paper's three schemes, by the names of `attsync gen tree --scheme`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SchemeArg {
    /// Scheme 1: observer 7a–7c + law `control`.
    ObserverTimeVarying,
    /// Scheme 2: observer 16a–16b + law `controlconstantestimate`.
    ObserverConstant,
    /// Scheme 3: law `districontrol`.
    Observerless,
}

impl SchemeArg {
    /// Every scheme, in the paper's order.
    pub const ALL: [SchemeArg; 3] = [
        SchemeArg::ObserverTimeVarying,
        SchemeArg::ObserverConstant,
        SchemeArg::Observerless,
    ];

    /// The scheme's name, as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SchemeArg::ObserverTimeVarying => "observer-time-varying",
            SchemeArg::ObserverConstant => "observer-constant",
            SchemeArg::Observerless => "observerless",
        }
    }

    fn scheme(self) -> Scheme {
        let observer = ObserverGains {
            k_r: 9.0,
            k_w: 14.0,
            k_sigma: 12.0,
        };
        let control = ControlGains {
            k_r: 8.0,
            k_w: 13.0,
        };
        match self {
            SchemeArg::ObserverTimeVarying => Scheme::ObserverTimeVarying { observer, control },
            SchemeArg::ObserverConstant => Scheme::ObserverConstant { observer, control },
            SchemeArg::Observerless => Scheme::Observerless { control },
        }
    }
}

fn diag(c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(c, c + 1.0, c + 2.0))
}

/// `P` of the paper's experiment.
fn paper_p() -> Matrix3<f64> {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, -h, 0.0, h, 0.0)
}

/// The neighbours of agent `id` in the binary tree of `n` agents, by id.
fn neighbours(id: u32, n: u32) -> Vec<Neighbour> {
    let parent = (id >= 2).then_some(id / 2);
    let children = [2 * id, 2 * id + 1].into_iter().filter(|&c| c <= n);
    (parent.into_iter().chain(children))
        .map(|j| Neighbour {
            id: j,
            a: diag(1.0 + f64::from(id.max(j) % 3)),
            link: None,
        })
        .collect()
}

/// A binary tree of `n` ≥ 1 agents under `scheme`, `steps` steps of 1 ms,
/// continuous coupling, a sample every 10 steps.
pub fn network(n: u32, scheme: SchemeArg, steps: u64) -> Network {
    let p = paper_p();
    let axis = Vector3::new(1.0, 1.0, 0.0).normalize();
    let agents = (1..=n)
        .map(|id| {
            let k = f64::from(id % 100);
            let model = AgentModel {
                id,
                inertia: Inertia::new(Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3))),
                a_bar: diag(1.0 + k / 100.0),
                neighbours: neighbours(id, n),
                leader_gain: (id == 1).then(|| diag(4.0)),
                leader_link: None,
                scheme: scheme.scheme(),
                p,
                law: Default::default(),
                timeline: Default::default(),
                effects: None,
            };
            let r = rot(0.1 + 0.01 * k, &axis);
            let initial = AgentState {
                r,
                w: Vector3::zeros(),
                r_hat: r,
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
        dt: 1e-3,
        steps,
        coupling: Coupling::Continuous,
        sample_every: 10,
        guard: Default::default(),
        repoint: Vec::new(),
    }
}
