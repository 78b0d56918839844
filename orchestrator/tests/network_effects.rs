//! Network impairments (`[network]`, `attitude::link`) and `attsync sweep`,
//! end to end through the built `attsync` binary.
//!
//! Each test runs the binary as a child process in its own temporary
//! directory (also its working directory, so nothing leaks into the crate),
//! with `--engine in-process` unless it says otherwise. What is checked:
//! - an ideal `[network]` section (delay 0, no jitter, no loss) changes
//!   nothing: `errors.csv` and `states.bin` are byte-identical to the
//!   scenario without it; so is a lossless Bernoulli link (`loss = 0.0`,
//!   filtered but transparent), while a one-step delay does change them;
//! - the paper's observerless experiment (40 s) still converges with a
//!   50 ms delay on every link and does not converge with a 1 s delay;
//! - seeded loss (with jitter and delay, Bernoulli and Gilbert–Elliott) is
//!   reproducible: the same `network.seed` gives byte-identical results and
//!   link counters, another seed different ones; the loss rate in
//!   `summary.json` is within 6σ of p;
//! - the process-per-node engine delivers the same impaired values as the
//!   in-process engine (byte-identical results, with per-link overrides);
//! - `attsync sweep`: `sweep.csv` (header, one row per value, rows agreeing
//!   with each run's `summary.json`), convergence at delay 0 and not at 1 s,
//!   `--find-margin` bracketing the margin between the given values,
//!   bisection points that are clean multiples of the quantum, failures
//!   (bad `--param`, bad value, an unbracketed margin) exiting non-zero,
//!   naming the field, and leaving nothing behind.

mod common;

use common::{OBSERVERLESS, Out, PAPER, attsync, entries, run_args, summary};
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// `attsync run SCENARIO --engine ENGINE --out OUT --quiet --set …`.
fn run_with(cwd: &Path, engine: &str, scenario: &Path, out: &Path, sets: &[&str]) -> Out {
    attsync(cwd, &run_args(scenario, engine, out, sets))
}

/// An in-process run that must succeed.
fn run(cwd: &Path, scenario: &Path, out: &Path, sets: &[&str]) {
    run_with(cwd, "in-process", scenario, out, sets).assert_ok();
}

