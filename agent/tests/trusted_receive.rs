//! [`AgentNode`] takes the values the runtime hands it as already validated
//! (the runtime checks every received state once, `StateMsg::validated`):
//! stepped through the [`Stepper`] interface it must evolve bit for bit as
//! the model's own agent fed through its checking entry points
//! (`Agent::receive_neighbour`, `Agent::receive_leader`).

use attitude::agent::Agent;
use attitude::network::Exchanged;
use attsync::processes::{ProcessOptions, node_configs};
use attsync_agent::{AgentNode, Stepper};
use msgs::Telemetry;
use msgs::config::{NodeConfig, Role};
use nalgebra::{Rotation3, Vector3};
use std::path::Path;

/// The node configurations of the paper's time-varying experiment.
fn configs() -> Vec<NodeConfig> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper/timevarying.toml");
    let net = attsync::scenario::load(&file, &["simulation.duration=1".into()])
        .expect("the paper scenario loads")
        .resolved
        .network;
    node_configs(&net, "x", Path::new("/tmp"), &ProcessOptions::default())
}

/// A valid (trusted) state that changes with `t`.
fn input(t: f64) -> Exchanged {
    let axis = Vector3::new(1.0, 2.0, 3.0).normalize();
    Exchanged {
        r: *Rotation3::from_axis_angle(&nalgebra::Unit::new_unchecked(axis), 0.3 + t).matrix(),
        w: Vector3::new(0.1, -0.2, 0.3 * t),
        s: Vector3::new(t, 0.0, -t),
    }
}

/// The bits of the state an agent node samples.
fn bits(t: &Telemetry) -> Vec<u64> {
    let Telemetry::Sample { state, .. } = t else {
        panic!("an agent samples Sample, not {t:?}")
    };
    let m = [&state.r, &state.r_hat].into_iter().flat_map(|m| m.iter());
    let v = [&state.w, &state.w_hat, &state.s_hat]
        .into_iter()
        .flat_map(|v| v.iter());
    m.chain(v).map(|x| x.to_bits()).collect()
}

#[test]
fn a_node_fed_validated_inputs_steps_bit_identically_to_the_checking_agent() {
    let configs = configs();
    // Agent 1 reads a neighbour (3) and the leader: both entry points.
    let cfg = configs.iter().find(|c| c.id == 1).expect("agent 1");
    assert_eq!(cfg.inputs, vec![3, 0]);
    let Role::Agent { model, initial } = &cfg.role else {
        panic!("agent 1 is an agent")
    };
    let mut node = AgentNode::from_config(cfg).expect("an agent");
    let mut checked = Agent::new((**model).clone(), *initial, cfg.dt);
    let mut deaf = AgentNode::from_config(cfg).expect("an agent");
    for stage in 0..12 {
        let t = f64::from(stage) * 1e-3;
        let (nbr, leader) = (input(t), input(2.0 * t + 0.5));
        assert!(nbr.trust().is_ok() && leader.trust().is_ok());
        node.receive(0, nbr);
        node.receive(1, leader);
        checked.receive_neighbour(0, nbr);
        checked.receive_leader(leader);
        node.advance();
        checked.advance();
        deaf.advance();
    }
    let step = 3;
    let checked_sample = Telemetry::Sample {
        step,
        state: *checked.state(),
        peak_torque: checked.peak_torque(),
    };
    assert_eq!(bits(&node.sample(step)), bits(&checked_sample));
    assert_eq!(
        node.peak_torque().to_bits(),
        checked.peak_torque().to_bits()
    );
    // The inputs were used: a node that heard nothing is elsewhere.
    assert_ne!(bits(&node.sample(step)), bits(&deaf.sample(step)));
}
