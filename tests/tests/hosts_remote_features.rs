//! Across hosts, what a local run has must work on a remote host too
//! (issue 12), each host an `attsync host` daemon in a sandbox of its own
//! (private `/dev/shm`, own `TMPDIR`), Zenoh over 127.0.0.1:
//! - a plug-in (the `saturated-agent` example behind a wrapper checking
//!   PROTOCOL.md's command rules) placed on a host: the same `errors.csv`
//!   and `states.bin` as the whole run on one machine;
//! - real-time mode: every link, the cut edges too, reported with its age
//!   of information;
//! - the orchestrator SIGKILLed while stepping: each daemon ends its run
//!   (nodes, `/dev/shm`, namespace gone) and serves the next one;
//! - a remote node that prints a lot: its log in the results is only the
//!   end of it, headed by a note saying how much was cut.
//!
//! Nothing is left on any host afterwards.

use attsync_tests::{
    Attsync, Daemon, Running, Sandbox, assert_hosts_clean, assert_same_bytes, assert_serves_again,
    bin, hosts_file, kill9, owned_run, paper, read, run_args, run_leftovers, run_on_hosts,
    run_processes, scenario, sh_plugin, staging_dir, summary, wait_until, with_agent_lines,
};
use std::collections::BTreeSet;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// A generous bound for a daemon's clean-up (the orchestrator's liveliness
/// lease is 2 s); not a measured figure.
const CLEANUP_BOUND: Duration = Duration::from_secs(10);

/// How often the bounded waits poll.
const POLL: Duration = Duration::from_millis(20);

/// The saturated plug-in scenario, agent 3 started through `sh -c` that
/// runs `saturated-agent` only if the rules of PROTOCOL.md § 1 hold: its
/// `env` (`SATURATED_TAU_MAX`), `ATTSYNC_CONFIG`, and the scenario's
/// directory as its working directory (`marker` lies beside the copy).
fn saturated_scenario(tmp: &Sandbox) -> PathBuf {
    let text = read(&scenario("plugin/saturated-observerless.toml"));
    let line = "command = [\"../../target/release/saturated-agent\"]";
    assert!(text.contains(line), "the scenario's command changed");
    let script = r#"test "$SATURATED_TAU_MAX" = 3.0 && test -f "$ATTSYNC_CONFIG" && test -f marker && exec "$0" "$@""#;
    let command = format!(
        "command = [\"sh\", \"-c\", {script:?}, {:?}]",
        bin("saturated-agent").display().to_string()
    );
    std::fs::write(tmp.join("marker"), "").expect("marker");
    let file = tmp.join("saturated.toml");
    std::fs::write(&file, text.replace(line, &command)).expect("scenario");
    file
}

/// `--allow-plugin /bin/sh`: the plug-ins here start through `sh -c`.
fn allow_sh() -> Vec<String> {
    vec!["--allow-plugin".into(), "/bin/sh".into()]
}

#[test]
fn a_plugin_on_a_remote_host_gives_the_results_of_one_machine() {
    let tmp = Sandbox::new("hosts-plugin");
    let scenario = saturated_scenario(&tmp);
    // The plug-in starts through `sh`: the daemon must allow it.
    let a = Daemon::start_with("a", &[], &allow_sh());
    let hosts = hosts_file(tmp.path(), "hosts.toml", &[(&a, false, &[3, 5])]);
    // Run from elsewhere: the plug-in's directory is the scenario's.
    let elsewhere = tmp.join("elsewhere");
    std::fs::create_dir(&elsewhere).expect("a directory");
    let sets = ["simulation.duration=2"];
    let (h, l) = (tmp.join("hosts"), tmp.join("local"));
    run_on_hosts(&elsewhere, &scenario, &h, &sets, &hosts)
        .output()
        .assert_ok()
        .assert_no_leftovers();
    Attsync::new(&elsewhere)
        .args(run_args(&scenario, "processes", &l, &sets))
        .output()
        .assert_ok();
    assert_same_bytes(&h.join("errors.csv"), &l.join("errors.csv"));
    assert_same_bytes(&h.join("states.bin"), &l.join("states.bin"));
    let s = summary(&h);
    assert_eq!(s["complete"], true, "{s:#}");
    let a3 = &s["agents"][2];
    assert_eq!(a3["id"], 3);
    assert!(a3["plugin"].is_string(), "{a3}");
    assert_eq!(a3["plugin"], summary(&l)["agents"][2]["plugin"]);
    // The limit (its env) binds on the host as on one machine.
    let peak = a3["peak_torque"].as_f64().expect("peak_torque");
    assert!(peak <= 3.0 && peak > 2.9, "peak torque {peak}");
    assert_eq!(peak, summary(&l)["agents"][2]["peak_torque"]);
    assert!(
        h.join("logs/agent-3.log").is_file(),
        "agent-3's log came back"
    );
    assert_hosts_clean(&[&a]);
}