fn bytes(file: &Path) -> Vec<u8> {
    fs::read(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
}

/// Whether `name` is byte-identical in the two results directories.
fn same(a: &Path, b: &Path, name: &str) -> bool {
    bytes(&a.join(name)) == bytes(&b.join(name))
}

#[track_caller]
fn assert_same_results(a: &Path, b: &Path) {
    for name in ["errors.csv", "states.bin"] {
        assert!(
            same(a, b, name),
            "{name} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

/// `scenario`'s text with `extra` appended, written to `dir/name`.
fn variant(dir: &Path, scenario: &str, name: &str, extra: &str) -> PathBuf {
    let text = fs::read_to_string(scenario).expect("scenario");
    assert!(
        !text.contains("[network]"),
        "{scenario} already has a [network] section"
    );
    let file = dir.join(name);
    fs::write(&file, format!("{text}\n{extra}")).expect("write scenario");
    file
}

/// `summary.json`'s links as `(from, to, sent, delivered, lost)`.
fn link_counts(s: &serde_json::Value) -> Vec<(u64, u64, u64, u64, u64)> {
    s["links"]
        .as_array()
        .unwrap_or_else(|| panic!("no links array: {s:#}"))
        .iter()
        .map(|l| {
            let n = |k: &str| l[k].as_u64().unwrap_or_else(|| panic!("{k}: {l:#}"));
            (n("from"), n("to"), n("sent"), n("delivered"), n("lost"))
        })
        .collect()
}

// ---------------------------------------------------------------- ideal

#[test]
fn ideal_network_section_changes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let short = "simulation.duration=1";
    for (scenario, tag) in [(PAPER, "tv"), (OBSERVERLESS, "ol")] {
        let plain = cwd.join(format!("{tag}-plain"));
        run(cwd, Path::new(scenario), &plain, &[short]);
        assert_eq!(summary(&plain)["links"], serde_json::json!([]));

        // An explicit ideal [network] section in the file.
        let file = variant(
            cwd,
            scenario,
            &format!("{tag}-ideal.toml"),
            "[network]\nseed = 17\ndelay = 0.0\njitter = 0.0\n",
        );
        let ideal = cwd.join(format!("{tag}-ideal"));
        run(cwd, &file, &ideal, &[short]);
        assert_same_results(&plain, &ideal);
        let s = summary(&ideal);
        assert_eq!(s["links"], serde_json::json!([]), "no impaired link: {s:#}");
        assert_eq!(s["complete"], true);

        // The same through --set.
        let set = cwd.join(format!("{tag}-set"));
        run(
            cwd,
            Path::new(scenario),
            &set,
            &[short, "network.delay=0", "network.seed=3"],
        );
        assert_same_results(&plain, &set);

        // A lossless Bernoulli link is filtered (it is listed) but delivers
        // every message at once: still the same values, bit for bit.
        let lossless = cwd.join(format!("{tag}-lossless"));
        run(
            cwd,
            Path::new(scenario),
            &lossless,
            &[short, "network.loss=0.0"],
        );
        assert_same_results(&plain, &lossless);
        let links = link_counts(&summary(&lossless));
        assert_eq!(links.len(), 12, "2 leader links + 2 × 5 edges: {links:?}");
        for &(from, to, sent, delivered, lost) in &links {
            assert_eq!(sent, 4 * 1000, "{from} → {to}: every stage of 1000 steps");
            assert_eq!((delivered, lost), (sent, 0), "{from} → {to}");
        }

        // Not vacuous: one step of delay does change the trajectory.
        let delayed = cwd.join(format!("{tag}-delayed"));
        run(
            cwd,
            Path::new(scenario),
            &delayed,
            &[short, "network.delay=0.001"],
        );
        assert!(!same(&plain, &delayed, "errors.csv"));
        assert!(!same(&plain, &delayed, "states.bin"));
    }
}

// ------------------------------------------------------- paper, delayed

#[test]
fn observerless_paper_converges_with_50ms_delay_not_with_1s() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let results: Vec<(f64, serde_json::Value)> = std::thread::scope(|s| {
        let runs: Vec<_> = [0.05, 1.0]
            .into_iter()
            .map(|d| {
                s.spawn(move || {
                    let out = cwd.join(format!("delay-{d}"));
                    run(
                        cwd,
                        Path::new(OBSERVERLESS),
                        &out,
                        &[&format!("network.delay={d}")],
                    );
                    (d, summary(&out))
                })
            })
            .collect();
        runs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (d, s) in &results {
        assert_eq!(s["complete"], true, "{s:#}");
        assert_eq!(s["t_end"].as_f64(), Some(40.0), "the full experiment");
        // Every one of the 12 directed links is delayed by d: the oldest
        // value ever used is d old.
        let links = s["links"].as_array().unwrap();
        assert_eq!(links.len(), 12);
        for l in links {
            assert_eq!(l["lost"].as_u64(), Some(0), "{l:#}");
            let aoi = l["aoi_max"].as_f64().unwrap();
            assert!((aoi - d).abs() < 1e-9, "delay {d}: {l:#}");
        }
    }
    let (small, large) = (&results[0].1, &results[1].1);
    let err = |s: &serde_json::Value| s["max_final_att_err"].as_f64().unwrap();
    assert!(
        err(small) < 1e-3,
        "delay 0.05 s: final max att_err {:e}",
        err(small)
    );
    for a in small["agents"].as_array().unwrap() {
        assert!(a["settle_att_1e-3_s"].is_number(), "delay 0.05 s: {a:#}");
    }
    assert!(
        err(large) > 1e-3,
        "delay 1 s: final max att_err {:e} (converged)",
        err(large)
    );
    for a in large["agents"].as_array().unwrap() {
        assert!(a["settle_att_1e-3_s"].is_null(), "delay 1 s: {a:#}");
    }
}

// ------------------------------------------------------------ seeded loss

#[test]
fn seeded_loss_is_reproducible_end_to_end() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let p = 0.3;
    let bernoulli = format!("network.loss={p}");
    let gilbert =
        "network.loss={ model = \"gilbert-elliott\", p_gb = 0.05, p_bg = 0.3, loss_bad = 0.9 }";
    for (scenario, loss, tag) in [
        (PAPER, bernoulli.as_str(), "tv-b"),
        (OBSERVERLESS, gilbert, "ol-ge"),
    ] {
        let go = |seed: u64, name: &str| {
            let out = cwd.join(format!("{tag}-{name}"));
            let seed = format!("network.seed={seed}");
            run(
                cwd,
                Path::new(scenario),
                &out,
                &[
                    "simulation.duration=1",
                    loss,
                    "network.delay=0.002",
                    "network.jitter=0.003",
                    &seed,
                ],
            );
            out
        };
        let (a, b, c) = (go(5, "a"), go(5, "b"), go(6, "c"));
        assert_same_results(&a, &b);
        let (sa, sb, sc) = (summary(&a), summary(&b), summary(&c));
        assert_eq!(link_counts(&sa), link_counts(&sb), "{tag}: same seed");
        assert_eq!(sa["links"], sb["links"], "{tag}: same ages of information");
        assert!(!same(&a, &c, "errors.csv"), "{tag}: another seed");
        assert!(!same(&a, &c, "states.bin"), "{tag}: another seed");
        assert_ne!(link_counts(&sa), link_counts(&sc), "{tag}: another seed");
        let links = link_counts(&sa);
        assert_eq!(links.len(), 12);
        // Every link draws from its own stream.
        let lost: BTreeSet<u64> = links.iter().map(|l| l.4).collect();
        assert!(lost.len() > 6, "{tag}: per-link streams alike? {links:?}");
        for &(from, to, sent, delivered, lost) in &links {
            assert_eq!(sent, 4000, "{from} → {to}");
            assert!(lost > 0 && delivered > 0, "{from} → {to}: {lost} lost");
            // At most delay + jitter = 5 steps' messages still on their way.
            assert!(delivered + lost <= sent && delivered + lost >= sent - 20);
        }
        if tag == "tv-b" {
            let sent: u64 = links.iter().map(|l| l.2).sum();
            let lost: u64 = links.iter().map(|l| l.4).sum();
            let (n, k) = (sent as f64, lost as f64);
            let sd = (n * p * (1.0 - p)).sqrt();
            assert!(
                (k - n * p).abs() < 6.0 * sd,
                "{k} of {n} lost, expected {} ± {}",
                n * p,
                6.0 * sd
            );
        }
    }
}

// ------------------------------------------------------ processes engine

/// The node binaries beside the `attsync` executable under test.
fn node_binaries_present() -> bool {
    let dir = Path::new(env!("CARGO_BIN_EXE_attsync"))
        .parent()
        .expect("a directory");
    ["attsync-agent", "attsync-leader"]
        .iter()
        .all(|b| dir.join(b).is_file())
}

#[test]
fn process_engine_delivers_the_same_impaired_values() {
    assert!(
        node_binaries_present(),
        "attsync-agent and attsync-leader are not beside {}: build them first \
         (cargo build --release --workspace, with the same target directory)",
        env!("CARGO_BIN_EXE_attsync")
    );
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let file = variant(
        cwd,
        PAPER,
        "impaired.toml",
        "[network]\nseed = 11\ndelay = 0.002\njitter = 0.002\nloss = 0.2\n\
         [[network.link]]\nfrom = 0\nto = 1\ndelay = 0.005\nperiod = 0.004\n\
         [[network.link]]\nfrom = 3\nto = 1\n\
         loss = { model = \"gilbert-elliott\", p_gb = 0.1, p_bg = 0.3 }\n",
    );
    let (p, i) = (cwd.join("processes"), cwd.join("in-process"));
    let sets = ["simulation.duration=0.5"];
    run_with(cwd, "processes", &file, &p, &sets).assert_ok();
    run_with(cwd, "in-process", &file, &i, &sets).assert_ok();
    assert_same_results(&p, &i);
    let (sp, si) = (summary(&p), summary(&i));
    assert_eq!(sp["engine"], "processes");
    assert_eq!(sp["complete"], true, "{sp:#}");
    assert_eq!(link_counts(&sp), link_counts(&si));
    // The per-link override of 0 → 1 is in force: only stage 0 of every
    // 4th step is carried (500 steps → 125 messages).
    let l01 = link_counts(&si)
        .into_iter()
        .find(|l| (l.0, l.1) == (0, 1))
        .expect("link 0 → 1");
    assert_eq!(l01.2, 125, "{l01:?}");
}

// ------------------------------------------------------------------ sweep

/// `attsync sweep OBSERVERLESS --param network.delay --values VALUES
/// --jobs 2 --engine in-process --out OUT --set simulation.duration=15 EXTRA…`.
fn sweep(cwd: &Path, param: &str, values: &str, out: &str, extra: &[&str]) -> Out {
    let mut args = vec![
        "sweep",
        OBSERVERLESS,
        "--param",
        param,
        "--values",
        values,
        "--jobs",
        "2",
        "--engine",
        "in-process",
        "--out",
        out,
        "--set",
        "simulation.duration=15",
    ];
    args.extend_from_slice(extra);
    attsync(cwd, &args)
}

/// `sweep.csv` as its header and rows of fields.
fn read_sweep(dir: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = fs::read_to_string(dir.join("sweep.csv")).expect("sweep.csv");
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("a header")
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

/// A row's fields by column name.
fn field<'a>(header: &[String], row: &'a [String], name: &str) -> &'a str {
    let k = header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    &row[k]
}

/// A TOML number (`--set` writes `15` as an integer).
fn num(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// The `margin: PARAM = LO converges, HI does not` line of the table.
fn margin_line(stdout: &str) -> (String, String) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("margin: network.delay = "))
        .unwrap_or_else(|| panic!("no margin line:\n{stdout}"));
    let rest = line.trim_start_matches("margin: network.delay = ");
    let (lo, rest) = rest.split_once(" converges, ").expect("margin format");
    let hi = rest.strip_suffix(" does not").expect("margin format");
    (lo.to_string(), hi.to_string())
}

/// The margin of `sweep.json`: (converges_up_to, fails_from, linear margin).
fn margin_json(dir: &Path) -> (f64, f64, f64, serde_json::Value) {
    let info: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(dir.join("sweep.json")).unwrap()).unwrap();
    let m = &info["margin"];
    let lo = m["converges_up_to"].as_f64().expect("converges_up_to");
    let hi = m["fails_from"].as_f64().expect("fails_from");
    assert_eq!(m["linear"]["kind"], "crossing", "{info:#}");
    let linear = m["linear"]["delay"].as_f64().expect("a linear margin");
    (lo, hi, linear, info)
}

