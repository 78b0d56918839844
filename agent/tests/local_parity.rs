//! The node runtime over iceoryx2's process-local service
//! (`iceoryx2::service::local::Service`) against the in-process engine.
//!
//! Every node of the paper's time-varying experiment (2 s) runs the real
//! node loop ([`attsync_agent::runtime::run`] with the leader's and the
//! agents' steppers) on its own thread of this one process; a minimal
//! orchestrator on the test thread opens the control and telemetry services
//! through `msgs::open`, sends `Start` once every node is `Ready`, collects
//! the samples and sends `Stop`. Every sampled state must be bit-identical
//! to [`InProcess`]'s.

use attitude::engine::InProcess;
use attitude::network::{AgentState, Network};
use attitude::reference::LeaderState;
use attsync::launch::namespace::Namespace;
use attsync::processes::{ProcessOptions, node_configs};
use attsync_agent::{AgentNode, NodeError};
use attsync_leader::LeaderNode;
use iceoryx2::service::local::Service as Local;
use msgs::config::{NodeConfig, Role};
use msgs::{ControlCommand, ControlMsg, Limits, Telemetry, TelemetryMsg};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// The samples of a run: (step, node id) → the bits of the state.
type Samples = BTreeMap<(u64, u32), Vec<u64>>;

fn agent_bits(s: &AgentState) -> Vec<u64> {
    let m = [&s.r, &s.r_hat].into_iter().flat_map(|m| m.iter());
    let v = [&s.w, &s.w_hat, &s.s_hat]
        .into_iter()
        .flat_map(|v| v.iter());
    m.chain(v).map(|x| x.to_bits()).collect()
}

fn leader_bits(s: &LeaderState) -> Vec<u64> {
    let v = [&s.w0, &s.s0].into_iter().flat_map(|v| v.iter());
    s.r0.iter().chain(v).map(|x| x.to_bits()).collect()
}

/// The network of the paper's time-varying experiment, shortened to 2 s.
fn network() -> Network {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper/timevarying.toml");
    attsync::scenario::load(&file, &["simulation.duration=2".into()])
        .expect("the paper scenario loads")
        .resolved
        .network
}

/// One node: its iceoryx2 node on the local service, the real node loop.
fn node(cfg: &NodeConfig) -> Result<(), NodeError> {
    let name = format!("node_{}", cfg.id);
    let node = msgs::iox::create_node::<Local>(&cfg.run, Path::new(&cfg.iox_root), &name)
        .map_err(NodeError::Port)?;
    let shutdown = AtomicBool::new(false);
    match cfg.role {
        Role::Leader { .. } => {
            let mut l =
                LeaderNode::from_config(cfg).map_err(|e| NodeError::Protocol(e.to_string()))?;
            attsync_agent::runtime::run(&node, cfg, &mut l, &shutdown)
        }
        Role::Agent { .. } => {
            let mut a =
                AgentNode::from_config(cfg).map_err(|e| NodeError::Protocol(e.to_string()))?;
            attsync_agent::runtime::run(&node, cfg, &mut a, &shutdown)
        }
    }
}

/// The minimal orchestrator: Start when all are Ready, collect until all
/// are Done, then Stop.
fn orchestrate(net: &Network, configs: &[NodeConfig]) -> Samples {
    let (run, root) = (&configs[0].run, Path::new(&configs[0].iox_root));
    let limits = Limits::of(net);
    let node = msgs::iox::create_node::<Local>(run, root, "orchestrator").expect("node");
    let control = msgs::open::control(&node, run, &limits)
        .expect("control")
        .publisher_builder()
        .create()
        .expect("control publisher");
    let wake = msgs::open::orchestrator_wake(&node, run, &limits)
        .expect("wake")
        .listener_builder()
        .create()
        .expect("wake listener");
    let telemetry: Vec<_> = configs
        .iter()
        .map(|c| {
            msgs::open::telemetry(&node, run, c.id, &limits)
                .expect("telemetry")
                .subscriber_builder()
                .buffer_size(limits.telemetry_buffer)
                .create()
                .expect("telemetry subscriber")
        })
        .collect();
    let (mut ready, mut done, mut samples) = (0, 0, Samples::new());
    let deadline = Instant::now() + Duration::from_secs(120);
    while done < configs.len() {
        assert!(Instant::now() < deadline, "the run did not end in 120 s");
        let _ = wake.timed_wait(|_| {}, Duration::from_millis(10));
        for (sub, c) in telemetry.iter().zip(configs) {
            while let Some(m) = sub.receive().expect("telemetry receive") {
                let m: TelemetryMsg = *m;
                match m.decode().expect("telemetry decodes") {
                    Telemetry::Ready => {
                        ready += 1;
                        if ready == configs.len() {
                            control
                                .send_copy(ControlMsg::new(ControlCommand::Start))
                                .expect("send Start");
                        }
                    }
                    Telemetry::Sample { step, state, .. } => {
                        samples.insert((step, c.id), agent_bits(&state));
                    }
                    Telemetry::LeaderSample { step, state } => {
                        samples.insert((step, c.id), leader_bits(&state));
                    }
                    Telemetry::Done(_) => done += 1,
                    Telemetry::Failed(f) => panic!("node {} failed: {f:?}", c.id),
                    _ => {}
                }
            }
        }
    }
    control
        .send_copy(ControlMsg::new(ControlCommand::Stop))
        .expect("send Stop");
    samples
}

/// The samples of the in-process engine.
fn in_process(net: &Network) -> Samples {
    let mut samples = Samples::new();
    InProcess::new(net).run(|snap| {
        samples.insert((snap.step, 0), leader_bits(snap.leader));
        for (a, s) in net.agents.iter().zip(snap.agents) {
            samples.insert((snap.step, a.model.id), agent_bits(s));
        }
        true
    });
    samples
}

#[test]
fn every_node_on_local_service_matches_the_in_process_engine_bit_for_bit() {
    let net = network();
    let ns = Namespace::create().expect("a run namespace");
    let configs = node_configs(&net, ns.run(), ns.dir(), &ProcessOptions::default());
    let nodes: Vec<_> = configs
        .iter()
        .map(|c| {
            let c = c.clone();
            std::thread::spawn(move || node(&c))
        })
        .collect();
    let got = orchestrate(&net, &configs);
    for (c, t) in configs.iter().zip(nodes) {
        let r = t.join().expect("node thread");
        assert!(r.is_ok(), "node {}: {:?}", c.id, r);
    }
    let want = in_process(&net);
    assert_eq!(want.len(), 201 * 8, "2 s sampled every 0.01 s, 8 nodes");
    assert_eq!(
        got.keys().collect::<Vec<_>>(),
        want.keys().collect::<Vec<_>>(),
        "the samples taken"
    );
    for (key, w) in &want {
        assert_eq!(&got[key], w, "(step, node) {key:?}: not bit-identical");
    }
}
