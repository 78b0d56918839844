//! Issue 9: PROTOCOL.md is enough to write an agent bit-identical to
//! attsync's. `tests/independent_agent/agent.py` was written from
//! PROTOCOL.md alone (pure Python, PyPI `iceoryx2==0.10.0`); with it in
//! place of built-in agents, each of the paper's three experiments gives
//! byte-identical `errors.csv` and `states.bin`, and it passes
//! `attsync conform`.
//!
//! Needs `python3 -m pip install -r examples/python/requirements.txt` (the
//! README's test command and `.ci/run` do it); without the binding the
//! tests fail saying so.

use attsync_tests::{
    Attsync, Sandbox, assert_same_bytes, conform_python, paper, require_iceoryx2_module, run_args,
    summary,
};
use std::path::{Path, PathBuf};

/// Simulated seconds per run: 5000 steps of the paper's dt = 1 ms, 20 000
/// exchanges (the Python agent is slow; the built-in run is cut alike).
const DURATION: &str = "simulation.duration=5";

fn agent_py() -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("independent_agent/agent.py");
    p.canonicalize().expect("tests/independent_agent/agent.py")
}

/// `--set agent[k].command=["python3", "<abs>/agent.py"]` for the agents
/// at 0-based file positions `positions`.
fn plugin_sets(positions: &[usize]) -> Vec<String> {
    let agent = format!("{:?}", agent_py().display().to_string());
    positions
        .iter()
        .map(|k| format!("agent[{k}].command=[\"python3\", {agent}]"))
        .collect()
}

/// Runs `scenario` (processes engine) with the agents at `positions`
/// replaced by the independent agent, and again with attsync's own, both
/// with `sets`; asserts identical trajectories, per-agent summaries and
/// link statistics.
fn assert_bit_identical(name: &str, scenario: &Path, positions: &[usize], sets: &[&str]) {
    require_iceoryx2_module();
    let tmp = Sandbox::new(name);
    let (ind, builtin) = (tmp.join("independent"), tmp.join("builtin"));
    let plugins = plugin_sets(positions);
    let mut with_plugins: Vec<&str> = sets.to_vec();
    with_plugins.extend(plugins.iter().map(String::as_str));
    Attsync::new(tmp.path())
        .args(run_args(scenario, "processes", &ind, &with_plugins))
        .output()
        .assert_ok()
        .assert_no_leftovers();
    Attsync::new(tmp.path())
        .args(run_args(scenario, "processes", &builtin, sets))
        .output()
        .assert_ok();
    assert_same_bytes(&ind.join("errors.csv"), &builtin.join("errors.csv"));
    assert_same_bytes(&ind.join("states.bin"), &builtin.join("states.bin"));
    let (s, b) = (summary(&ind), summary(&builtin));
    assert_eq!(s["complete"], true, "{s:#}");
    assert_eq!(s["steps"], b["steps"]);
    let (sa, ba) = (
        s["agents"].as_array().unwrap(),
        b["agents"].as_array().unwrap(),
    );
    for &k in positions {
        let plugin = sa[k]["plugin"].as_str().unwrap_or_default();
        assert!(plugin.contains("independent_agent/agent.py"), "{s:#}");
    }
    // The link counters and ages of information (LinkStats, § 5) too.
    assert_eq!(s["links"], b["links"], "summary.json links differ");
    for (x, y) in sa.iter().zip(ba) {
        for key in [
            "final_att_err",
            "final_angvel_err",
            "final_obs_att_err",
            "peak_torque",
        ] {
            assert_eq!(x[key], y[key], "agent {}: {key}", x["id"]);
        }
    }
}

/// Agents 1 (hears the leader) and 3 (three neighbours, one of them agent 1).
const AGENTS_1_AND_3: [usize; 2] = [0, 2];

#[test]
fn scheme_1_observer_time_varying_is_bit_identical() {
    assert_bit_identical(
        "independent-tv",
        &paper("timevarying"),
        &AGENTS_1_AND_3,
        &[DURATION],
    );
}

#[test]
fn scheme_2_observer_constant_is_bit_identical() {
    assert_bit_identical(
        "independent-co",
        &paper("constant-observer"),
        &AGENTS_1_AND_3,
        &[DURATION],
    );
}

#[test]
fn scheme_3_observerless_is_bit_identical() {
    assert_bit_identical(
        "independent-ol",
        &paper("constant-observerless"),
        &AGENTS_1_AND_3,
        &[DURATION],
    );
}

#[test]
fn sampled_coupling_is_bit_identical() {
    // Agents 3 and 6 (a leaf of 3): exchanges every 10 steps, held between.
    assert_bit_identical(
        "independent-sampled",
        &paper("timevarying"),
        &[2, 5],
        &[
            DURATION,
            "simulation.coupling=sampled",
            "simulation.period=0.01",
        ],
    );
}