/// The directed links `from → to` of the paper's graph (5 edges both ways,
/// the leader to agents 1 and 2) whose ends run on different sides, with
/// `sides[id]` where node `id` runs.
fn cut_edges(sides: &[&str; 8]) -> BTreeSet<(u32, u32)> {
    let edges = [(1, 3), (2, 7), (3, 5), (3, 6), (4, 5)];
    let both = edges.iter().flat_map(|&(i, j)| [(i, j), (j, i)]);
    (both.chain([(0, 1), (0, 2)]))
        .filter(|&(f, t)| sides[f as usize] != sides[t as usize])
        .collect()
}

#[test]
fn realtime_across_hosts_reports_every_link_with_its_age_of_information() {
    let tmp = Sandbox::new("hosts-realtime");
    let a = Daemon::start("a", &[]);
    let b = Daemon::start("b", &[&a]);
    let hosts = hosts_file(
        tmp.path(),
        "hosts.toml",
        &[(&a, true, &[1, 3]), (&b, false, &[2, 5])],
    );
    let sides = ["a", "a", "b", "a", "local", "b", "local", "local"];
    let cut = cut_edges(&sides);
    assert!(cut.len() >= 6, "{cut:?}");
    let out = tmp.join("rt");
    run_on_hosts(
        tmp.path(),
        &paper("constant-observerless"),
        &out,
        &["simulation.duration=1"],
        &hosts,
    )
    .args(["--realtime"])
    .output()
    .assert_ok()
    .assert_no_leftovers();
    let s = summary(&out);
    assert_eq!(s["complete"], true, "{s:#}");
    assert_eq!(s["realtime"], 1.0, "{s:#}");
    let links = s["links"].as_array().expect("links");
    let reported: BTreeSet<(u32, u32)> = links
        .iter()
        .map(|l| {
            let id = |k: &str| u32::try_from(l[k].as_u64().expect("an id")).expect("small");
            (id("from"), id("to"))
        })
        .collect();
    assert_eq!(reported.len(), 12, "every directed link once: {s:#}");
    assert!(cut.is_subset(&reported), "cut edges {cut:?}: {s:#}");
    for l in links {
        let exchanges = 1000 * 4;
        assert_eq!(l["sent"], exchanges, "{l}");
        let delivered = l["delivered"].as_u64().expect("delivered");
        assert!(delivered > 0, "{l}");
        assert_eq!(l["lost"].as_u64(), Some(exchanges - delivered), "{l}");
        let (mean, max) = (l["aoi_mean"].as_f64(), l["aoi_max"].as_f64());
        let (Some(mean), Some(max)) = (mean, max) else {
            panic!("no age of information: {l}");
        };
        assert!(mean > 0.0 && mean <= max && max.is_finite(), "{l}");
        let (p50, p99) = (l["aoi_p50"].as_f64(), l["aoi_p99"].as_f64());
        let (Some(p50), Some(p99)) = (p50, p99) else {
            panic!("no quantiles of the age of information: {l}");
        };
        assert!(0.0 < p50 && p50 <= p99 && p99 <= max * 1.032, "{l}");
    }
    assert_hosts_clean(&[&a, &b]);
}

/// SIGKILLs `running` (the orchestrator only) and reaps it.
fn kill_orchestrator(mut running: Running) -> Running {
    assert!(kill9(running.pid()), "kill -9 attsync failed");
    let reaped = wait_until(CLEANUP_BOUND, POLL, || running.has_ended().then_some(()));
    assert!(reaped.is_some(), "attsync survived kill -9");
    running
}

