//! `[[event]] action = "crash"` / `"restart"` (issue 35, item 1): an agent's
//! process really ends and a new one takes over.
//!
//! - a crash and restart (`state = "last"` and `"initial"`, observerless and
//!   scheme 1) runs in both engines with byte-identical `errors.csv` and
//!   `states.bin`, and changes the trajectory; the processes engine reports
//!   the replaced process in `summary.json` `restarts` and logs the new one
//!   to `logs/agent-3.restart-1.log`;
//! - while down the agent is frozen (same attitude and rate in every
//!   sample) with a NaN torque; at its restart it runs again from its state
//!   at the crash or from its initial state;
//! - a crash never followed by a restart keeps the agent down to the end
//!   (its stand-in process is reported all the same), and the links out of
//!   it lose every message from the crash on;
//! - a crash under link delay, jitter and loss, several crashes of one
//!   agent and of two agents, a restart at the smallest gap allowed, and a
//!   crash under sampled coupling are byte-identical too;
//! - bad crash events are refused (exit 2) naming `event[K].action`, and a
//!   crash cannot run in real time.

mod common;

use common::{OBSERVERLESS, PAPER, attsync, json, read, run_args};
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};

/// `base` with `events` appended, written into `dir/name.toml`.
fn scenario(dir: &Path, base: &str, name: &str, events: &str) -> PathBuf {
    scenario_text(dir, &read(Path::new(base)), name, events)
}

/// `text` with `events` appended, written into `dir/name.toml`.
fn scenario_text(dir: &Path, text: &str, name: &str, events: &str) -> PathBuf {
    let file = dir.join(format!("{name}.toml"));
    fs::write(&file, text.to_string() + "\n" + events).expect("write");
    file
}

/// One agent event: `action` of agent `agent` at `t`.
fn event(t: &str, agent: u32, action: &str) -> String {
    format!("[[event]]\nt = {t}\nagent = {agent}\naction = \"{action}\"\n\n")
}

/// A restart of `agent` at `t` from its `state` ("last" or "initial").
fn restart(t: &str, agent: u32, state: &str) -> String {
    format!("[[event]]\nt = {t}\nagent = {agent}\naction = \"restart\"\nstate = \"{state}\"\n\n")
}

/// Runs `file` with `engine` for 2 s into `dir/out`; the run's directory.
fn run(dir: &Path, file: &Path, engine: &str, out: &str) -> PathBuf {
    let out = dir.join(out);
    let o = attsync(
        dir,
        &run_args(file, engine, &out, &["simulation.duration=2"]),
    );
    o.assert_code(0);
    out
}

/// Runs `file` in both engines (`dir/NAME-in`, `dir/NAME-pr`), asserts the
/// same bytes of `errors.csv` and `states.bin`; (in-process, processes).
fn both(dir: &Path, file: &Path, name: &str) -> (PathBuf, PathBuf) {
    let a = run(dir, file, "in-process", &format!("{name}-in"));
    let b = run(dir, file, "processes", &format!("{name}-pr"));
    for f in ["errors.csv", "states.bin"] {
        assert!(
            bytes(&a, f) == bytes(&b, f),
            "{name}: the engines' {f} differ"
        );
    }
    assert!(
        json(&a.join("summary.json")).get("restarts").is_none(),
        "{name}: an in-process run lists restarts"
    );
    (a, b)
}

