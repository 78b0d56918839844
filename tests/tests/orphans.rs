//! Nodes never outlive their orchestrator: after `kill -9` of `attsync run`,
//! every node process of the run (`attsync-agent` / `attsync-leader` with
//! `--config <tmp>/attsync-iox2/<run>/node-<id>.json`) exits by itself
//! (each checks its parent at least every 100 ms in every phase).
//!
//! - connecting: agent 3 is a plug-in that never connects (`sleep 30`), so
//!   every other node waits in the readiness barrier;
//! - stepping: the paper's time-varying scenario (40 s), killed once agent 3
//!   has logged `started` and rows of `errors.csv` are written.
//!
//! The plug-in `sleep` is not a node: it may outlive the orchestrator and is
//! not looked at. The nodes must be gone within 5 s (expected: well under 1 s;
//! the time measured is printed).

use attsync_tests::{
    Attsync, Running, Sandbox, kill9, node_pid, owned_run, paper, run_args, run_leftovers,
    run_processes, staging_dir, wait_until, with_agent_lines,
};
use std::time::{Duration, Instant};

const POLL: Duration = Duration::from_millis(20);

/// Pids of the node processes `ids` of run `run` that are alive.
fn alive(run: &str, ids: &[u32]) -> Vec<(u32, u32)> {
    ids.iter()
        .filter_map(|&id| node_pid(run, id).map(|pid| (id, pid)))
        .collect()
}

/// Kills `attsync` and asserts that the nodes `ids` of `run` all exit;
/// then removes what is left of the run (the plug-in, iceoryx2's files).
fn kill_orchestrator_and_check(mut running: Running, run: &str, ids: &[u32]) {
    assert!(kill9(running.pid()), "kill -9 attsync failed");
    let killed = Instant::now();
    // (Dropping `running` would kill the nodes: reap the orchestrator only.)
    let reaped = wait_until(Duration::from_secs(5), POLL, || {
        running.has_ended().then_some(())
    });
    assert!(reaped.is_some(), "attsync survived kill -9");
    let gone = wait_until(Duration::from_secs(5), Duration::from_millis(5), || {
        alive(run, ids).is_empty().then_some(())
    });
    let after = killed.elapsed();
    let left = alive(run, ids);
    for (pid, _) in run_processes(run) {
        kill9(pid);
    }
    let _ = running.wait(Duration::from_secs(10));
    for path in run_leftovers(run) {
        let _ = std::fs::remove_dir_all(&path).or_else(|_| std::fs::remove_file(&path));
    }
    assert!(
        gone.is_some(),
        "node processes (id, pid) of run {run} still alive 5 s after the orchestrator's death: {left:?}"
    );
    eprintln!(
        "every node exited {:.0} ms after the orchestrator's death",
        after.as_secs_f64() * 1e3
    );
}

#[test]
fn nodes_exit_when_the_orchestrator_dies_while_they_connect() {
    let tmp = Sandbox::new("orphans-connecting");
    // (`sh -c` ignores the `--config FILE` appended to a plug-in's command.)
    let extra = "command = [\"sh\", \"-c\", \"sleep 30\", \"never-connects\"]\n";
    let file = with_agent_lines(&tmp, &paper("timevarying"), 3, "never-connects", extra);
    let out = tmp.join("results");
    let running = Attsync::new(tmp.path())
        .args(run_args(&file, "processes", &out, &[]))
        .spawn();
    let run = owned_run(running.pid());
    let nodes = [0, 1, 2, 4, 5, 6, 7];
    let all = wait_until(Duration::from_secs(30), POLL, || {
        (alive(&run, &nodes).len() == nodes.len()).then_some(())
    });
    assert!(
        all.is_some(),
        "not every node started: {:?}",
        alive(&run, &nodes)
    );
    // Let them get into the readiness barrier (the leader's and agent 3's
    // neighbours' wait for agent 3 lasts 30 s).
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(alive(&run, &nodes).len(), nodes.len(), "a node ended early");
    kill_orchestrator_and_check(running, &run, &nodes);
}

#[test]
fn nodes_exit_when_the_orchestrator_dies_while_they_step() {
    let tmp = Sandbox::new("orphans-stepping");
    let out = tmp.join("results");
    let running = Attsync::new(tmp.path())
        .args(run_args(
            &paper("timevarying"),
            "processes",
            &out,
            &["simulation.duration=40"],
        ))
        .spawn();
    let staging = staging_dir(&out, running.pid());
    let running = running.once_stepping(&staging, "agent-3");
    let run = owned_run(running.pid());
    let nodes: Vec<u32> = (0..=7).collect();
    assert_eq!(alive(&run, &nodes).len(), nodes.len(), "a node ended early");
    kill_orchestrator_and_check(running, &run, &nodes);
}
