//! The in-process engine on several threads gives the same results, bit
//! for bit, as on one (issue 11 item 5): every agent does the same
//! arithmetic on the same held values whichever thread steps it.
//!
//! - the paper's three scenarios, stepped by the library on exactly 1, 2, 3
//!   and 7 threads (one agent per thread at 7): every sampled state, peak
//!   torque and link counter equal to the bit;
//! - generated 300-agent trees (schemes 3 and 1) through `attsync run
//!   --threads N` (N = 1, 2, 3, 7): `errors.csv` and `states.bin` byte-identical, and
//!   `summary.json` records the threads used (7 asks for more than 300 / 64
//!   allows: 4);
//! - per-agent work at samples (`InProcess::run_with`, how `attsync run`
//!   makes `errors.csv` rows on the stepping threads): the outputs equal the
//!   work done on the snapshot, for 1, 2, 3 and 7 threads alike;
//! - `--threads 0` is refused with exit code 2, naming the option.

mod common;

use attitude::engine::InProcess;
use attitude::link::LinkStats;
use attitude::network::AgentState;
use attitude::reference::LeaderState;
use attsync::scenario::load;
use common::{PAPER, attsync, load_paper, run_args, summary};
use std::path::PathBuf;

/// Every sample's step and state bits, the peak torques and the link counters.
type Run = (Vec<(u64, Vec<u64>)>, Vec<u64>, Vec<Vec<(u32, LinkStats)>>);

fn run_on(net: &attitude::network::Network, threads: usize) -> Run {
    let mut engine = InProcess::new(net).with_exact_threads(threads);
    assert_eq!(engine.threads(), threads);
    let mut samples = Vec::new();
    engine.run(|snap| {
        let bits = (snap.agents.iter())
            .flat_map(|a| {
                (a.r.iter().chain(&a.w).chain(&a.r_hat))
                    .chain(&a.w_hat)
                    .chain(&a.s_hat)
            })
            .chain(snap.leader.r0.iter().chain(&snap.leader.w0))
            .map(|v| v.to_bits())
            .collect();
        samples.push((snap.step, bits));
        true
    });
    let agents = engine.agents();
    let peaks = agents.iter().map(|a| a.peak_torque().to_bits()).collect();
    (
        samples,
        peaks,
        agents.iter().map(|a| a.link_stats()).collect(),
    )
}

#[test]
fn paper_scenarios_are_bit_identical_on_1_2_3_and_7_threads() {
    for name in ["timevarying", "constant-observer", "constant-observerless"] {
        let loaded = load_paper(name, &["simulation.duration=1"]);
        let net = &loaded.resolved.network;
        let one = run_on(net, 1);
        assert_eq!(one.0.len(), 101, "{name}: samples every 10 ms over 1 s");
        assert_ne!(one.0[0].1, one.0[100].1, "{name}: the network moved");
        for threads in [2, 3, 7] {
            assert!(
                run_on(net, threads) == one,
                "{name}: {threads} threads differ"
            );
        }
    }
}

#[test]
fn per_agent_work_at_samples_is_the_same_on_any_thread_count() {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/tree-30.toml");
    let loaded = load(&file, &["simulation.duration=0.2".into()]).expect("valid");
    let net = &loaded.resolved.network;
    // The work: the agent's index and the bits of its attitude error.
    let work = |k: usize, x: &AgentState, l: &LeaderState| {
        (k, attitude::metrics::errors(x, l, true).att.to_bits())
    };
    let run = |threads: usize| {
        let mut engine = InProcess::new(net).with_exact_threads(threads);
        let mut samples = Vec::new();
        engine.run_with(work, |snap, outs| {
            let again: Vec<_> = (snap.agents.iter().enumerate())
                .map(|(k, x)| work(k, x, snap.leader))
                .collect();
            assert_eq!(
                outs,
                &again[..],
                "step {}: outputs of the snapshot",
                snap.step
            );
            samples.push(outs.to_vec());
            true
        });
        samples
    };
    let one = run(1);
    assert_eq!(one.len(), 21, "samples every 10 ms over 0.2 s");
    assert_ne!(one[0], one[20], "the errors moved");
    for threads in [2, 3, 7] {
        assert!(run(threads) == one, "{threads} threads differ");
    }
}

#[test]
fn a_300_agent_tree_gives_byte_identical_results_for_any_thread_count() {
    tree_results_are_byte_identical_for_any_thread_count("observerless");
}

#[test]
fn a_300_agent_scheme_1_tree_gives_byte_identical_results_for_any_thread_count() {
    tree_results_are_byte_identical_for_any_thread_count("observer-time-varying");
}

/// A generated 300-agent tree under `scheme` through `attsync run
/// --threads 1/2/3/7`: `errors.csv` and `states.bin` byte-identical,
/// `summary.json` naming the threads used.
fn tree_results_are_byte_identical_for_any_thread_count(scheme: &str) {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = tmp.path();
    let made = attsync(
        dir,
        &[
            "gen",
            "tree",
            "--agents",
            "300",
            "--leader-links",
            "3",
            "--seed",
            "1",
            "--scheme",
            scheme,
            "--duration",
            "0.3",
            "--out",
            "tree.toml",
        ],
    );
    made.assert_ok();
    let mut first: Option<(Vec<u8>, Vec<u8>)> = None;
    for (threads, used) in [("1", 1), ("2", 2), ("3", 3), ("7", 4)] {
        let out = format!("out-{threads}");
        let mut args = run_args("tree.toml", "in-process", &out, &[]);
        args.extend(["--threads".into(), threads.into()]);
        attsync(dir, &args).assert_ok();
        let out = dir.join(out);
        assert_eq!(summary(&out)["threads"], serde_json::json!(used));
        let files = (
            std::fs::read(out.join("errors.csv")).expect("errors.csv"),
            std::fs::read(out.join("states.bin")).expect("states.bin"),
        );
        assert!(files.0.len() > 300 * 30 && !files.1.is_empty());
        match &first {
            None => first = Some(files),
            Some(f) => assert!(*f == files, "{scheme}, --threads {threads}: results differ"),
        }
    }
}

#[test]
fn zero_threads_are_refused_naming_the_option() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let paper = PAPER;
    for cmd in [
        vec![
            "run",
            paper,
            "--engine",
            "in-process",
            "--threads",
            "0",
            "--out",
            "o",
        ],
        vec![
            "sweep",
            paper,
            "--param",
            "simulation.dt",
            "--values",
            "0.001",
            "--threads",
            "0",
        ],
    ] {
        let out = attsync(tmp.path(), &cmd);
        assert_eq!(out.code, Some(2), "{cmd:?}");
        let err = &out.stderr;
        assert!(err.contains("--threads 0: must be at least 1"), "{err}");
    }
    assert!(!tmp.path().join("o").exists());
}
