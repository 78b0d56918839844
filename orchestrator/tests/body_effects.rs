//! Bodies that aren't ideal (issue 35, item 3): `[[disturbance]]`,
//! `[sensor]` and `[controller]`, checked against the physics and across
//! the engines.
//!
//! - every effect is byte-identical in both engines, and changes the run;
//! - zero amplitudes (and a law inertia equal to the body's) give the bits
//!   of a run without them;
//! - a constant disturbance on the observerless law leaves the steady
//!   attitude offset its linearisation predicts (`k_Ř 𝐊 θ = d`, with
//!   `ψ(A exp(θ^×)) ≈ ½(tr A − A) θ`), solved here independently;
//! - a common attitude bias makes the network settle where the *measured*
//!   attitudes agree with the leader: every body turned by `−b`;
//! - an impulse changes the body's angular momentum by the impulse within
//!   its step;
//! - bad keys are refused (exit 2) naming the field.

mod common;

use attitude::engine::InProcess;
use attitude::so3::log;
use attsync::scenario::load_str;
use common::{OBSERVERLESS, PAPER, attsync, read, run_args};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use std::fs;
use std::path::{Path, PathBuf};

/// `base` with `extra` appended, written into `dir/name.toml`.
fn scenario(dir: &Path, base: &str, name: &str, extra: &str) -> PathBuf {
    let file = dir.join(format!("{name}.toml"));
    fs::write(&file, read(Path::new(base)) + "\n" + extra).expect("write");
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

const EVERY_DISTURBANCE: &str = r#"
[[disturbance]]
kind = "constant"
torque = [0.02, -0.01, 0.03]
frame = "inertial"

[[disturbance]]
kind = "sine"
amplitude = [0.05, 0.0, 0.02]
frequency = 0.7
phase = 0.3

[[disturbance]]
kind = "noise"
std = [0.02, 0.01, 0.03]
bandwidth = 3.0
agents = [3, 4, 7]

[[disturbance]]
kind = "impulse"
t = 1.5
impulse = [0.2, 0.0, -0.1]
agents = [5]
"#;

const SENSOR: &str = r#"
[sensor]
attitude_noise = 2e-3
attitude_bias = [0.0, 1e-3, 0.0]
rate_noise = 1e-3
rate_bias = [5e-4, 0.0, 0.0]
"#;

#[test]
fn every_effect_is_byte_identical_in_both_engines_and_changes_the_run() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (
            "observerless",
            OBSERVERLESS,
            format!("{EVERY_DISTURBANCE}{SENSOR}"),
        ),
        (
            "scheme1",
            PAPER,
            format!("{EVERY_DISTURBANCE}{SENSOR}\n[controller]\ninertia_scale = 1.3\n"),
        ),
        (
            "mismatch",
            PAPER,
            "[controller]\ninertia = [1.2, 1.0, 0.9]\n".to_string(),
        ),
    ];
    for (name, base, extra) in cases {
        let free = run(
            tmp.path(),
            Path::new(base),
            "in-process",
            &format!("{name}-free"),
        );
        let file = scenario(tmp.path(), base, name, &extra);
        let a = run(tmp.path(), &file, "in-process", &format!("{name}-a"));
        let b = run(tmp.path(), &file, "processes", &format!("{name}-b"));
        assert!(same_bits(&a, &b), "{name}: the engines differ");
        assert!(!same_bits(&a, &free), "{name}: the effects changed nothing");
    }
}

#[test]
fn zero_amplitudes_change_no_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let zero = r#"
[[disturbance]]
kind = "constant"
torque = [0.0, 0.0, 0.0]

[[disturbance]]
kind = "sine"
amplitude = [0.0, 0.0, 0.0]
frequency = 1.0

[[disturbance]]
kind = "noise"
std = 0.0
bandwidth = 1.0
frame = "inertial"

[[disturbance]]
kind = "impulse"
t = 1.0
impulse = [0.0, 0.0, 0.0]

[sensor]
attitude_noise = 0.0
rate_noise = 0.0

[controller]
inertia_scale = 1.0
"#;
    for (name, base) in [("observerless", OBSERVERLESS), ("scheme1", PAPER)] {
        let free = run(
            tmp.path(),
            Path::new(base),
            "in-process",
            &format!("{name}-free"),
        );
        let file = scenario(tmp.path(), base, name, zero);
        let with = run(tmp.path(), &file, "in-process", &format!("{name}-zero"));
        assert!(same_bits(&free, &with), "{name}: zero effects changed bits");
    }
}

/// The final body attitudes' offsets `θᵢ = log(R₀ᵀRᵢ)` (body frame) and
/// the largest `‖ωᵢ‖` of a run of the observerless paper experiment with
/// `extra` appended, for `seconds`.
fn settled(extra: &str, seconds: f64) -> (Vec<Vector3<f64>>, f64, attitude::network::Network) {
    let text = read(Path::new(OBSERVERLESS)) + "\n" + extra;
    let set = vec![format!("simulation.duration={seconds}")];
    let loaded = load_str(Path::new(OBSERVERLESS), &text, &set).unwrap_or_else(|e| panic!("{e}"));
    let net = loaded.resolved.network;
    let mut engine = InProcess::new(&net);
    assert!(engine.run(|_| true).is_none(), "diverged");
    let r0 = net.leader.r0;
    let agents = engine.agents();
    let theta = agents
        .iter()
        .map(|a| log(&(r0.transpose() * a.state().r)))
        .collect();
    let w = agents
        .iter()
        .map(|a| a.state().w.norm())
        .fold(0.0, f64::max);
    (theta, w, net)
}