/// Whether a row's error decays (the bisection's criterion).
fn decays(header: &[String], r: &[String]) -> bool {
    match field(header, r, "verdict") {
        "converged" | "converging" => true,
        "persistent" | "diverging" => false,
        "undecided" => false,
        v => panic!("verdict {v:?}"),
    }
}

/// The stability boundary of the paper's observerless experiment: the
/// bisection, on each run's verdict with runs extended until it is final,
/// brackets the linearisation's exact margin (0.3892 s, `attsync margin`);
/// every row agrees with its run's summary.json and scenario.toml.
#[test]
fn sweep_network_delay_with_margin() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let out = sweep(
        cwd,
        "network.delay",
        "0,0.05,1.0",
        "sw",
        // Near the margin the rates are ~0.003/s: long runs resolve them.
        &["--find-margin", "--bisect", "6", "--max-duration", "1280"],
    );
    out.assert_ok();
    let dir = cwd.join("sw");
    assert_eq!(
        entries(cwd),
        BTreeSet::from(["sw".to_string()]),
        "staging left behind"
    );
    for f in ["sweep.csv", "sweep.json", "sweep.svg"] {
        assert!(dir.join(f).is_file(), "{f} missing: {:?}", entries(&dir));
    }
    let (header, rows) = read_sweep(&dir);
    assert_eq!(
        header[..4],
        ["value", "verdict", "decay_rate_per_s", "linear_rate_per_s"].map(String::from),
        "{header:?}"
    );
    // One row per listed value, in order, then the 6 bisection points.
    assert_eq!(rows.len(), 3 + 6, "{rows:?}");
    let values: Vec<&str> = rows.iter().map(|r| field(&header, r, "value")).collect();
    assert_eq!(values[..3], ["0", "0.05", "1.0"]);
    assert_eq!(
        field(&header, &rows[0], "verdict"),
        "converged",
        "{:?}",
        rows[0]
    );
    assert_eq!(
        field(&header, &rows[1], "verdict"),
        "converged",
        "{:?}",
        rows[1]
    );
    assert!(!decays(&header, &rows[2]), "delay 1.0: {:?}", rows[2]);

    // Every row agrees with its run's summary.json and scenario.toml.
    for r in &rows {
        assert_eq!(field(&header, r, "complete"), "true", "{r:?}");
        let run_dir = dir.join(field(&header, r, "run"));
        let s = summary(&run_dir);
        let err: f64 = field(&header, r, "final_max_att_err").parse().unwrap();
        assert_eq!(Some(err), s["max_final_att_err"].as_f64(), "{r:?}");
        assert_eq!(field(&header, r, "verdict"), s["verdict"]["kind"], "{r:?}");
        let rate = field(&header, r, "decay_rate_per_s").parse::<f64>().ok();
        assert_eq!(rate, s["verdict"]["decay_rate"].as_f64(), "{r:?}");
        assert_eq!(
            field(&header, r, "converged") == "true",
            s["verdict"]["kind"] == "converged"
        );
        let settle: Vec<Option<f64>> = s["agents"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a["settle_att_1e-3_s"].as_f64())
            .collect();
        let latest = settle.iter().try_fold(0.0_f64, |m, t| t.map(|t| m.max(t)));
        let t = field(&header, r, "settle_att_1e-3_s");
        match latest {
            Some(x) => assert_eq!(t.parse::<f64>().ok(), Some(x), "{r:?}"),
            None => assert_eq!(t, "", "{r:?}: an agent never settles"),
        }
        // The run really had that delay, and ran to the horizon it says
        // (extended from 15 s until its verdict was final).
        let eff: toml::Table = fs::read_to_string(run_dir.join("scenario.toml"))
            .unwrap()
            .parse()
            .unwrap();
        let v: f64 = field(&header, r, "value").parse().unwrap();
        assert_eq!(num(&eff["network"]["delay"]), Some(v), "{r:?}");
        let duration: f64 = field(&header, r, "duration_s").parse().unwrap();
        assert_eq!(num(&eff["simulation"]["duration"]), Some(duration), "{r:?}");
        assert_eq!(s["duration"].as_f64(), Some(duration), "{r:?}");
        assert!(duration >= 15.0, "{r:?}");
        assert_eq!(s["until"]["rule"], "settled", "{r:?}");
    }

    // The margin: lo decays, hi does not, both in the rows; the
    // linearisation's margin lies in the bracket (widened by one step).
    let (lo, hi) = margin_line(&out.stdout);
    let (l, h): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
    assert!(0.05 <= l && l < h && h <= 1.0, "margin {lo} .. {hi}");
    let row = |v: &str| {
        rows.iter()
            .find(|r| field(&header, r, "value") == v)
            .unwrap_or_else(|| panic!("no row for {v}: {rows:?}"))
    };
    assert!(decays(&header, row(&lo)), "{lo} is said to decay");
    assert!(!decays(&header, row(&hi)), "{hi} is said not to");
    let (jl, jh, linear, info) = margin_json(&dir);
    assert_eq!(info["param"], "network.delay");
    assert_eq!((jl, jh), (l, h));
    assert!((linear - 0.3892).abs() < 1e-3, "linear margin {linear}");
    assert!(
        l - 0.001 <= linear && linear <= h + 0.001,
        "{linear} outside [{l}, {h}]"
    );
    assert!(info["margin"]["warning"].is_null(), "{info:#}");
    assert!(
        out.stdout.contains("linear margin: 0.389"),
        "{}",
        out.stdout
    );
    // Bisection points are rounded to the step (the default quantum for a delay).
    for r in &rows[3..] {
        let v: f64 = field(&header, r, "value").parse().unwrap();
        assert!(((v / 0.001).round() * 0.001 - v).abs() < 1e-12, "{r:?}");
    }
}

