//! The mesh the orchestrator wires (issue 37, item 3): daemons started with
//! `--listen` only serve a run split over them, byte-identical to the
//! in-process engine, each host that dials a peer saying so on its stdout;
//! and a pair of hosts that cannot reach each other (one in a network
//! namespace of its own, to which the other's `127.0.0.1` is its own
//! loopback) fails the run before `Start`, within seconds, naming both
//! hosts and the endpoint that did not answer, nothing left anywhere.

use attsync_tests::{
    Daemon, HostSandbox, Sandbox, assert_hosts_clean, assert_same_results, free_port, hosts_file,
    paper, reference_run, run_on_hosts,
};
use std::time::{Duration, Instant};

#[test]
fn daemons_started_with_listen_only_serve_a_run() {
    let tmp = Sandbox::new("hosts-mesh");
    let a = Daemon::start("mesh-a", &[]);
    let b = Daemon::start("mesh-b", &[]);
    // cut edges a–b: 1–3 and 2–7; the leader stays on this machine
    let hosts = hosts_file(
        tmp.path(),
        "hosts.toml",
        &[(&a, false, &[1, 2, 4]), (&b, false, &[3, 5, 6, 7])],
    );
    let (p, i) = (tmp.join("hosts"), tmp.join("in-process"));
    let sets = ["simulation.duration=1"];
    let scenario = paper("timevarying");
    run_on_hosts(tmp.path(), &scenario, &p, &sets, &hosts)
        .output()
        .assert_ok()
        .assert_no_leftovers();
    reference_run(tmp.path(), &scenario, &i, &sets);
    assert_same_results(&p, &i);
    let said = b.stdout();
    assert!(said.contains("; dialled host mesh-a"), "{said}");
    assert!(!a.stdout().contains("dialled host"), "{}", a.stdout());
    assert_hosts_clean(&[&a, &b]);
}

#[test]
fn hosts_that_cannot_reach_each_other_fail_the_run_before_start_naming_both() {
    let tmp = Sandbox::new("hosts-mesh-apart");
    let near_at = format!("tcp/127.0.0.1:{}", free_port());
    let near = Daemon::start_on(HostSandbox::new("near"), &near_at, near_at.clone(), &[]);
    let far_host = HostSandbox::networked("far");
    let veth = far_host.veth().expect("a networked host has a veth");
    let far_at = format!("tcp/{}:{}", veth.host_addr, free_port());
    let far = Daemon::start_on(far_host, &far_at, far_at.clone(), &[]);
    // near is listed first: far dials it, at an address far cannot reach
    let hosts = hosts_file(
        tmp.path(),
        "hosts.toml",
        &[(&near, false, &[1, 4, 6]), (&far, false, &[3, 5])],
    );
    let out = tmp.join("results");
    let t0 = Instant::now();
    let finished = run_on_hosts(
        tmp.path(),
        &paper("timevarying"),
        &out,
        &["simulation.duration=1"],
        &hosts,
    )
    .output();
    let took = t0.elapsed();
    finished.assert_code(1).assert_no_leftovers();
    let e = &finished.stderr;
    let named = format!("host far cannot reach host near at {near_at}: no answer within 5 s");
    assert!(e.contains(&named), "{e}");
    assert!(took < Duration::from_secs(20), "failed after {took:?}");
    assert!(!e.contains("timed out"), "it failed before Start: {e}");
    assert!(far.stdout().contains("refused"), "{}", far.stdout());
    assert_hosts_clean(&[&near, &far]);
}
