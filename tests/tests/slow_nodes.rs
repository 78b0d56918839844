//! Nodes that are slow at the wrong moment. The orchestrator starts every
//! node; each waits (bounded) until its peers are connected, reports
//! `Ready`, and steps only after `Start`, taking each input's messages in
//! order; so however slow a node is at any point, the run must give the
//! in-process results (a fast sender is held back by the receiver's full
//! buffer, ARCHITECTURE.md).
//!
//! The test makes the leader late and its followers slow with `kill -STOP` /
//! `kill -CONT` on the node processes of the paper's time-varying scenario
//! (agents 1 and 2 hear the leader; agent 6 is linked to neither):
//! 1. stop the leader and agent 6 as soon as their processes exist (before
//!    they open their iceoryx2 ports); let the others open theirs (0.5 s);
//! 2. continue the leader; wait until agents 1 and 2 have logged `ready`;
//!    stop them;
//! 3. continue agent 6: every node is ready, the orchestrator sends `Start`,
//!    and the leader (which has no inputs) runs ahead until agents 1 and 2
//!    hold it back; after 0.5 s continue them.
//!
//! Asserts the run exits 0, leaves no iceoryx2 files, and equals an
//! in-process run.

use attsync_tests::{
    Attsync, RUN_TIMEOUT, Sandbox, assert_same_results, node_pid, owned_runs, paper, run_args,
    run_processes, signal, staging_dir, wait_until,
};
use std::time::Duration;

const SETS: [&str; 1] = ["simulation.duration=1"];

#[test]
fn late_leader_and_slow_followers() {
    let tmp = Sandbox::new("slow-nodes");
    let reference = tmp.join("in-process");
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("timevarying"),
            "in-process",
            &reference,
            &SETS,
        ))
        .output()
        .assert_ok();

    let out = tmp.join("processes");
    let running = Attsync::new(tmp.path())
        .args(run_args(&paper("timevarying"), "processes", &out, &SETS))
        .spawn();
    let pid = running.pid();
    let (fast, bound) = (Duration::from_micros(200), Duration::from_secs(30));
    let run = wait_until(bound, fast, || owned_runs(pid).into_iter().next())
        .expect("attsync creates its namespace");
    let node = |id: u32| {
        wait_until(bound, fast, || node_pid(&run, id))
            .unwrap_or_else(|| panic!("no process for node {id}: {:#?}", run_processes(&run)))
    };
    let stop = |p: u32| assert!(signal(p, "STOP"), "kill -STOP {p}");
    let cont = |p: u32| assert!(signal(p, "CONT"), "kill -CONT {p}");

    // 1.
    let leader = node(0);
    stop(leader);
    let agent6 = node(6);
    stop(agent6);
    std::thread::sleep(Duration::from_millis(500));
    // 2.
    cont(leader);
    let logs = staging_dir(&out, pid).join("logs");
    let ready = |id: u32| {
        let log = logs.join(format!("agent-{id}.log"));
        wait_until(bound, Duration::from_millis(5), || {
            std::fs::read_to_string(&log)
                .is_ok_and(|l| l.contains("ready"))
                .then_some(())
        })
        .unwrap_or_else(|| {
            panic!(
                "agent {id} not ready within {bound:?}: {:?}",
                std::fs::read_to_string(&log)
            )
        });
    };
    ready(1);
    ready(2);
    let followers = [node(1), node(2)];
    followers.iter().copied().for_each(stop);
    // 3.
    cont(agent6);
    std::thread::sleep(Duration::from_millis(500));
    followers.iter().copied().for_each(cont);

    running.wait(RUN_TIMEOUT).assert_ok().assert_no_leftovers();
    assert_same_results(&out, &reference);
}