fn bytes(dir: &Path, name: &str) -> Vec<u8> {
    let file = dir.join(name);
    fs::read(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
}

/// Whether two runs' `errors.csv` and `states.bin` are the same bytes.
fn same_bits(a: &Path, b: &Path) -> bool {
    ["errors.csv", "states.bin"]
        .iter()
        .all(|f| bytes(a, f) == bytes(b, f))
}

/// `summary.json` `restarts` of a processes run.
fn restarts(out: &Path) -> Vec<Value> {
    let s = json(&out.join("summary.json"));
    (s["restarts"].as_array().cloned()).unwrap_or_else(|| panic!("no restarts: {s:#}"))
}

/// Asserts that `r` is a restart of `agent` at `step` by two real processes;
/// (pid_before, pid_after).
#[track_caller]
fn assert_restart(r: &Value, agent: u64, step: u64) -> (u64, u64) {
    assert_eq!(r["agent"].as_u64(), Some(agent), "{r}");
    assert_eq!(r["step"].as_u64(), Some(step), "{r}");
    let before = r["pid_before"].as_u64().expect("pid_before");
    let after = r["pid_after"].as_u64().expect("pid_after");
    assert!(before != 0 && after != 0, "{r}");
    assert_ne!(before, after, "{r}");
    let ms = r["handover_ms"].as_f64();
    assert!(ms.is_some_and(|ms| ms >= 0.0 && ms.is_finite()), "{r}");
    (before, after)
}

/// `attsync export --csv` of a run's `states.bin`: the header and the rows.
struct Csv {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    fn of(dir: &Path, out: &Path) -> Self {
        let states = out.join("states.bin");
        let o = attsync(
            dir,
            &["export".as_ref(), states.as_os_str(), "--csv".as_ref()],
        );
        o.assert_ok();
        let mut lines = o.stdout.lines();
        let split = |l: &str| l.split(',').map(str::to_string).collect::<Vec<_>>();
        let header = split(lines.next().expect("header"));
        Csv {
            header,
            rows: lines.map(split).collect(),
        }
    }

    fn col(&self, name: &str) -> usize {
        (self.header.iter().position(|h| h == name))
            .unwrap_or_else(|| panic!("no column {name}: {:?}", self.header))
    }

    /// Node `node`'s samples: (t, its row).
    fn node(&self, node: u32) -> Vec<(f64, &Vec<String>)> {
        let (t, n) = (self.col("t"), self.col("node"));
        (self.rows.iter())
            .filter(|r| r[n] == node.to_string())
            .map(|r| (r[t].parse::<f64>().expect("t"), r))
            .collect()
    }

    /// Node `node`'s row at `t` (to 1e-9).
    fn at(&self, node: u32, t: f64) -> &Vec<String> {
        (self.node(node).into_iter())
            .find(|(s, _)| (s - t).abs() < 1e-9)
            .unwrap_or_else(|| panic!("no sample of node {node} at t = {t}"))
            .1
    }

    /// The attitude and rate columns `r11…r33, w1…w3` of `row`, as printed
    /// (shortest round-trip: equal text is equal bits).
    fn motion<'a>(&self, row: &'a [String]) -> &'a [String] {
        let r11 = self.col("r11");
        assert_eq!(self.col("w3"), r11 + 11);
        &row[r11..r11 + 12]
    }

    /// The torque `tau1…tau3` of `row`.
    fn tau(&self, row: &[String]) -> [f64; 3] {
        let k = self.col("tau1");
        [0, 1, 2].map(|i| row[k + i].parse::<f64>().expect("tau"))
    }
}

/// Asserts what `csv` shows of agent 3, which crashed at `t_c` and
/// restarted at `t_r` (`None`: never), from its initial state if `initial`:
/// frozen with a NaN torque while down, finite torque otherwise, and at
/// `t_r` its state at `t_c` or at t = 0.
#[track_caller]
fn assert_down(csv: &Csv, t_c: f64, t_r: Option<f64>, initial: bool, what: &str) {
    let frozen = csv.motion(csv.at(3, t_c)).to_vec();
    let down = |t: f64| t >= t_c - 1e-9 && t_r.is_none_or(|r| t < r - 1e-9);
    let samples = csv.node(3);
    let last = samples.last().expect("samples").0;
    for (t, row) in &samples {
        let tau = csv.tau(row);
        if down(*t) {
            assert_eq!(
                csv.motion(row),
                frozen.as_slice(),
                "{what}: t = {t}: moved while down"
            );
            assert!(tau.iter().all(|x| x.is_nan()), "{what}: t = {t}: {tau:?}");
        } else if *t < last - 1e-9 {
            // The last record has no torque (nothing follows it).
            assert!(
                tau.iter().all(|x| x.is_finite()),
                "{what}: t = {t}: {tau:?}"
            );
        }
    }
    if let Some(t_r) = t_r {
        let from = if initial {
            csv.at(3, 0.0)
        } else {
            csv.at(3, t_c)
        };
        assert_eq!(
            csv.motion(csv.at(3, t_r)),
            csv.motion(from),
            "{what}: at the restart"
        );
        let next = csv.motion(csv.at(3, t_r + 0.01));
        assert_ne!(
            next,
            csv.motion(from),
            "{what}: not running after the restart"
        );
    }
    // The others run on.
    let other = csv.motion(csv.at(4, t_c));
    assert_ne!(
        csv.motion(csv.at(4, t_c + 0.1)),
        other,
        "{what}: agent 4 stopped"
    );
}