/// Waits (at most [`CLEANUP_BOUND`]) until `d` holds nothing of its runs;
/// what it still holds otherwise.
fn cleaned_up(d: &Daemon) -> Result<(), Vec<String>> {
    match wait_until(CLEANUP_BOUND, POLL, || {
        d.leftovers().is_empty().then_some(())
    }) {
        Some(()) => Ok(()),
        None => Err(d.leftovers()),
    }
}

#[test]
fn losing_the_orchestrator_makes_each_daemon_clean_its_run_up_and_serve_the_next() {
    let tmp = Sandbox::new("hosts-orphaned");
    let a = Daemon::start("a", &[]);
    let b = Daemon::start("b", &[&a]);
    let hosts = hosts_file(
        tmp.path(),
        "hosts.toml",
        &[(&a, true, &[1, 3]), (&b, false, &[2, 4, 6])],
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
    let local_run = owned_run(running.pid());
    assert!(
        !a.leftovers().is_empty() && !b.leftovers().is_empty(),
        "the hosts run nothing?"
    );
    let running = kill_orchestrator(running);
    let killed = Instant::now();
    for d in [&a, &b] {
        if let Err(left) = cleaned_up(d) {
            panic!(
                "host {} still holds {left:?} {CLEANUP_BOUND:?} after the orchestrator's death\n{}",
                d.name(),
                d.log()
            );
        }
        assert!(d.log().contains("the orchestrator is gone"), "{}", d.log());
    }
    eprintln!(
        "both hosts were clean {:?} after the orchestrator's death",
        killed.elapsed()
    );
    // The local nodes exit by themselves (tests/tests/orphans.rs); what the
    // dead orchestrator could not remove on this machine is removed here.
    drop(running.wait(CLEANUP_BOUND));
    for (pid, _) in run_processes(&local_run) {
        kill9(pid);
    }
    for path in run_leftovers(&local_run) {
        let _ = std::fs::remove_dir_all(&path).or_else(|_| std::fs::remove_file(&path));
    }
    let _ = std::fs::remove_dir_all(&staging);
    // The same daemons serve the next run.
    assert_serves_again(&tmp, &hosts, &[&a, &b]);
}

/// The bytes a chatty plug-in prints before it runs the agent (far more
/// than a host sends back of a log).
const CHATTER: usize = 1 << 20;

#[test]
fn a_remote_nodes_log_in_the_results_is_its_end_and_says_what_was_cut() {
    let tmp = Sandbox::new("hosts-chatty");
    let script =
        format!(r#"yes "chatter chatter chatter" | head -c {CHATTER} >&2; exec "$0" "$@""#);
    // The agent itself is `$0`.
    let agent = format!(", {:?}]\n", bin("attsync-agent").display().to_string());
    let extra = sh_plugin(&script).replacen("]\n", &agent, 1);
    let file = with_agent_lines(&tmp, &paper("constant-observerless"), 3, "chatty", &extra);
    let a = Daemon::start_with("a", &[], &allow_sh());
    let hosts = hosts_file(tmp.path(), "hosts.toml", &[(&a, false, &[3])]);
    let out = tmp.join("results");
    run_on_hosts(tmp.path(), &file, &out, &["simulation.duration=1"], &hosts)
        .output()
        .assert_ok()
        .assert_no_leftovers();
    let log = std::fs::read(out.join("logs/agent-3.log")).expect("agent-3's log");
    assert!(log.len() < CHATTER / 4, "{} bytes came back", log.len());
    let text = String::from_utf8_lossy(&log);
    let first = text.lines().next().expect("a line");
    let cut = first
        .strip_prefix("[attsync: the first ")
        .and_then(|r| r.split_once(" bytes of this log were cut on host a;"))
        .and_then(|(n, _)| n.parse::<usize>().ok());
    let Some(cut) = cut else {
        panic!("no note of the cut: {first}");
    };
    assert!(cut > CHATTER / 2 && cut <= CHATTER, "{cut} bytes cut");
    assert!(text.contains("chatter"), "the end of the chatter came back");
    // The agent's own last lines are there.
    assert!(text.contains("done"), "{}", &text[text.len() - 400..]);
    assert_hosts_clean(&[&a]);
}
