//! Plug-in agents: `[[agent]] command = [...]`, `env = {...}` run the
//! user's program in place of `attsync-agent`, and nothing else changes.

use attsync_tests::{
    Attsync, Sandbox, assert_same_bytes, bin, paper, read, run_args, run_processes, summary,
    with_agent_lines,
};
use std::path::{Path, PathBuf};

/// The observerless paper scenario with `extra` TOML lines added to agent 3.
fn with_agent_3(tmp: &Sandbox, name: &str, extra: &str) -> PathBuf {
    let base = paper("constant-observerless");
    with_agent_lines(tmp, &base, 3, name, &format!("{extra}\n"))
}

fn toml_str(p: &Path) -> String {
    format!("{:?}", p.display().to_string())
}

#[test]
fn a_plugin_running_the_builtin_agent_changes_nothing() {
    let tmp = Sandbox::new("plugin-identity");
    let agent = bin("attsync-agent");
    let scenario = with_agent_3(
        &tmp,
        "identity",
        &format!("command = [{}]", toml_str(&agent)),
    );
    let (p, b) = (tmp.join("plugin"), tmp.join("builtin"));
    let sets = ["simulation.duration=1"];
    Attsync::new(tmp.path())
        .args(run_args(&scenario, "processes", &p, &sets))
        .output()
        .assert_ok()
        .assert_no_leftovers();
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("constant-observerless"),
            "processes",
            &b,
            &sets,
        ))
        .output()
        .assert_ok();
    assert_same_bytes(&p.join("errors.csv"), &b.join("errors.csv"));
    assert_same_bytes(&p.join("states.bin"), &b.join("states.bin"));
    let s = summary(&p);
    assert_eq!(s["agents"][2]["id"], 3);
    assert_eq!(s["agents"][2]["plugin"], agent.display().to_string());
    assert!(s["agents"][1].get("plugin").is_none(), "{s:#}");
}

#[test]
fn a_plugin_gets_its_env_its_config_and_the_scenario_directory() {
    let tmp = Sandbox::new("plugin-env");
    let agent = bin("attsync-agent");
    std::fs::write(tmp.join("marker"), "").unwrap();
    // The wrapper runs the agent only if the variable, the config variable
    // and the working directory are what PROTOCOL.md promises.
    let script = r#"test "$FOO" = "bar baz" && test -f "$ATTSYNC_CONFIG" && test -f marker && exec "$0" "$@""#;
    let scenario = with_agent_3(
        &tmp,
        "env",
        &format!(
            "command = [\"sh\", \"-c\", {script:?}, {}]\nenv = {{ FOO = \"bar baz\" }}",
            toml_str(&agent)
        ),
    );
    // Run from elsewhere: the plug-in's directory is the scenario's.
    std::fs::create_dir(tmp.join("elsewhere")).unwrap();
    let out = tmp.join("out");
    Attsync::new(&tmp.join("elsewhere"))
        .args(run_args(
            &scenario,
            "processes",
            &out,
            &["simulation.duration=0.2"],
        ))
        .output()
        .assert_ok();
    assert_eq!(summary(&out)["complete"], true);
}

#[test]
fn a_plugin_that_hangs_is_named_and_nothing_is_left_running() {
    let tmp = Sandbox::new("plugin-hang");
    let agent = bin("attsync-agent");
    // Runs the real agent, then freezes it (SIGSTOP) after 0.5 s.
    let script = r#""$0" "$@" & p=$!; sleep 0.5; kill -STOP $p; wait $p"#;
    let scenario = with_agent_3(
        &tmp,
        "hang",
        &format!(
            "command = [\"sh\", \"-c\", {script:?}, {}]",
            toml_str(&agent)
        ),
    );
    let out = tmp.join("out");
    let mut args = run_args(&scenario, "processes", &out, &["simulation.duration=40"]);
    args.extend(["--stage-timeout".into(), "2".into()]);
    let r = Attsync::new(tmp.path()).args(args).output();
    r.assert_code(1).assert_no_leftovers();
    assert!(
        r.stderr.contains("agent-3 (plug-in `sh -c") && r.stderr.contains("stopped answering"),
        "{}",
        r.describe()
    );
    for run in &r.runs {
        let left = run_processes(run);
        assert!(left.is_empty(), "processes left running: {left:?}");
    }
    let s = summary(&out);
    assert_eq!(s["complete"], false);
    assert!(
        s["incomplete_reason"]
            .as_str()
            .unwrap()
            .contains("agent-3 (plug-in"),
        "{s:#}"
    );
}

#[test]
fn a_missing_plugin_program_is_a_scenario_error() {
    let tmp = Sandbox::new("plugin-missing");
    let scenario = with_agent_3(
        &tmp,
        "missing",
        "command = [\"./no-such-agent\", \"--fast\"]\nenv = { \"A=B\" = \"x\" }",
    );
    let r = Attsync::new(tmp.path())
        .args(run_args(&scenario, "processes", &tmp.join("out"), &[]))
        .output();
    r.assert_code(2);
    assert!(r.stderr.contains("agent[2].command[0]"), "{}", r.describe());
    assert!(
        r.stderr.contains("./no-such-agent: no such file"),
        "{}",
        r.describe()
    );
    assert!(r.stderr.contains("agent[2].env"), "{}", r.describe());
    assert!(!tmp.join("out").exists());

    // And the in-process engine cannot run a plug-in.
    let ok = with_agent_3(
        &tmp,
        "ok",
        &format!("command = [{}]", toml_str(&bin("attsync-agent"))),
    );
    let r = Attsync::new(tmp.path())
        .args(run_args(&ok, "in-process", &tmp.join("out"), &[]))
        .output();
    r.assert_code(2);
    assert!(
        r.stderr.contains("plug-ins need --engine processes"),
        "{}",
        r.describe()
    );
}

#[test]
fn the_saturated_rust_example_converges_within_its_torque_limit() {
    let tmp = Sandbox::new("plugin-saturated");
    let out = tmp.join("out");
    let scenario = attsync_tests::scenario("plugin/saturated-observerless.toml");
    let text = read(&scenario);
    assert!(
        text.contains("SATURATED_TAU_MAX = \"3.0\""),
        "the scenario's limit changed"
    );
    // The scenario names ../../target/release/saturated-agent; point it at
    // this build's binary, wherever the target directory is.
    let command = format!("agent[2].command=[{}]", toml_str(&bin("saturated-agent")));
    Attsync::new(tmp.path())
        .args(run_args(&scenario, "processes", &out, &[&command]))
        .output()
        .assert_ok()
        .assert_no_leftovers();
    let s = summary(&out);
    assert_eq!(s["complete"], true);
    assert!(s["max_final_att_err"].as_f64().unwrap() < 1e-3, "{s:#}");
    let a3 = &s["agents"][2];
    assert_eq!(a3["id"], 3);
    let peak = a3["peak_torque"].as_f64().unwrap();
    // Built-in agent 3 peaks at ≈ 8.47 N·m: the limit binds.
    assert!(peak <= 3.0 && peak > 2.9, "peak torque {peak}");
}
