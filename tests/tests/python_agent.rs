//! The Python example agent (`examples/python/agent.py`, PyPI
//! `iceoryx2==0.10.0`): it passes `attsync conform` (observerless and
//! observer schemes); the observerless paper experiment converges with agent
//! 3 replaced by it, to the same errors as the built-in agent; with either
//! observer scheme (the paper's experiment, shortened) `errors.csv` and
//! `states.bin` are byte-identical to the built-in run; and it runs in
//! real-time mode, reporting the age of information of its links.
//!
//! Needs `python3 -m pip install -r examples/python/requirements.txt` (the
//! README's test command and `.ci/run` do it).

use attsync_tests::{
    Attsync, Sandbox, assert_same_bytes, assert_same_file, conform_python, paper, reference_run,
    require_iceoryx2_module, run_args, scenario, summary,
};
use std::path::PathBuf;

fn agent_py() -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/python/agent.py");
    p.canonicalize().expect("examples/python/agent.py")
}

#[test]
fn the_python_agent_conforms() {
    let tmp = Sandbox::new("python-conform");
    let r = conform_python(&tmp, &[], &agent_py());
    r.assert_ok();
    assert!(r.stdout.contains("10/10 rules pass"), "{}", r.describe());
}

#[test]
fn the_paper_experiment_converges_with_a_python_agent() {
    require_iceoryx2_module();
    let tmp = Sandbox::new("python-paper");
    let (py, builtin) = (tmp.join("python"), tmp.join("builtin"));
    Attsync::new(tmp.path())
        .args(run_args(
            &scenario("plugin/python-observerless.toml"),
            "processes",
            &py,
            &[],
        ))
        .output()
        .assert_ok()
        .assert_no_leftovers();
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("constant-observerless"),
            "in-process",
            &builtin,
            &[],
        ))
        .output()
        .assert_ok();
    let (s, b) = (summary(&py), summary(&builtin));
    assert_eq!(s["complete"], true, "{s:#}");
    assert_eq!(s["t_end"], 40.0);
    assert!(
        s["agents"][2]["plugin"]
            .as_str()
            .unwrap()
            .contains("agent.py"),
        "{s:#}"
    );
    let max = s["max_final_att_err"].as_f64().unwrap();
    assert!(max < 1e-3, "did not converge: max final att_err {max}");
    for (a, c) in s["agents"]
        .as_array()
        .unwrap()
        .iter()
        .zip(b["agents"].as_array().unwrap())
    {
        for key in ["final_att_err", "final_angvel_err", "peak_torque"] {
            let (x, y) = (a[key].as_f64().unwrap(), c[key].as_f64().unwrap());
            assert!(
                (x - y).abs() <= 1e-12 + 1e-6 * y.abs(),
                "agent {}: {key} {x} with the Python agent, {y} built-in",
                a["id"]
            );
        }
    }
}

/// `attsync conform` with the candidate (agent 2) in the neighbourhood
/// `scenarios/plugin/<neighbourhood>.toml`.
fn conforms_in(neighbourhood: &str) {
    let tmp = Sandbox::new(neighbourhood);
    let file = scenario(&format!("plugin/{neighbourhood}.toml"));
    let r = conform_python(&tmp, &["--scenario".into(), file.into()], &agent_py());
    r.assert_ok();
    assert!(r.stdout.contains("10/10 rules pass"), "{}", r.describe());
}

#[test]
fn the_python_agent_conforms_with_the_time_varying_observer() {
    conforms_in("conform-timevarying");
}

#[test]
fn the_python_agent_conforms_with_the_constant_observer() {
    conforms_in("conform-constant-observer");
}