/// `½(tr A − A)`: `ψ(A exp(θ^×)) = ½(tr A − A) θ + O(θ²)` for symmetric A.
fn stiffness(a: &Matrix3<f64>) -> Matrix3<f64> {
    (Matrix3::identity() * a.trace() - a) * 0.5
}

/// The linearised equilibrium of the observerless law under a constant
/// body-frame torque `d` on every agent: `k_Ř (K_{i0} θᵢ + Σⱼ K_{ij}(θᵢ − θⱼ)) = d`.
fn predicted(net: &attitude::network::Network, d: &Vector3<f64>) -> Vec<Vector3<f64>> {
    let n = net.agents.len();
    let index = |id: u32| net.agents.iter().position(|a| a.model.id == id).unwrap();
    let mut m = DMatrix::<f64>::zeros(3 * n, 3 * n);
    let mut rhs = DVector::<f64>::zeros(3 * n);
    for (i, a) in net.agents.iter().enumerate() {
        let k_r = match &a.model.scheme {
            attitude::network::Scheme::Observerless { control } => control.k_r,
            _ => panic!("observerless only"),
        };
        let mut block = |r: usize, c: usize, k: Matrix3<f64>| {
            let mut v = m.view_mut((3 * r, 3 * c), (3, 3));
            v += k * k_r;
        };
        if let Some(a0) = &a.model.leader_gain {
            block(i, i, stiffness(a0));
        }
        for nb in &a.model.neighbours {
            let k = stiffness(&nb.a);
            block(i, i, k);
            block(i, index(nb.id), -k);
        }
        rhs.rows_mut(3 * i, 3).copy_from(d);
    }
    let x = m
        .lu()
        .solve(&rhs)
        .expect("the network is connected to the leader");
    (0..n)
        .map(|i| Vector3::from(x.fixed_rows::<3>(3 * i)))
        .collect()
}

#[test]
fn a_constant_disturbance_leaves_the_offset_the_linearisation_predicts() {
    let d = Vector3::new(2e-3, -1e-3, 1.5e-3);
    let extra = format!(
        "[[disturbance]]\nkind = \"constant\"\ntorque = [{}, {}, {}]\n",
        d.x, d.y, d.z
    );
    let (theta, w, net) = settled(&extra, 80.0);
    assert!(w < 1e-9, "still turning: {w}");
    let want = predicted(&net, &d);
    for ((a, got), want) in net.agents.iter().zip(&theta).zip(&want) {
        let id = a.model.id;
        assert!(want.norm() > 1e-5, "agent {id}: a trivial offset {want}");
        let rel = (got - want).norm() / want.norm();
        assert!(
            rel < 1e-3,
            "agent {id}: offset {got} vs linearised {want} ({rel:e})"
        );
    }
}

#[test]
fn a_common_attitude_bias_turns_every_body_by_minus_the_bias() {
    let b = Vector3::new(0.01, -0.02, 0.005);
    let extra = format!("[sensor]\nattitude_bias = [{}, {}, {}]\n", b.x, b.y, b.z);
    let (theta, w, net) = settled(&extra, 80.0);
    assert!(w < 1e-9, "still turning: {w}");
    for (a, got) in net.agents.iter().zip(&theta) {
        let err = (got + b).norm();
        assert!(
            err < 1e-9,
            "agent {}: offset {got}, want {}",
            a.model.id,
            -b
        );
    }
}

#[test]
fn an_impulse_changes_the_angular_momentum_by_itself_within_its_step() {
    let p = Vector3::new(0.5, -0.2, 0.1);
    let extra = format!(
        "[[disturbance]]\nkind = \"impulse\"\nt = 2.0\nimpulse = [{}, {}, {}]\nagents = [7]\n",
        p.x, p.y, p.z
    );
    let text = read(Path::new(OBSERVERLESS)) + "\n" + &extra;
    let set = ["simulation.duration=2.002", "output.sample_period=0.001"].map(String::from);
    let net = load_str(Path::new(OBSERVERLESS), &text, &set)
        .unwrap_or_else(|e| panic!("{e}"))
        .resolved
        .network;
    let k = net.agents.iter().position(|a| a.model.id == 7).unwrap();
    let j = net.agents[k].model.inertia.j;
    let mut h = Vec::new();
    InProcess::new(&net).run(|s| {
        if (1999..=2001).contains(&s.step) {
            h.push(j * s.agents[k].w);
        }
        true
    });
    let (before, during, after) = (h[1] - h[0], h[2] - h[1], p);
    // the body's own torque moves its momentum by ~‖τ‖·dt ≈ 1e-3 per step
    assert!(before.norm() < 5e-3, "a step without the impulse: {before}");
    assert!(
        (during - after).norm() < 5e-3,
        "Δ(Jω) = {during}, impulse {after}"
    );
}

