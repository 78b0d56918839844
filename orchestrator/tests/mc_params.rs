//! `[[monte_carlo.param]]` (issue 35): Monte Carlo over any numeric field.
//!
//! - `trials.csv` gets one column per dispersed field, named by its path,
//!   holding the value the trial's scenario had (read back, so a
//!   dispersion silently not applied would show); the values lie in their
//!   laws' bounds, differ between trials, and a timing field is a whole
//!   number of steps;
//! - trial K alone (`--trial K`) runs with the same values (its
//!   `scenario.toml`);
//! - the initial conditions are drawn from a stream of their own: adding a
//!   parameter leaves `initial.csv` byte-identical, and a parameter whose
//!   law is a single value leaves every trial's numbers as they were;
//! - every bad entry is refused with exit code 2 naming
//!   `monte_carlo.param[k].KEY` (or the field), before anything runs.

mod common;

use common::{Out, attsync, paper, read};
use std::fs;
use std::path::{Path, PathBuf};

/// The observerless paper run, 6 s, with `[monte_carlo]` then `extra`
/// appended, written into `dir`.
fn scenario(dir: &Path, name: &str, extra: &str) -> PathBuf {
    let mut text = read(Path::new(&paper("constant-observerless")));
    text = text.replace("duration = 40.0", "duration = 6.0");
    text += "\n[monte_carlo]\ndisperse = [\"attitude\", \"omega\"]\n";
    text += extra;
    let file = dir.join(format!("{name}.toml"));
    fs::write(&file, text).expect("write");
    file
}

const K_R: &str = "\n[[monte_carlo.param]]\nfield = \"scheme.control.k_r\"\n\
                   distribution = \"uniform\"\nmin = 0.5\nmax = 4.0\n";
const DELAY: &str = "\n[[monte_carlo.param]]\nfield = \"network.delay\"\n\
                     distribution = \"normal\"\nmean = 0.1\nstd = 0.05\nmin = 0.0\n";

/// `attsync mc FILE --trials 8 --out OUT --quiet EXTRA…`.
fn mc(cwd: &Path, file: &Path, out: &str, extra: &[&str]) -> Out {
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "mc".as_ref(),
        file.as_os_str(),
        "--trials".as_ref(),
        "8".as_ref(),
        "--out".as_ref(),
        out.as_ref(),
        "--quiet".as_ref(),
    ];
    args.extend(extra.iter().map(|e| std::ffi::OsStr::new(*e)));
    attsync(cwd, &args)
}

/// `trials.csv` as its header and rows.
fn trials(dir: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = read(&dir.join("trials.csv"));
    let mut lines = text.lines();
    let split = |l: &str| l.split(',').map(str::to_string).collect::<Vec<_>>();
    let header = split(lines.next().expect("a header"));
    (header, lines.map(split).collect())
}

#[test]
fn each_dispersed_field_is_a_column_of_the_values_the_trials_ran_with() {
    let tmp = tempfile::tempdir().unwrap();
    let file = scenario(tmp.path(), "params", &format!("{K_R}{DELAY}"));
    mc(tmp.path(), &file, "out", &[]).assert_code(0);
    let (header, rows) = trials(&tmp.path().join("out"));
    let n = header.len();
    assert_eq!(header[n - 2..], ["scheme.control.k_r", "network.delay"]);
    let k_r: Vec<f64> = rows.iter().map(|r| r[n - 2].parse().unwrap()).collect();
    let delay: Vec<f64> = rows.iter().map(|r| r[n - 1].parse().unwrap()).collect();
    assert!(k_r.iter().all(|k| (0.5..=4.0).contains(k)), "{k_r:?}");
    assert!(delay.iter().all(|d| *d >= 0.0), "{delay:?}");
    // A delay is a whole number of steps (dt = 1 ms).
    assert!(
        delay
            .iter()
            .all(|d| ((d * 1e3).round() - d * 1e3).abs() < 1e-9)
    );
    let distinct = |v: &[f64]| v.windows(2).any(|w| w[0] != w[1]);
    assert!(distinct(&k_r) && distinct(&delay));
    // Trial 3 alone runs with the same values.
    mc(tmp.path(), &file, "alone", &["--trial", "3"]).assert_code(0);
    let used: toml::Value = toml::from_str(&read(&tmp.path().join("alone/scenario.toml"))).unwrap();
    let num = |v: &toml::Value| {
        v.as_float()
            .unwrap_or_else(|| v.as_integer().unwrap() as f64)
    };
    assert_eq!(num(&used["scheme"]["control"]["k_r"]), k_r[3]);
    assert_eq!(num(&used["network"]["delay"]), delay[3]);
}

