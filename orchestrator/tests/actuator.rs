//! `[actuator]` and `agent.actuator` (issue 35, item 3, actuator limits):
//! the torque a body receives is saturated, by its norm or per axis.
//!
//! - the applied torque never exceeds the limit (`peak_torque` in
//!   `summary.json` is the applied one): per axis exactly, in norm up to
//!   a rounding;
//! - a limit above every torque of the run gives the bits of a run
//!   without one;
//! - both engines are byte-identical with limits;
//! - an agent's own limit replaces `[actuator]` for it alone;
//! - a rate limit moves the applied torque at most `ρ·dt` per step (from
//!   zero before the first step), byte-identical in both engines;
//! - bad bounds are refused (exit 2) naming the field.

mod common;

use common::{PAPER, attsync, json, read, run_args};
use std::fs;
use std::path::{Path, PathBuf};

/// `base` with `extra` appended, written into `dir/name.toml`.
fn scenario(dir: &Path, name: &str, extra: &str) -> PathBuf {
    let file = dir.join(format!("{name}.toml"));
    fs::write(&file, read(Path::new(PAPER)) + "\n" + extra).expect("write");
    file
}

fn run(dir: &Path, file: &Path, engine: &str, out: &str) -> PathBuf {
    let out = dir.join(out);
    let sets = ["simulation.duration=3"];
    attsync(dir, &run_args(file, engine, &out, &sets)).assert_code(0);
    out
}

fn same_bits(a: &Path, b: &Path) -> bool {
    ["errors.csv", "states.bin"]
        .iter()
        .all(|f| fs::read(a.join(f)).unwrap() == fs::read(b.join(f)).unwrap())
}

/// Each agent's `peak_torque`, by id.
fn peaks(out: &Path) -> Vec<(u64, f64)> {
    let s = json(&out.join("summary.json"));
    let agents = s["agents"].as_array().expect("agents").clone();
    (agents.iter())
        .map(|a| {
            (
                a["id"].as_u64().unwrap(),
                a["peak_torque"].as_f64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn the_applied_torque_never_exceeds_the_limit_in_either_engine() {
    let tmp = tempfile::tempdir().unwrap();
    let free = run(tmp.path(), Path::new(PAPER), "in-process", "free");
    let unlimited = peaks(&free);
    for (name, table, bound) in [
        ("norm", "[actuator]\nmax_torque = 0.5\n", 0.5),
        (
            "axes",
            "[actuator]\nmax_torque = [0.2, 0.3, 0.25]\n",
            (0.2f64 * 0.2 + 0.09 + 0.0625).sqrt(),
        ),
    ] {
        let file = scenario(tmp.path(), name, table);
        let a = run(tmp.path(), &file, "in-process", &format!("{name}-a"));
        let b = run(tmp.path(), &file, "processes", &format!("{name}-b"));
        assert!(same_bits(&a, &b), "{name}: the engines differ");
        assert!(!same_bits(&a, &free), "{name}: the limit changed nothing");
        for ((id, peak), (_, before)) in peaks(&a).into_iter().zip(&unlimited) {
            assert!(
                peak <= bound * (1.0 + 4.0 * f64::EPSILON),
                "{name}: agent {id}: {peak} > {bound}"
            );
            assert!(*before > bound, "agent {id} never needed more than {bound}");
        }
    }
}

#[test]
fn a_limit_above_every_torque_changes_no_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let free = run(tmp.path(), Path::new(PAPER), "in-process", "free");
    let most = peaks(&free).iter().map(|p| p.1).fold(0.0, f64::max);
    let table = format!("[actuator]\nmax_torque = {}\n", most * 1.01);
    let high = run(
        tmp.path(),
        &scenario(tmp.path(), "high", &table),
        "in-process",
        "high",
    );
    assert!(same_bits(&free, &high));
}

#[test]
fn an_agents_own_limit_replaces_the_common_one_for_it_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let common = "[actuator]\nmax_torque = 0.5\n";
    let both = scenario(tmp.path(), "both", common);
    let text = read(&both).replacen(
        "[[agent]]\nid = 3\n",
        "[[agent]]\nid = 3\nactuator = { max_torque = 0.1 }\n",
        1,
    );
    assert!(text.contains("max_torque = 0.1"));
    fs::write(&both, text).unwrap();
    let out = run(tmp.path(), &both, "in-process", "both");
    for (id, peak) in peaks(&out) {
        let bound = if id == 3 { 0.1 } else { 0.5 };
        assert!(
            peak <= bound * (1.0 + 4.0 * f64::EPSILON),
            "agent {id}: {peak}"
        );
        assert!(peak > bound * 0.99, "agent {id} not saturated: {peak}");
    }
}

#[test]
fn bad_bounds_are_refused_naming_the_field() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, table, says) in [
        (
            "zero",
            "[actuator]\nmax_torque = 0.0\n",
            "actuator.max_torque: a torque bound must be finite and > 0",
        ),
        (
            "negative-axis",
            "[actuator]\nmax_torque = [0.1, -0.2, 0.3]\n",
            "actuator.max_torque: a torque bound must be finite and > 0 N·m, got -0.2",
        ),
        (
            "two-numbers",
            "[actuator]\nmax_torque = [0.1, 0.2]\n",
            "actuator.max_torque",
        ),
        (
            "unknown-key",
            "[actuator]\nmax_torque = 1.0\nrate = 2.0\n",
            "rate",
        ),
        (
            "rate",
            "[actuator]\nmax_torque_rate = -3.0\n",
            "actuator.max_torque_rate: a torque rate bound must be finite and > 0 N·m/s, got -3",
        ),
        (
            "empty",
            "[actuator]\n",
            "actuator: needs max_torque, max_torque_rate or both",
        ),
    ] {
        let file = scenario(tmp.path(), name, table);
        let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
        o.assert_code(2);
        assert!(o.stderr.contains(says), "{name}: {}", o.stderr);
    }
}

#[test]
fn a_rate_limit_moves_the_applied_torque_at_most_rho_dt_per_step() {
    let tmp = tempfile::tempdir().unwrap();
    let table = "[actuator]\nmax_torque = 2.0\nmax_torque_rate = 5.0\n";
    let file = scenario(tmp.path(), "rate", table);
    let a = run(tmp.path(), &file, "in-process", "rate-a");
    let b = run(tmp.path(), &file, "processes", "rate-b");
    assert!(same_bits(&a, &b), "the engines differ");
    // every step's stage-0 torque, from the model itself
    let text = read(&file);
    let set = ["simulation.duration=3".to_string()];
    let loaded = attsync::scenario::load_str(&file, &text, &set).unwrap();
    let net = loaded.resolved.network;
    let dt = net.dt;
    let mut engine = attitude::engine::InProcess::new(&net);
    let mut before: Vec<nalgebra::Vector3<f64>> = vec![nalgebra::Vector3::zeros(); 7];
    let (mut fastest, mut limited) = (0.0f64, 0usize);
    for _ in 0..net.steps {
        engine.step();
        for (k, agent) in engine.agents().iter().enumerate() {
            let tau = agent.torque();
            let rate = (tau - before[k]).norm() / dt;
            fastest = fastest.max(rate);
            limited += usize::from(rate > 5.0 * 0.999);
            assert!(tau.norm() <= 2.0 * (1.0 + 4.0 * f64::EPSILON));
            before[k] = tau;
        }
    }
    assert!(fastest <= 5.0 * (1.0 + 1e-9), "{fastest} N·m/s > 5");
    assert!(limited > 100, "the limit hardly acted: {limited} steps");
}