#[test]
fn bad_keys_are_refused_naming_the_field() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (
            "no-torque",
            "[[disturbance]]\nkind = \"constant\"\n",
            "disturbance[0].torque: is required by kind = \"constant\"",
        ),
        (
            "foreign",
            "[[disturbance]]\nkind = \"constant\"\ntorque = [0, 0, 0]\nfrequency = 2.0\n",
            "disturbance[0].frequency: does not apply to kind = \"constant\"",
        ),
        (
            "freq",
            "[[disturbance]]\nkind = \"sine\"\namplitude = [1, 0, 0]\nfrequency = 0.0\n",
            "disturbance[0].frequency: must be > 0",
        ),
        (
            "std",
            "[[disturbance]]\nkind = \"noise\"\nstd = -1.0\nbandwidth = 1.0\n",
            "disturbance[0].std: must be finite and ≥ 0",
        ),
        (
            "bandwidth",
            "[[disturbance]]\nkind = \"noise\"\nstd = 1.0\n",
            "disturbance[0].bandwidth: is required",
        ),
        (
            "off-grid",
            "[[disturbance]]\nkind = \"impulse\"\nt = 1.0005\nimpulse = [1, 0, 0]\n",
            "disturbance[0].t: must be a whole multiple of simulation.dt",
        ),
        (
            "late",
            "[[disturbance]]\nkind = \"impulse\"\nt = 50.0\nimpulse = [1, 0, 0]\n",
            "disturbance[0].t: must be in [0, 40) s",
        ),
        (
            "who",
            "[[disturbance]]\nkind = \"constant\"\ntorque = [1, 0, 0]\nagents = [9]\n",
            "disturbance[0].agents: agent 9 does not exist",
        ),
        (
            "twice",
            "[[disturbance]]\nkind = \"constant\"\ntorque = [1, 0, 0]\nagents = [2, 2]\n",
            "disturbance[0].agents: agent 2 is listed twice",
        ),
        (
            "kind",
            "[[disturbance]]\nkind = \"gust\"\n",
            "unknown variant `gust`",
        ),
        (
            "frame",
            "[[disturbance]]\nkind = \"constant\"\ntorque = [1, 0, 0]\nframe = \"orbit\"\n",
            "unknown variant `orbit`",
        ),
        (
            "sensor",
            "[sensor]\nrate_noise = -0.1\n",
            "sensor.rate_noise: must be finite and ≥ 0",
        ),
        ("sensor-key", "[sensor]\ngyro = 0.1\n", "gyro"),
        (
            "both",
            "[controller]\ninertia_scale = 1.1\ninertia = [1, 1, 1]\n",
            "controller: give inertia_scale or inertia, not both",
        ),
        (
            "neither",
            "[controller]\n",
            "controller: needs inertia_scale or inertia",
        ),
        (
            "scale",
            "[controller]\ninertia_scale = -1.0\n",
            "controller.inertia_scale: must be > 0",
        ),
        (
            "spd",
            "[controller]\ninertia = [1, -1, 1]\n",
            "controller.inertia: the law's inertia Ĵ must be symmetric positive definite",
        ),
    ];
    for (name, table, says) in cases {
        let file = scenario(tmp.path(), PAPER, name, table);
        let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
        o.assert_code(2);
        assert!(o.stderr.contains(says), "{name}: {}", o.stderr);
    }
    // the observerless law has no inertia: the key is ignored, said so
    let file = scenario(
        tmp.path(),
        OBSERVERLESS,
        "ignored",
        "[controller]\ninertia_scale = 2.0\n",
    );
    let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
    o.assert_code(0);
    let said = format!("{}{}", o.stdout, o.stderr);
    assert!(
        said.contains("controller: ignored: the observerless law"),
        "{said}"
    );
}

#[test]
fn the_disturbance_saturation_experiment_ends_at_the_linearised_offset() {
    // docs/experiments.md: the offset of every agent to the linearisation's
    // 0.1 %, and no torque above the 2 N·m limit.
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/experiments/disturbance-saturation.toml"
    );
    let loaded = attsync::scenario::load(Path::new(file), &[]).unwrap_or_else(|e| panic!("{e}"));
    let net = loaded.resolved.network;
    let d = match loaded.scenario.disturbances[0].torque {
        Some(t) => Vector3::from(t),
        None => panic!("the experiment's disturbance is constant"),
    };
    let mut engine = InProcess::new(&net);
    assert!(engine.run(|_| true).is_none(), "diverged");
    let want = predicted(&net, &d);
    for (a, want) in engine.agents().iter().zip(&want) {
        let got = log(&(net.leader.r0.transpose() * a.state().r));
        let rel = (got - want).norm() / want.norm();
        assert!(
            rel < 3e-3,
            "agent {}: {got} vs {want} ({rel:e})",
            a.model().id
        );
        let peak = a.peak_torque();
        assert!(
            peak <= 2.0 * (1.0 + 4.0 * f64::EPSILON) && peak > 1.99,
            "peak {peak}"
        );
    }
}
