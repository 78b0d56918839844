//! The Python example agent (`examples/python/agent.py`, PyPI
//! `iceoryx2==0.10.0`): it passes `attsync conform`, and the observerless
//! paper experiment converges with agent 3 replaced by it, to the same
//! errors as the built-in agent.
//!
//! Needs `python3 -m pip install -r examples/python/requirements.txt` (the
//! README's test command and `.ci/run` do it).

use attsync_tests::{Attsync, Sandbox, paper, run_args, scenario, summary};
use std::path::PathBuf;
use std::process::Command;

fn agent_py() -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/python/agent.py");
    p.canonicalize().expect("examples/python/agent.py")
}

fn require_iceoryx2_module() {
    let ok = Command::new("python3")
        .args(["-c", "import iceoryx2"])
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        ok,
        "python3 cannot import iceoryx2: run `python3 -m pip install -r examples/python/requirements.txt`"
    );
}

#[test]
fn the_python_agent_conforms() {
    require_iceoryx2_module();
    let tmp = Sandbox::new("python-conform");
    let r = Attsync::new(tmp.path())
        .args(["conform", "--log"])
        .args([tmp.join("candidate.log")])
        .args(["--", "python3"])
        .args([agent_py()])
        .output();
    r.assert_ok();
    assert!(r.stdout.contains("9/9 rules pass"), "{}", r.describe());
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
