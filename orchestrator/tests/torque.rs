//! The applied torque over time (issue 35, item 3): `states.bin` version 2
//! records every agent's torque `τᵢ` at stage 0 of each sampled step.
//!
//! - both engines write byte-identical `states.bin` with torques;
//! - with `[actuator] max_torque` every recorded torque is within the limit
//!   (by norm, per axis) and some record reaches it;
//! - the last record's torques are NaN (no torque follows the last step),
//!   every other is finite;
//! - the torque recorded at step 0 is the observerless law evaluated by
//!   hand from the initial states, bit for bit;
//! - a version-1 file (no torques) is still read, its torques NaN, and
//!   `verify` finds no difference in the values it holds;
//! - `attsync export --csv` has `tau1..tau3`, which read back equal;
//! - `[output] torque_plot = true` adds the torque panel to `errors.svg`,
//!   and without it the plot is the plot of a run without the key.

mod common;

use attitude::control::tau_districontrol;
use attitude::network::Exchanged;
use attitude::observer::LeaderInput;
use attsync::results::plot;
use attsync::results::states::{self, Record};
use common::{OBSERVERLESS, PAPER, attsync, read, run_args};
use nalgebra::Vector3;
use std::fs;
use std::path::{Path, PathBuf};

/// Runs `scenario` with `sets` on `engine` into `dir/out`.
fn run(dir: &Path, scenario: &Path, engine: &str, out: &str, sets: &[&str]) -> PathBuf {
    let out = dir.join(out);
    attsync(dir, &run_args(scenario, engine, &out, sets)).assert_ok();
    out
}

/// `base` with `extra` appended, written into `dir/name.toml`.
fn scenario(dir: &Path, base: &str, name: &str, extra: &str) -> PathBuf {
    let file = dir.join(format!("{name}.toml"));
    fs::write(&file, read(Path::new(base)) + "\n" + extra).expect("write");
    file
}

/// Every record of `out/states.bin`.
fn records(out: &Path) -> Vec<Record> {
    let (header, records) = states::read(&out.join("states.bin")).expect("states.bin reads");
    assert_eq!(header.version, states::VERSION);
    records
}

/// The bits of every torque of `records`.
fn torque_bits(records: &[Record]) -> Vec<u64> {
    let taus = records
        .iter()
        .flat_map(|r| r.agents.iter().flat_map(|a| a.tau));
    taus.map(f64::to_bits).collect()
}

#[test]
fn both_engines_record_the_same_torques_bit_for_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let limited = scenario(
        tmp.path(),
        PAPER,
        "limited",
        "[actuator]\nmax_torque = 0.5\n",
    );
    for (name, file) in [("paper", Path::new(PAPER)), ("limited", &limited)] {
        let sets = ["simulation.duration=0.5"];
        let a = run(tmp.path(), file, "in-process", &format!("{name}-a"), &sets);
        let b = run(tmp.path(), file, "processes", &format!("{name}-b"), &sets);
        let bytes = |d: &Path| fs::read(d.join("states.bin")).unwrap();
        assert_eq!(bytes(&a), bytes(&b), "{name}: states.bin differs");
        let recs = records(&a);
        assert!(
            recs[0].agents.iter().all(|x| x.torque().norm() > 0.0),
            "{name}: torques recorded"
        );
    }
}

#[test]
fn the_last_record_has_no_torque_and_every_other_has_one() {
    let tmp = tempfile::tempdir().unwrap();
    let sets = ["simulation.duration=0.1"];
    let out = run(tmp.path(), Path::new(PAPER), "in-process", "run", &sets);
    let recs = records(&out);
    assert_eq!(recs.len(), 11);
    let (last, others) = recs.split_last().unwrap();
    assert_eq!(last.step, 100);
    assert!(last.agents.iter().all(|a| a.tau.iter().all(|x| x.is_nan())));
    for r in others {
        let finite = r.agents.iter().all(|a| a.tau.iter().all(|x| x.is_finite()));
        assert!(finite, "step {}: {:?}", r.step, r.agents[0].tau);
    }
}