/// The bracket `--find-margin` finds does not depend on the horizon the
/// runs start from (15 s or 40 s): the runs are extended until their
/// verdicts are final.
#[test]
fn the_sweep_margin_does_not_depend_on_the_starting_duration() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let margin = |out: &str, duration: &str| {
        let set = format!("simulation.duration={duration}");
        sweep(
            cwd,
            "network.delay",
            "0.3,0.5",
            out,
            &[
                "--find-margin",
                "--bisect",
                "4",
                "--set",
                &set,
                "--max-duration",
                "1280",
            ],
        )
        .assert_ok();
        let (lo, hi, _, _) = margin_json(&cwd.join(out));
        (lo, hi)
    };
    let short = margin("short", "15");
    let long = margin("long", "40");
    assert_eq!(short, long, "the bracket moved with the starting duration");
    assert!(short.0 < 0.3892 && 0.3892 < short.1 + 0.001, "{short:?}");
}

/// The bisection point between 0 and 0.742 is 371 steps; it must be
/// reported as `0.371` (as given on a command line), not as `371 × 0.001`
/// with binary noise, in `sweep.csv`, the run directory's name, the margin
/// line and `sweep.json`.
#[test]
fn sweep_bisection_points_are_printed_without_binary_noise() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let out = sweep(
        cwd,
        "network.delay",
        "0,0.742",
        "sw",
        &["--find-margin", "--bisect", "1"],
    );
    out.assert_ok();
    let dir = cwd.join("sw");
    let (header, rows) = read_sweep(&dir);
    assert_eq!(rows.len(), 3, "{rows:?}");
    assert!(decays(&header, &rows[0]), "{rows:?}");
    assert!(!decays(&header, &rows[1]), "{rows:?}");
    let point = &rows[2];
    let v: f64 = field(&header, point, "value").parse().unwrap();
    assert!((v - 0.371).abs() < 1e-12, "{point:?}");
    assert_eq!(field(&header, point, "value"), "0.371", "{point:?}");
    assert_eq!(field(&header, point, "run"), "runs/002-0.371", "{point:?}");
    // 0.371 s is below the margin (0.389 s): its error decays.
    assert!(decays(&header, point), "{point:?}");
    let (lo, _) = margin_line(&out.stdout);
    assert_eq!(lo, "0.371", "{}", out.stdout);
    let (l, _, _, _) = margin_json(&dir);
    assert_eq!(l.to_string(), "0.371");
}