#[test]
fn a_timeline_of_events_is_bit_identical() {
    // PROTOCOL.md § 10.10: agent 3 holds a cut edge's last value, then
    // leaves silent agent 5 out of its law; agent 1 loses the leader
    // (removed); every agent is retuned.
    let events = concat!(
        "event=[{t=1.0, cut=[3,5]}, {t=2.0, restore=[3,5]}, ",
        "{t=2.5, agent=5, action=\"silence\", hold=false}, {t=3.5, agent=5, action=\"resume\"}, ",
        "{t=0.5, cut=[0,1], hold=false}, {t=1.5, restore=[0,1]}, ",
        "{t=3.0, set={\"scheme.control.k_r\"=4.0, \"scheme.observer.k_sigma\"=9.0}}]"
    );
    assert_bit_identical(
        "independent-events",
        &paper("timevarying"),
        &[0, 2, 4],
        &[DURATION, events],
    );
}

#[test]
fn actuator_limits_are_bit_identical() {
    // PROTOCOL.md § 10.11: agent 1 saturated by norm and in rate, agent 3
    // per axis.
    assert_bit_identical(
        "independent-actuator",
        &paper("timevarying"),
        &[0, 2],
        &[
            DURATION,
            "actuator={max_torque=0.5, max_torque_rate=4.0}",
            "agent[2].actuator={max_torque=[0.2, 0.3, 0.25]}",
        ],
    );
}

#[test]
fn body_effects_are_bit_identical() {
    // PROTOCOL.md § 10.12–10.13: every kind of disturbance (one inertial),
    // noisy biased sensors; without an observer agents 1 and 3 publish what
    // their sensors measure.
    let disturbances = concat!(
        "disturbance=[",
        "{kind=\"constant\", torque=[0.02, -0.01, 0.03], frame=\"inertial\"},",
        "{kind=\"sine\", amplitude=[0.05, 0.0, 0.02], frequency=0.7, phase=0.3},",
        "{kind=\"noise\", std=[0.02, 0.01, 0.03], bandwidth=3.0},",
        "{kind=\"impulse\", t=1.5, impulse=[0.2, 0.0, -0.1]}]"
    );
    let sensor = "sensor={attitude_noise=2e-3, attitude_bias=[0.0, 1e-3, 0.0], rate_noise=1e-3, rate_bias=[5e-4, 0.0, 0.0]}";
    assert_bit_identical(
        "independent-effects",
        &paper("constant-observerless"),
        &AGENTS_1_AND_3,
        &[DURATION, disturbances, sensor],
    );
    // § 10.14 with sensors under an observer: the law assumes 1.3 J.
    assert_bit_identical(
        "independent-mismatch",
        &paper("timevarying"),
        &AGENTS_1_AND_3,
        &[DURATION, sensor, "controller={inertia_scale=1.3}"],
    );
}

#[test]
fn the_independent_agent_conforms() {
    let tmp = Sandbox::new("independent-conform");
    let r = conform_python(&tmp, &[], &agent_py());
    r.assert_ok();
    assert!(r.stdout.contains("10/10 rules pass"), "{}", r.describe());
}

#[test]
fn conform_checks_the_law_with_body_effects() {
    // § 10.12–10.13: conform's law rule plays the neighbourhood with the
    // scenario's effects; the independent agent follows them, the example
    // plug-in (which ignores them) is caught.
    let tmp = Sandbox::new("independent-conform-effects");
    let scenario = tmp.join("effects.toml");
    let base = std::fs::read_to_string(paper("constant-observerless")).unwrap();
    let extra = concat!(
        "\n[[disturbance]]\nkind = \"sine\"\namplitude = [0.05, 0.0, 0.02]\nfrequency = 0.7\n",
        "\n[[disturbance]]\nkind = \"noise\"\nstd = 0.02\nbandwidth = 2.0\n",
        "\n[sensor]\nattitude_noise = 0.001\nrate_noise = 0.0005\n"
    );
    std::fs::write(&scenario, base + extra).unwrap();
    let args = [
        "--scenario".into(),
        scenario.into_os_string(),
        "--agent".into(),
        "3".into(),
    ];
    let r = conform_python(&tmp, &args, &agent_py());
    r.assert_ok();
    assert!(r.stdout.contains("10/10 rules pass"), "{}", r.describe());
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/python/agent.py");
    let r = conform_python(&tmp, &args, &example);
    assert!(r.stdout.contains("FAIL  law"), "{}", r.describe());
}

#[test]
fn impaired_links_are_bit_identical() {
    // § 10.9: delay, jitter and Bernoulli loss on every link, a period on
    // one; agents 1 and 3 apply them to what they receive.
    assert_bit_identical(
        "independent-impaired",
        &paper("timevarying"),
        &AGENTS_1_AND_3,
        &[
            DURATION,
            "network.delay=0.002",
            "network.jitter=0.002",
            "network.loss=0.1",
            "network.seed=3",
        ],
    );
}
