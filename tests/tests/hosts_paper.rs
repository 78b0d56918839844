//! The paper's runs split over hosts (issue 12): each host an `attsync
//! host` daemon in a sandbox of its own (private `/dev/shm`, own `TMPDIR`),
//! Zenoh over 127.0.0.1; `errors.csv` and `states.bin` byte-identical to
//! the in-process engine; nothing left on any host; a daemon serves one
//! run after another and two runs at once.

use attsync_tests::{
    Attsync, Daemon, Sandbox, assert_hosts_clean, assert_same_results, hosts_file, paper, run_args,
    run_on_hosts, summary,
};
use std::path::Path;

const TWO_SECONDS: &str = "simulation.duration=2";

/// Runs `scenario` over `hosts` into `out`, asserting success.
fn run_over(tmp: &Sandbox, scenario: &Path, hosts: &Path, out: &Path) {
    run_on_hosts(tmp.path(), scenario, out, &[TWO_SECONDS], hosts)
        .output()
        .assert_ok()
        .assert_no_leftovers();
    assert_eq!(summary(out)["complete"], true);
}

/// The in-process reference of `scenario` into `out`.
fn reference(tmp: &Sandbox, scenario: &Path, out: &Path) {
    Attsync::new(tmp.path())
        .args(run_args(scenario, "in-process", out, &[TWO_SECONDS]))
        .output()
        .assert_ok();
}

#[test]
fn timevarying_with_agents_on_one_host_is_byte_identical() {
    let tmp = Sandbox::new("hosts-tv");
    let a = Daemon::start("a", &[]);
    let hosts = hosts_file(tmp.path(), "hosts.toml", &[(&a, false, &[2, 3])]);
    let (p, i) = (tmp.join("hosts"), tmp.join("in-process"));
    run_over(&tmp, &paper("timevarying"), &hosts, &p);
    reference(&tmp, &paper("timevarying"), &i);
    assert_same_results(&p, &i);
    // The remote nodes' logs came back.
    let log = std::fs::read_to_string(p.join("logs/agent-2.log")).expect("agent-2's log");
    assert!(log.contains("done"), "{log}");
    assert_hosts_clean(&[&a]);
    // The daemon said that it listens (name, endpoint, version), then one
    // line for the run it served.
    let said = a.stdout();
    let lines: Vec<&str> = said.lines().collect();
    let version = env!("CARGO_PKG_VERSION");
    assert!(
        lines[0].starts_with(&format!(
            "attsync host a {version}: listening on quic/127.0.0.1:"
        )),
        "{said}"
    );
    assert!(
        lines[1].starts_with("run ") && lines[1].ends_with(": started 2 nodes (agent-2, agent-3)"),
        "{said}"
    );
    assert_eq!(lines.len(), 2, "{said}");
}

#[test]
fn the_three_schemes_over_three_hosts_are_byte_identical_and_the_daemons_serve_run_after_run() {
    let tmp = Sandbox::new("hosts-schemes");
    let a = Daemon::start("a", &[]);
    let b = Daemon::start("b", &[&a]);
    let c = Daemon::start("c", &[&a, &b]);
    let hosts = hosts_file(
        tmp.path(),
        "hosts.toml",
        &[
            (&a, true, &[1, 2]),
            (&b, false, &[3, 4]),
            (&c, false, &[5, 6]),
        ],
    );
    for scheme in ["timevarying", "constant-observer", "constant-observerless"] {
        let (p, i) = (tmp.join(format!("{scheme}-hosts")), tmp.join(scheme));
        run_over(&tmp, &paper(scheme), &hosts, &p);
        reference(&tmp, &paper(scheme), &i);
        assert_same_results(&p, &i);
        assert_hosts_clean(&[&a, &b, &c]);
    }
}

#[test]
fn two_runs_at_once_on_the_same_daemons_are_isolated() {
    let tmp = Sandbox::new("hosts-two");
    let a = Daemon::start("a", &[]);
    let b = Daemon::start("b", &[&a]);
    let hosts = hosts_file(
        tmp.path(),
        "hosts.toml",
        &[(&a, true, &[1, 3, 5]), (&b, false, &[2, 4])],
    );
    let scheme = paper("constant-observerless");
    let runs: Vec<_> = (0..2)
        .map(|k| {
            let out = tmp.join(format!("run-{k}"));
            let running = run_on_hosts(tmp.path(), &scheme, &out, &[TWO_SECONDS], &hosts).spawn();
            (out, running)
        })
        .collect();
    let i = tmp.join("in-process");
    reference(&tmp, &scheme, &i);
    for (out, running) in runs {
        running.wait(attsync_tests::RUN_TIMEOUT).assert_ok();
        assert_same_results(&out, &i);
    }
    assert_hosts_clean(&[&a, &b]);
}