#[test]
fn sweep_failures_name_the_field_and_leave_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();

    // A field that does not exist.
    let out = sweep(cwd, "network.delai", "0,0.05", "sw", &[]);
    out.assert_failed();
    assert!(
        out.stderr.contains("network.delai") && out.stderr.contains("unknown field"),
        "{}",
        out.stderr
    );
    assert!(
        out.stderr.contains("constant-observerless.toml"),
        "{}",
        out.stderr
    );

    // A value the field does not accept (checked before anything runs,
    // even when it is not the first).
    let out = sweep(cwd, "network.delay", "0,0.05,0.0005", "sw", &[]);
    out.assert_failed();
    assert!(
        out.stderr.contains("network.delay") && out.stderr.contains("multiple"),
        "{}",
        out.stderr
    );
    let out = sweep(cwd, "network.loss", "0.1,1.5", "sw", &[]);
    out.assert_failed();
    assert!(
        out.stderr.contains("network.loss") && out.stderr.contains("probability"),
        "{}",
        out.stderr
    );
    assert!(entries(cwd).is_empty(), "{:?}", entries(cwd));

    // --find-margin without a bracket (the first value's error does not decay).
    let out = sweep(
        cwd,
        "network.delay",
        "1.0,0",
        "sw",
        &["--find-margin", "--set", "simulation.duration=1"],
    );
    out.assert_failed();
    assert!(
        out.stderr.contains("--find-margin") && out.stderr.contains("network.delay"),
        "{}",
        out.stderr
    );
    assert!(entries(cwd).is_empty(), "{:?}", entries(cwd));
}

/// README.md, "Exit codes": 2 for an invalid scenario or `--set`. A swept
/// `--param` value is applied exactly like a `--set` (and reported with the
/// same `FILE: FIELD: REASON`), so an invalid one must exit 2 as an invalid
/// `--set` of the same sweep does.
#[test]
fn sweep_invalid_param_exits_2_like_an_invalid_set() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let by_set = sweep(
        cwd,
        "network.delay",
        "0",
        "sw",
        &["--set", "network.delai=0"],
    );
    assert_eq!(by_set.code, Some(2), "{}", by_set.stderr);
    assert!(by_set.stderr.contains("network.delai"), "{}", by_set.stderr);
    for (param, values) in [("network.delai", "0"), ("network.delay", "0,0.0005")] {
        let out = sweep(cwd, param, values, "sw", &[]);
        assert!(out.stderr.contains(param), "{}", out.stderr);
        assert_eq!(
            out.code,
            Some(2),
            "--param {param} --values {values}: {}",
            out.stderr
        );
    }
    assert!(entries(cwd).is_empty(), "{:?}", entries(cwd));
}