#[test]
fn crash_and_restart_are_byte_identical_in_both_engines() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let cases = [
        ("observerless-last", OBSERVERLESS, "last"),
        ("observerless-initial", OBSERVERLESS, "initial"),
        // PAPER: scheme 1 (observer, time-varying reference).
        ("timevarying-last", PAPER, "last"),
    ];
    for base in [OBSERVERLESS, PAPER] {
        let text = read(Path::new(base));
        assert!(text.contains("\nid = 3\n"), "{base}: no agent 3");
        assert!(text.contains("coupling = \"continuous\""), "{base}");
    }
    let plain_obs = run(
        dir,
        Path::new(OBSERVERLESS),
        "in-process",
        "plain-observerless",
    );
    let plain_tv = run(dir, Path::new(PAPER), "in-process", "plain-timevarying");
    let mut outs = Vec::new();
    for (name, base, state) in cases {
        let events = event("0.5", 3, "crash") + &restart("1.2", 3, state);
        let file = scenario(dir, base, name, &events);
        let (a, b) = both(dir, &file, name);
        let plain = if base == PAPER { &plain_tv } else { &plain_obs };
        assert!(!same_bits(&a, plain), "{name}: the crash changed nothing");

        let listed = json(&a.join("summary.json"))["events"].clone();
        let kinds: Vec<_> = (listed.as_array().expect("events").iter())
            .map(|e| (e["kind"].as_str().unwrap().to_string(), e["step"].as_u64()))
            .collect();
        assert_eq!(
            kinds,
            [
                ("crash".to_string(), Some(500)),
                ("restart".to_string(), Some(1200))
            ],
            "{name}: {listed}"
        );
        assert_eq!(
            listed[1]["initial"].as_bool(),
            Some(state == "initial"),
            "{name}"
        );

        let r = restarts(&b);
        assert_eq!(r.len(), 1, "{name}: {r:?}");
        assert_restart(&r[0], 3, 500);
        let logs = b.join("logs");
        assert!(logs.join("agent-3.log").is_file(), "{name}");
        assert!(logs.join("agent-3.restart-1.log").is_file(), "{name}");
        assert!(!logs.join("agent-3.restart-2.log").exists(), "{name}");

        let csv = Csv::of(dir, &a);
        assert_down(&csv, 0.5, Some(1.2), state == "initial", name);
        outs.push(a);
    }
    // From the last state or from the initial one: different runs.
    assert!(!same_bits(&outs[0], &outs[1]));
}

#[test]
fn a_crash_without_restart_keeps_the_agent_down_to_the_end() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let file = scenario(dir, OBSERVERLESS, "down", &event("1.0", 3, "crash"));
    let (a, b) = both(dir, &file, "down");
    let plain = run(dir, Path::new(OBSERVERLESS), "in-process", "plain");
    assert!(!same_bits(&a, &plain), "the crash changed nothing");

    // The crashed process is replaced all the same: by a stand-in that
    // publishes (unused values) to the end, so its neighbours' lockstep
    // goes on.
    let r = restarts(&b);
    assert_eq!(r.len(), 1, "{r:?}");
    assert_restart(&r[0], 3, 1000);
    assert!(b.join("logs/agent-3.restart-1.log").is_file());

    // Every message out of agent 3 from step 1000 to the end (1000 steps, 4
    // per step under continuous coupling) is lost, in both engines.
    for out in [&a, &b] {
        let s = json(&out.join("summary.json"));
        for to in [1, 5, 6] {
            let links = s["links"].as_array().expect("links");
            let l = (links.iter().find(|l| l["from"] == 3 && l["to"] == to))
                .unwrap_or_else(|| panic!("no link 3→{to}: {links:?}"));
            assert_eq!(l["lost"].as_u64(), Some(4 * 1000), "3→{to}: {l}");
        }
    }

    // Frozen with a NaN torque from t = 1.0 to the end, finite before.
    let csv = Csv::of(dir, &b);
    assert_down(&csv, 1.0, None, false, "down");
    let before = csv.tau(csv.at(3, 0.99));
    assert!(before.iter().all(|x| x.is_finite()), "{before:?}");
    let after = csv.tau(csv.at(3, 1.0));
    assert!(after.iter().all(|x| x.is_nan()), "{after:?}");
    assert_eq!(csv.motion(csv.at(3, 1.0)), csv.motion(csv.at(3, 2.0)));
}