#[test]
fn recorded_torques_keep_to_the_actuator_limit_and_reach_it() {
    let tmp = tempfile::tempdir().unwrap();
    let sets = ["simulation.duration=1"];
    let tight = 1.0 + 4.0 * f64::EPSILON;
    let norm = scenario(tmp.path(), PAPER, "norm", "[actuator]\nmax_torque = 0.5\n");
    let recs = records(&run(tmp.path(), &norm, "in-process", "norm", &sets));
    let norms: Vec<f64> = (recs.iter().flat_map(|r| &r.agents))
        .map(|a| a.torque().norm())
        .filter(|n| !n.is_nan())
        .collect();
    assert!(norms.iter().all(|&n| n <= 0.5 * tight), "{norms:?}");
    assert!(
        norms.iter().any(|&n| n >= 0.5 * (1.0 - 1e-12)),
        "never saturated"
    );
    let bounds = [0.2, 0.3, 0.25];
    let axes = scenario(
        tmp.path(),
        PAPER,
        "axes",
        "[actuator]\nmax_torque = [0.2, 0.3, 0.25]\n",
    );
    let recs = records(&run(tmp.path(), &axes, "in-process", "axes", &sets));
    let taus: Vec<[f64; 3]> = (recs.iter().flat_map(|r| &r.agents))
        .map(|a| a.tau)
        .filter(|t| !t[0].is_nan())
        .collect();
    for (k, bound) in bounds.into_iter().enumerate() {
        assert!(taus.iter().all(|t| t[k].abs() <= bound), "axis {k}");
        assert!(
            taus.iter().any(|t| t[k].abs() == bound),
            "axis {k} never saturated"
        );
    }
}

#[test]
fn the_torque_at_step_0_is_the_observerless_law_of_the_initial_states() {
    let tmp = tempfile::tempdir().unwrap();
    let sets = ["simulation.duration=0.05"];
    let out = run(
        tmp.path(),
        Path::new(OBSERVERLESS),
        "in-process",
        "run",
        &sets,
    );
    let recorded = &records(&out)[0];
    assert_eq!(recorded.step, 0);
    let loaded = attsync::scenario::load(Path::new(OBSERVERLESS), &[]).expect("valid");
    let net = &loaded.resolved.network;
    let published = |id: u32| {
        let a = net
            .agents
            .iter()
            .find(|a| a.model.id == id)
            .expect("a neighbour");
        Exchanged {
            r: a.initial.r,
            w: a.initial.w,
            s: Vector3::zeros(),
        }
    };
    let leader = net.leader.exchanged();
    for (agent, rec) in net.agents.iter().zip(&recorded.agents) {
        let m = &agent.model;
        let attitude::network::Scheme::Observerless { control } = &m.scheme else {
            panic!("the observerless scheme");
        };
        let gains: Vec<_> = m.neighbours.iter().map(|n| n.a).collect();
        let nbrs: Vec<_> = m.neighbours.iter().map(|n| published(n.id)).collect();
        let from_leader = (m.leader_gain.as_ref()).map(|a| LeaderInput { a, x: &leader });
        let (r, w) = (&agent.initial.r, &agent.initial.w);
        let tau = tau_districontrol(control, r, w, &gains, &nbrs, from_leader);
        let bits = |t: [f64; 3]| t.map(f64::to_bits);
        assert_eq!(bits(rec.tau), bits(tau.into()), "agent {}", m.id);
    }
}

/// `bytes` of a version-2 `states.bin` in layout version 1: version 1, and
/// every agent without its last 3 words (`tau`).
fn as_version_1(bytes: &[u8]) -> Vec<u8> {
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    // Header: magic 8, version 4, scenario (u64 length + bytes), dt 8,
    // sample_every 8, agent_ids (u64 length + 4 each), has_observer 1.
    let ids_at = 20 + u64_at(12) as usize + 16;
    let n = u64_at(ids_at) as usize;
    let header = ids_at + 8 + 4 * n + 1;
    let mut out = bytes[..header].to_vec();
    out[8..12].copy_from_slice(&1u32.to_le_bytes());
    // Record: step 8, leader 15 words, agents (u64 length + 30 words each).
    let (head, agent) = (8 + 15 * 8 + 8, 30 * 8);
    for rec in bytes[header..].chunks(head + n * agent) {
        out.extend_from_slice(&rec[..head]);
        for a in rec[head..].chunks(agent) {
            out.extend_from_slice(&a[..agent - 3 * 8]);
        }
    }
    out
}

