//! Larger networks as processes: a 65-agent star (one hub, 64 leaves: the
//! hub's state service has 64 subscribers and its wake event 64 notifiers)
//! and a 100-agent random tree (101 processes). Each is run for 0.2 s with
//! the processes engine and the in-process engine; asserts: both exit 0,
//! `errors.csv` has every agent at every sample and is byte-identical between
//! the engines (so is the rest of the results but the wall-clock time), and
//! no iceoryx2 files are left.

use attsync_tests::{
    Attsync, Sandbox, assert_same_results, csv_agents, csv_rows, read, reference_run, run_args,
    summary,
};
use std::fmt::Write as _;
use std::path::Path;

/// A star: the leader talks to hub agent 1 only, agents 2..=leaves+1 each
/// have one edge to the hub. Observerless scheme, constant reference (the
/// format of `scenarios/paper/constant-observerless.toml`); initial
/// attitudes and angular velocities vary with the agent id.
fn star_scenario(leaves: u32) -> String {
    let mut s = format!(
        r#"name = "star-{leaves}"
description = "Star: hub agent 1 hears the leader, {leaves} leaves each linked to the hub"

[simulation]
dt = 0.001
duration = 0.2
coupling = "continuous"

[output]
sample_period = 0.01

[scheme]
kind = "observerless"
control = {{ k_r = 1.9, k_omega = 1.9 }}

[leader]
reference = "constant"
attitude = {{ axis = [1.0, 4.0, 2.0], angle_pi = 0.8 }}

[[leader_link]]
agent = 1
gain = [6.0, 7.0, 8.0]
"#
    );
    for j in 2..=leaves + 1 {
        let _ = write!(s, "\n[[edge]]\nagents = [1, {j}]\ngain = [9.0, 8.0, 7.0]\n");
    }
    for i in 1..=leaves + 1 {
        let axis = [
            1.0,
            f64::from((i * 3) % 7) - 3.0,
            f64::from((i * 5) % 11) - 5.0,
        ];
        let angle_pi = f64::from((i * 37) % 19) / 10.0 - 0.9;
        let omega = [
            (f64::from(i % 5) - 2.0) * 0.5,
            f64::from((i * 2) % 7) * 0.25,
            1.0 - f64::from(i % 3),
        ];
        let _ = write!(
            s,
            "\n[[agent]]\nid = {i}\ninertia = [0.1, 0.3, 0.2]\n\
             attitude = {{ axis = {axis:?}, angle_pi = {angle_pi:?} }}\nomega = {omega:?}\n"
        );
    }
    s
}

/// Runs `scenario` with both engines; asserts identical results with
/// `agents` agents and 21 samples (0.2 s every 0.01 s).
fn both_engines(tmp: &Sandbox, scenario: &Path, agents: u32) {
    let (p, i) = (tmp.join("processes"), tmp.join("in-process"));
    Attsync::new(tmp.path())
        .args(run_args(scenario, "processes", &p, &[]))
        .output()
        .assert_ok()
        .assert_no_leftovers();
    reference_run(tmp.path(), scenario, &i, &[]);
    let csv = read(&p.join("errors.csv"));
    assert_eq!(csv_agents(&csv), (1..=agents).collect());
    assert_eq!(csv_rows(&csv), 21 * agents as usize);
    assert_eq!(summary(&p)["complete"], true);
    assert_same_results(&p, &i);
}

#[test]
fn star_of_64_leaves() {
    let tmp = Sandbox::new("star64");
    let scenario = tmp.join("star-64.toml");
    std::fs::write(&scenario, star_scenario(64)).expect("write the scenario");
    both_engines(&tmp, &scenario, 65);
}

#[test]
fn tree_of_100_agents() {
    let tmp = Sandbox::new("tree100");
    let scenario = tmp.join("tree-100.toml");
    Attsync::new(tmp.path())
        .args(["gen", "tree", "--agents", "100", "--leader-links", "3"])
        .args(["--seed", "1", "--duration", "0.2", "--out"])
        .args([&scenario])
        .output()
        .assert_ok();
    both_engines(&tmp, &scenario, 100);
}