#[test]
fn a_crash_under_link_delay_and_loss_is_byte_identical() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let network = "[network]\nseed = 7\ndelay = 0.02\njitter = 0.003\nloss = 0.1\n\n";
    let events = event("0.5", 3, "crash") + &restart("1.2", 3, "last");
    let file = scenario(
        dir,
        OBSERVERLESS,
        "impaired",
        &(network.to_string() + &events),
    );
    let (a, b) = both(dir, &file, "impaired");
    let r = restarts(&b);
    assert_eq!(r.len(), 1, "{r:?}");
    assert_restart(&r[0], 3, 500);
    // Not the impaired run without the crash.
    let without = scenario(dir, OBSERVERLESS, "impaired-only", network);
    let plain = run(dir, &without, "in-process", "impaired-only");
    assert!(!same_bits(&a, &plain));
    assert_down(&Csv::of(dir, &a), 0.5, Some(1.2), false, "impaired");

    // Gilbert–Elliott loss, scheme 1, from the initial state.
    let network = "[network]\nseed = 3\ndelay = 0.005\nloss = { model = \"gilbert-elliott\", p_gb = 0.01, p_bg = 0.3, loss_good = 0.0, loss_bad = 0.8 }\n\n";
    let events = event("0.3", 3, "crash") + &restart("0.9", 3, "initial");
    let file = scenario(dir, PAPER, "impaired-ge", &(network.to_string() + &events));
    let (_, b) = both(dir, &file, "impaired-ge");
    assert_restart(&restarts(&b)[0], 3, 300);
}

#[test]
fn two_crashes_of_one_agent_and_one_of_another() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let text = read(Path::new(OBSERVERLESS));
    assert!(text.contains("\nid = 3\n") && text.contains("\nid = 5\n"));
    let events = event("0.3", 3, "crash")
        + &event("0.6", 3, "restart")
        + &event("1.0", 3, "crash")
        + &event("1.4", 3, "restart")
        + &event("0.5", 5, "crash")
        + &event("0.9", 5, "restart");
    let file = scenario_text(dir, &text, "two", &events);
    let (a, b) = both(dir, &file, "two");
    let r = restarts(&b);
    assert_eq!(r.len(), 3, "{r:?}");
    // In the order they happened.
    let (_, first) = assert_restart(&r[0], 3, 300);
    assert_restart(&r[1], 5, 500);
    let (second, _) = assert_restart(&r[2], 3, 1000);
    assert_eq!(first, second, "the second crash ends the first stand-in");
    let logs = b.join("logs");
    for f in [
        "agent-3.restart-1.log",
        "agent-3.restart-2.log",
        "agent-5.restart-1.log",
    ] {
        assert!(logs.join(f).is_file(), "no {f}");
    }
    assert!(!logs.join("agent-5.restart-2.log").exists());
    assert!(!logs.join("agent-3.restart-3.log").exists());
    assert_eq!(
        json(&a.join("summary.json"))["events"]
            .as_array()
            .map(Vec::len),
        Some(6)
    );
    let csv = Csv::of(dir, &a);
    // Agent 3, down over [0.3, 0.6) and [1.0, 1.4), from its last state.
    let frozen = |t_c: f64, t_r: f64| {
        let at = csv.motion(csv.at(3, t_c)).to_vec();
        for (t, row) in csv.node(3) {
            let tau = csv.tau(row);
            if t >= t_c - 1e-9 && t < t_r - 1e-9 {
                assert_eq!(csv.motion(row), at.as_slice(), "t = {t}");
                assert!(tau.iter().all(|x| x.is_nan()), "t = {t}");
            }
        }
        assert_eq!(csv.motion(csv.at(3, t_r)), at.as_slice());
    };
    frozen(0.3, 0.6);
    frozen(1.0, 1.4);
    let tau = csv.tau(csv.at(3, 0.8));
    assert!(
        tau.iter().all(|x| x.is_finite()),
        "between its crashes: {tau:?}"
    );
    // Agent 5, down over [0.5, 0.9).
    let at = csv.motion(csv.at(5, 0.5)).to_vec();
    assert_eq!(csv.motion(csv.at(5, 0.89)), at.as_slice());
    assert!(csv.tau(csv.at(5, 0.7)).iter().all(|x| x.is_nan()));
    assert!(csv.tau(csv.at(5, 0.9)).iter().all(|x| x.is_finite()));
}

#[test]
fn a_restart_at_the_smallest_gap_and_under_sampled_coupling_is_byte_identical() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Continuous coupling: 17 steps.
    let events = event("0.5", 3, "crash") + &event("0.517", 3, "restart");
    let file = scenario(dir, OBSERVERLESS, "gap", &events);
    let (_, b) = both(dir, &file, "gap");
    assert_restart(&restarts(&b)[0], 3, 500);
    // Sampled coupling, period 10 steps: 650 steps, on an exchange.
    let sampled = read(Path::new(OBSERVERLESS)).replacen(
        "coupling = \"continuous\"",
        "coupling = \"sampled\"\nperiod = 0.01",
        1,
    );
    let events = event("0.5", 3, "crash") + &restart("1.15", 3, "initial");
    let file = scenario_text(dir, &sampled, "sampled", &events);
    let (a, b) = both(dir, &file, "sampled");
    assert_restart(&restarts(&b)[0], 3, 500);
    assert_down(&Csv::of(dir, &a), 0.5, Some(1.15), true, "sampled");
}