/// Runs `scenarios/plugin/<plugin>.toml` (agent 3 the Python agent) and
/// `scenarios/paper/<builtin>.toml` (every agent built-in), both shortened to
/// `duration` s and with `sets`, and asserts byte-identical `errors.csv` and
/// `states.bin` (the plug-in run takes the paper scenario's name, which
/// `states.bin` records).
fn bit_identical_to_builtin(plugin: &str, builtin: &str, sets: &[&str]) {
    require_iceoryx2_module();
    let tmp = Sandbox::new(plugin);
    let (py, reference) = (tmp.join("python"), tmp.join("builtin"));
    let name = format!("name=paper-{builtin}");
    let mut py_sets = vec![name.as_str()];
    py_sets.extend(sets);
    Attsync::new(tmp.path())
        .args(run_args(
            &scenario(&format!("plugin/{plugin}.toml")),
            "processes",
            &py,
            &py_sets,
        ))
        .output()
        .assert_ok()
        .assert_no_leftovers();
    reference_run(tmp.path(), &paper(builtin), &reference, sets);
    let s = summary(&py);
    assert_eq!(s["complete"], true, "{s:#}");
    assert!(
        s["agents"][2]["plugin"]
            .as_str()
            .unwrap()
            .contains("agent.py"),
        "{s:#}"
    );
    assert_same_file(&py.join("errors.csv"), &reference.join("errors.csv"));
    assert_same_bytes(&py.join("states.bin"), &reference.join("states.bin"));
    for (a, b) in s["agents"]
        .as_array()
        .unwrap()
        .iter()
        .zip(summary(&reference)["agents"].as_array().unwrap())
    {
        assert_eq!(a["peak_torque"], b["peak_torque"], "agent {}", a["id"]);
    }
}

#[test]
fn a_python_agent_with_the_time_varying_observer_is_bit_identical() {
    bit_identical_to_builtin(
        "python-timevarying",
        "timevarying",
        &["simulation.duration=5"],
    );
}

#[test]
fn a_python_agent_with_the_constant_observer_is_bit_identical() {
    bit_identical_to_builtin(
        "python-constant-observer",
        "constant-observer",
        &["simulation.duration=5"],
    );
}

#[test]
fn a_python_agent_with_sampled_coupling_is_bit_identical() {
    bit_identical_to_builtin(
        "python-timevarying",
        "timevarying",
        &[
            "simulation.duration=2",
            "simulation.coupling=sampled",
            "simulation.period=0.005",
        ],
    );
}

#[test]
fn a_python_agent_runs_in_real_time_and_reports_its_age_of_information() {
    require_iceoryx2_module();
    let tmp = Sandbox::new("python-realtime");
    let out = tmp.join("rt");
    // Scheme 1, 0.5 s at a quarter of real time (1 ms of wall time per
    // stage, which pure Python keeps up with on a loaded machine): 2 s.
    let mut args = run_args(
        &scenario("plugin/python-timevarying.toml"),
        "processes",
        &out,
        &["simulation.duration=0.5"],
    );
    args.extend(["--realtime".into(), "0.25".into()]);
    Attsync::new(tmp.path())
        .args(args)
        .output()
        .assert_ok()
        .assert_no_leftovers();
    let s = summary(&out);
    assert_eq!(s["complete"], true, "{s:#}");
    assert_eq!(s["realtime"], 0.25, "{s:#}");
    assert!(s["wall_seconds"].as_f64().unwrap() >= 1.9, "{s:#}");
    let agent3 = &s["agents"][2];
    assert!(
        agent3["plugin"].as_str().unwrap().contains("agent.py"),
        "{s:#}"
    );
    assert!(agent3["late_stages"].is_u64(), "{agent3}");
    assert!(agent3["max_lateness"].is_f64(), "{agent3}");
    // Agent 3 reads agents 1, 5 and 6 (its LinkStats), which read it.
    let links = s["links"].as_array().expect("links");
    let exchanges = 500 * 4;
    for (from, to) in [(1, 3), (5, 3), (6, 3), (3, 1), (3, 5), (3, 6)] {
        let l = links
            .iter()
            .find(|l| l["from"] == from && l["to"] == to)
            .unwrap_or_else(|| panic!("no link {from} -> {to} in {s:#}"));
        assert_eq!(l["sent"], exchanges, "{l}");
        let delivered = l["delivered"].as_u64().unwrap();
        assert!(delivered > 0, "{l}");
        assert_eq!(l["lost"].as_u64().unwrap(), exchanges - delivered, "{l}");
        let (mean, max) = (
            l["aoi_mean"].as_f64().unwrap(),
            l["aoi_max"].as_f64().unwrap(),
        );
        assert!(mean > 0.0 && mean <= max && max < 0.5, "{l}");
    }
}
