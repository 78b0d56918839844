//! Runs across hosts that go wrong (issue 12), and the daemon's own life:
//! - a daemon SIGKILLed mid-run (plain TCP): the run fails (within 10 s here — the 2 s
//!   of the issue is a benchmark figure, not asserted), naming the host and
//!   its nodes; the results so far are kept; the other host and the
//!   orchestrator's machine keep nothing; the daemon restarted serves the
//!   next run;
//! - a host nobody serves: a clear error naming it and its endpoint;
//! - `attsync host`: bad options exit 2 naming the flag; SIGTERM ends it
//!   with exit 0.

use attsync_tests::{
    Attsync, Daemon, HostSandbox, Sandbox, assert_hosts_clean, assert_serves_again, free_port,
    hosts_file, paper, run_on_hosts, staging_dir, summary,
};
use std::time::{Duration, Instant};

#[test]
fn a_daemon_killed_mid_run_fails_the_run_naming_it_and_a_restarted_one_serves_again() {
    let tmp = Sandbox::new("hosts-kill");
    // Plain TCP: a killed daemon's reset is seen at once (over QUIC the
    // dead link is noticed only when a blocked write gives up, ~12 s).
    let tcp = || format!("tcp/127.0.0.1:{}", free_port());
    let (la, lb) = (tcp(), tcp());
    let a = Daemon::start_on(HostSandbox::new("a"), &la, la.clone(), &[]);
    let mut b = Daemon::start_on(HostSandbox::new("b"), &lb, lb.clone(), &[&a]);
    let hosts = hosts_file(
        tmp.path(),
        "hosts.toml",
        &[(&a, false, &[1, 3]), (&b, false, &[2, 4])],
    );
    let out = tmp.join("killed");
    let running = run_on_hosts(
        tmp.path(),
        &paper("timevarying"),
        &out,
        &["simulation.duration=400"],
        &hosts,
    )
    .spawn();
    let staging = staging_dir(&out, running.pid());
    // Agent 5 runs on the orchestrator's machine: once it steps, so do the hosts.
    let running = running.once_stepping(&staging, "agent-5");
    let killed_at = Instant::now();
    b.kill();
    let finished = running.wait(Duration::from_secs(60));
    let took = killed_at.elapsed();
    eprintln!("the run failed {took:?} after host b was killed");
    finished.assert_code(1);
    assert!(
        took < Duration::from_secs(10),
        "the run took {took:?} to fail"
    );
    let e = &finished.stderr;
    assert!(e.contains("host b was lost"), "{e}");
    assert!(e.contains("agent-2, agent-4"), "{e}");
    let s = summary(&out);
    assert_eq!(s["complete"], false, "{s:#}");
    assert!(
        s["incomplete_reason"]
            .as_str()
            .is_some_and(|r| r.contains("host b")),
        "{s:#}"
    );
    finished.assert_no_leftovers();
    assert_hosts_clean(&[&a]);
    // The same daemon, started again, serves the next run.
    b.restart();
    assert_serves_again(&tmp, &hosts, &[&a, &b]);
}

#[test]
fn a_host_nobody_serves_is_named_with_its_endpoint() {
    let tmp = Sandbox::new("hosts-unreachable");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let file = tmp.join("hosts.toml");
    let text = format!(
        "insecure = true\n\n[[host]]\nname = \"ghost\"\nendpoint = \"{endpoint}\"\nagents = [2]\n"
    );
    std::fs::write(&file, text).expect("HOSTS.toml");
    let out = tmp.join("results");
    let finished = run_on_hosts(
        tmp.path(),
        &paper("timevarying"),
        &out,
        &["simulation.duration=1"],
        &file,
    )
    .output();
    finished.assert_code(1).assert_no_leftovers();
    let e = &finished.stderr;
    assert!(
        e.contains(&format!("host ghost ({endpoint}) is unreachable")),
        "{e}"
    );
}

#[test]
fn the_daemon_checks_its_options_and_ends_cleanly_on_sigterm() {
    let tmp = Sandbox::new("hosts-daemon");
    let bad = Attsync::new(tmp.path())
        .args([
            "host",
            "--name",
            "a",
            "--listen",
            "127.0.0.1:7447",
            "--insecure",
        ])
        .output();
    bad.assert_code(2);
    assert!(
        bad.stderr.contains("--listen: `127.0.0.1:7447`"),
        "{}",
        bad.stderr
    );
    let bad = Attsync::new(tmp.path())
        .args([
            "host",
            "--name",
            "a/b",
            "--listen",
            "tcp/127.0.0.1:7447",
            "--insecure",
        ])
        .output();
    bad.assert_code(2);
    assert!(bad.stderr.contains("--name: `a/b`"), "{}", bad.stderr);
    let mut d = Daemon::start("a", &[]);
    // It serves (a run on it completes), then SIGTERM ends it with 0.
    let hosts = hosts_file(tmp.path(), "hosts.toml", &[(&d, true, &[])]);
    let out = tmp.join("results");
    run_on_hosts(
        tmp.path(),
        &paper("constant-observer"),
        &out,
        &["simulation.duration=1"],
        &hosts,
    )
    .output()
    .assert_ok();
    let status = d.terminate().expect("it ended within 20 s");
    assert!(status.success(), "{status:?}\n{}", d.log());
    assert_hosts_clean(&[&d]);
}