#[test]
fn parameters_leave_the_initial_conditions_and_a_fixed_value_leaves_the_bits() {
    let tmp = tempfile::tempdir().unwrap();
    let plain = scenario(tmp.path(), "plain", "");
    let with = scenario(tmp.path(), "with", &format!("{K_R}{DELAY}"));
    // k_r = 1.9 is the scenario's own value: the law of a single value.
    let fixed = scenario(
        tmp.path(),
        "fixed",
        "\n[[monte_carlo.param]]\nfield = \"scheme.control.k_r\"\n\
         distribution = \"uniform\"\nmin = 1.9\nmax = 1.9\n",
    );
    for (f, out) in [(&plain, "plain"), (&with, "with"), (&fixed, "fixed")] {
        mc(tmp.path(), f, out, &[]).assert_code(0);
    }
    let initial = |d: &str| read(&tmp.path().join(d).join("initial.csv"));
    assert_eq!(initial("plain"), initial("with"));
    let (_, plain_rows) = trials(&tmp.path().join("plain"));
    let (_, fixed_rows) = trials(&tmp.path().join("fixed"));
    for (p, f) in plain_rows.iter().zip(&fixed_rows) {
        assert_eq!(f[..f.len() - 1], p[..], "the same numbers");
        assert_eq!(f[f.len() - 1], "1.9");
    }
}

#[test]
fn bad_entries_are_refused_naming_the_key() {
    let tmp = tempfile::tempdir().unwrap();
    let entry = |body: &str| format!("\n[[monte_carlo.param]]\n{body}\n");
    let cases = [
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"uniform\"\nmin = 1.0",
            "monte_carlo.param[0].min",
        ),
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"uniform\"\nmin = 2.0\nmax = 1.0",
            "monte_carlo.param[0].max",
        ),
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"log-uniform\"\nmin = 0.0\nmax = 1.0",
            "needs min > 0",
        ),
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"normal\"\nmean = 1.0\nstd = -1.0",
            "monte_carlo.param[0].std",
        ),
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"normal\"\nmean = 1.0\nstd = 0.1\nmin = 2.0",
            "the bounds must hold at least",
        ),
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"uniform\"\nmin = 1.0\nmax = 2.0\nmean = 1.5",
            "monte_carlo.param[0].mean",
        ),
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"triangular\"\nmin = 1.0\nmax = 2.0",
            "triangular",
        ),
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"uniform\"\nmin = 1.0\nmax = 2.0\nspread = 1",
            "spread",
        ),
        (
            "field = \"scheme.control.k_r\"\ndistribution = \"uniform\"\nmin = -1.0\nmax = 2.0",
            "k_r",
        ),
        (
            "field = \"scheme.control.nope\"\ndistribution = \"uniform\"\nmin = 1.0\nmax = 2.0",
            "nope",
        ),
        (
            "field = \"network.delay\"\ndistribution = \"uniform\"\nmin = 0.0\nmax = 0.1\nstep = 0.0",
            "monte_carlo.param[0].step",
        ),
    ];
    for (k, (body, says)) in cases.iter().enumerate() {
        let file = scenario(tmp.path(), &format!("bad-{k}"), &entry(body));
        let out = format!("out-{k}");
        let o = mc(tmp.path(), &file, &out, &[]);
        o.assert_code(2);
        assert!(o.stderr.contains(says), "{body}: {}", o.stderr);
        assert!(!tmp.path().join(&out).exists());
    }
    let twice = scenario(tmp.path(), "twice", &format!("{K_R}{K_R}"));
    let o = mc(tmp.path(), &twice, "twice", &[]);
    o.assert_code(2);
    assert!(
        o.stderr.contains("monte_carlo.param[1].field"),
        "{}",
        o.stderr
    );
}