#[test]
fn a_version_1_states_file_is_still_read_with_nan_torques() {
    let tmp = tempfile::tempdir().unwrap();
    let sets = ["simulation.duration=0.05"];
    let out = run(tmp.path(), Path::new(PAPER), "in-process", "run", &sets);
    let v2 = out.join("states.bin");
    let v1 = tmp.path().join("v1.bin");
    fs::write(&v1, as_version_1(&fs::read(&v2).unwrap())).unwrap();
    let (h1, old) = states::read(&v1).expect("version 1 reads");
    let (h2, new) = states::read(&v2).expect("version 2 reads");
    assert_eq!((h1.version, h2.version), (1, 2));
    assert_eq!(old.len(), new.len());
    for (a, b) in old.iter().zip(&new) {
        assert_eq!(a.step, b.step);
        assert_eq!(a.leader, b.leader);
        for (x, y) in a.agents.iter().zip(&b.agents) {
            assert!(x.tau.iter().all(|t| t.is_nan()));
            assert_eq!((x.r, x.w, x.r_hat), (y.r, y.w, y.r_hat));
            assert_eq!((x.w_hat, x.s_hat), (y.w_hat, y.s_hat));
        }
    }
    let d = attsync::verify::compare::states(&v1, &v2).expect("compared");
    assert_eq!(d, None, "equal in every value version 1 holds");
    let csv = attsync(tmp.path(), &["export", v1.to_str().unwrap(), "--csv"]);
    csv.assert_ok();
    assert!(csv.stdout.lines().nth(1).unwrap().ends_with(",,,"));
    assert!(csv.stdout.lines().nth(2).unwrap().ends_with(",NaN,NaN,NaN"));
}

#[test]
fn export_csv_has_the_torque_columns_and_they_read_back_equal() {
    let tmp = tempfile::tempdir().unwrap();
    let sets = ["simulation.duration=0.05"];
    let out = run(tmp.path(), Path::new(PAPER), "in-process", "run", &sets);
    let file = out.join("states.bin");
    let csv = attsync(tmp.path(), &["export", file.to_str().unwrap(), "--csv"]);
    csv.assert_ok();
    let mut lines = csv.stdout.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[header.len() - 3..], ["tau1", "tau2", "tau3"]);
    let recs = records(&out);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let agents_per_record = recs[0].agents.len() + 1;
    let mut parsed = Vec::new();
    for (rec, chunk) in recs.iter().zip(rows.chunks(agents_per_record)) {
        assert_eq!(
            chunk[0][header.len() - 3..],
            ["", "", ""],
            "the leader has none"
        );
        for row in &chunk[1..] {
            let tau = &row[header.len() - 3..];
            parsed.extend(tau.iter().map(|x| x.parse::<f64>().unwrap().to_bits()));
        }
        assert_eq!(chunk.len(), agents_per_record, "step {}", rec.step);
    }
    assert_eq!(parsed, torque_bits(&recs));
}

#[test]
fn the_torque_panel_is_drawn_on_request_only() {
    let tmp = tempfile::tempdir().unwrap();
    let sets = ["simulation.duration=0.2"];
    let file = Path::new(PAPER);
    let plain = run(tmp.path(), file, "in-process", "plain", &sets);
    let off = ["simulation.duration=0.2", "output.torque_plot=false"];
    let off = run(tmp.path(), file, "in-process", "off", &off);
    let on = ["simulation.duration=0.2", "output.torque_plot=true"];
    let on = run(tmp.path(), file, "in-process", "on", &on);
    let svg = |d: &Path| read(&d.join("errors.svg"));
    assert!(!svg(&plain).contains(plot::TORQUE.0));
    // The same drawing; only the title, which lists every --set, differs.
    let untitled = svg(&off).replace(", output.torque_plot=false", "");
    assert_eq!(svg(&plain), untitled, "no request, no change");
    assert!(svg(&on).contains(plot::TORQUE.0), "the panel's title");
    assert!(svg(&on).len() > svg(&plain).len());
    let bytes = |d: &Path| fs::read(d.join("states.bin")).unwrap();
    assert_eq!(bytes(&plain), bytes(&on), "the plot only");
}