#[test]
fn bad_crash_events_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let text = read(Path::new(OBSERVERLESS));
    // Agent 3 run by a plug-in (the command need not run: check refuses
    // the event).
    let agent = Path::new(env!("CARGO_BIN_EXE_attsync")).with_file_name("saturated-agent");
    let plugin = text.replacen(
        "\nid = 3\n",
        &format!("\nid = 3\ncommand = [{:?}]\n", agent.to_str().unwrap()),
        1,
    );
    assert_ne!(plugin, text);
    let sampled = text.replacen(
        "coupling = \"continuous\"",
        "coupling = \"sampled\"\nperiod = 0.01",
        1,
    );
    assert_ne!(sampled, text);
    let cases = [
        (
            "plugin",
            &plugin,
            event("0.5", 3, "crash"),
            "event[0].action: agent 3 is a plug-in",
        ),
        (
            "restart-uncrashed",
            &text,
            event("1.0", 3, "restart"),
            "event[0].action: agent 3 has not crashed by t = 1 s",
        ),
        (
            "restart-other",
            &text,
            event("0.5", 3, "crash") + &event("1.0", 4, "restart"),
            "event[1].action: agent 4 has not crashed by t = 1 s",
        ),
        (
            "crash-twice",
            &text,
            event("0.5", 3, "crash") + &event("0.8", 3, "crash"),
            "event[1].action: agent 3 is down already (event[0])",
        ),
        (
            "restart-too-soon",
            &text,
            event("0.5", 3, "crash") + &event("0.516", 3, "restart"),
            "event[1].action: restarts agent 3 16 steps after its crash: a restart comes at least 17 steps",
        ),
        (
            "sampled-between-exchanges",
            &sampled,
            event("0.5", 3, "crash") + &event("1.205", 3, "restart"),
            "event[1].action: restarts agent 3 at step 1205, between exchanges",
        ),
        (
            "sampled-too-soon",
            &sampled,
            event("0.5", 3, "crash") + &event("1.14", 3, "restart"),
            "event[1].action: restarts agent 3 640 steps after its crash: a restart comes at least 650 steps",
        ),
        (
            "unknown-agent",
            &text,
            event("0.5", 9, "crash"),
            "event[0].agent: agent 9 does not exist",
        ),
        (
            "state-on-crash",
            &text,
            "[[event]]\nt = 0.5\nagent = 3\naction = \"crash\"\nstate = \"initial\"\n".into(),
            "event[0].state: is only for action = \"restart\"",
        ),
    ];
    for (name, base, events, says) in cases {
        let file = scenario_text(dir, base, name, &events);
        let o = attsync(dir, &["check".as_ref(), file.as_os_str()]);
        o.assert_code(2);
        assert!(o.stderr.contains(says), "{name}: {}", o.stderr);
        assert!(
            o.stderr.contains(&format!("{name}.toml")),
            "{name}: {}",
            o.stderr
        );
        // `run` refuses it the same way, before starting anything.
        let out = dir.join(format!("{name}-out"));
        let o = attsync(dir, &run_args(&file, "processes", &out, &[]));
        o.assert_code(2);
        assert!(o.stderr.contains(says), "{name} (run): {}", o.stderr);
    }
    // The same events without the fault are accepted.
    let fine = [
        (
            &text,
            event("0.5", 3, "crash") + &event("0.517", 3, "restart"),
        ),
        (
            &sampled,
            event("0.5", 3, "crash") + &event("1.15", 3, "restart"),
        ),
        (&text, event("0.5", 3, "crash")),
    ];
    for (k, (base, events)) in fine.iter().enumerate() {
        let file = scenario_text(dir, base, &format!("fine-{k}"), events);
        let o = attsync(dir, &["check".as_ref(), file.as_os_str()]);
        o.assert_code(0);
    }
}

#[test]
fn a_crash_cannot_run_in_real_time() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let events = event("0.5", 3, "crash") + &event("1.2", 3, "restart");
    let file = scenario(dir, OBSERVERLESS, "realtime", &events);
    let out = dir.join("out");
    let mut args = run_args(&file, "processes", &out, &["simulation.duration=2"]);
    args.extend(["--realtime".into(), "1".into()]);
    let o = attsync(dir, &args);
    o.assert_code(2);
    assert!(o.stderr.contains("crash"), "{}", o.stderr);
    assert!(o.stderr.contains("--realtime"), "{}", o.stderr);
    assert!(!out.exists(), "a results directory was left");
}
