//! Issue 14 items 1 and 5, without a browser (`tests/tests/view_browser.rs`
//! opens the page in Chromium): every run writes `view.html` unless
//! `--no-view`, one self-contained file (no URL but its own data, a
//! Content-Security-Policy that forbids any request), under 5 MB for the
//! paper's 40 s run; `attsync view DIR` writes the same page from the
//! results; `errors.svg` has the observer's panels exactly where the scheme
//! has an observer.

mod common;

use common::{OBSERVERLESS, PAPER, attsync, run_args};
use std::fs;
use std::path::Path;

const OBSERVER_CAPTION: &str = "attitude error of the observer";

/// `attsync run SCENARIO --engine in-process --out OUT --quiet EXTRA…`,
/// which must succeed.
fn run(cwd: &Path, scenario: &str, out: &str, extra: &[&str]) {
    let mut args = run_args(scenario, "in-process", out, &[]);
    args.extend(extra.iter().map(Into::into));
    attsync(cwd, &args).assert_ok();
}

/// The page's JSON data.
fn data(html: &str) -> serde_json::Value {
    let open = r#"<script type="application/json" id="data">"#;
    let start = html.find(open).expect("a data block") + open.len();
    let len = html[start..].find("</script>").expect("closed");
    serde_json::from_str(&html[start..start + len]).expect("valid JSON")
}

#[test]
fn the_paper_run_writes_a_small_self_contained_view_that_attsync_view_remakes() {
    let tmp = tempfile::tempdir().unwrap();
    run(tmp.path(), PAPER, "tv", &[]);
    let file = tmp.path().join("tv/view.html");
    let html = fs::read_to_string(&file).expect("view.html");
    assert!(html.len() < 5_000_000, "view.html is {} bytes", html.len());
    assert!(
        html.contains("default-src 'none'"),
        "no Content-Security-Policy"
    );
    for outside in [
        "http:",
        "https:",
        "//cdn",
        " src=",
        "<link rel=\"stylesheet\"",
    ] {
        assert!(
            !html.contains(outside),
            "the page refers to something outside: {outside}"
        );
    }
    let d = data(&html);
    assert_eq!(d["scheme"], "observer-time-varying");
    assert_eq!(d["observer"], true);
    assert_eq!(
        d["bodies"].as_array().map(Vec::len),
        Some(8),
        "leader + 7 agents"
    );
    let t = d["frames"]["t"].as_array().expect("times");
    assert_eq!(t.first().and_then(|v| v.as_f64()), Some(0.0));
    assert_eq!(t.last().and_then(|v| v.as_f64()), Some(40.0));
    assert!(t.len() <= 25 * 40 + 1, "{} frames for 40 s", t.len());
    assert_eq!(d["frames"]["q_hat"].as_array().map(Vec::len), Some(7));
    let leader_links: Vec<u64> = (d["bodies"].as_array().unwrap().iter())
        .filter(|b| b["leader_link"] == true)
        .map(|b| b["id"].as_u64().unwrap())
        .collect();
    assert_eq!(leader_links, [1, 2]);

    let svg = fs::read_to_string(tmp.path().join("tv/errors.svg")).unwrap();
    assert!(
        svg.contains(OBSERVER_CAPTION),
        "errors.svg lacks the observer's errors"
    );

    fs::remove_file(&file).unwrap();
    let again = attsync(tmp.path(), &["view", "tv"]);
    again.assert_ok();
    assert!(again.stdout.contains("view.html"));
    assert_eq!(
        fs::read_to_string(&file).unwrap(),
        html,
        "attsync view wrote another page"
    );
}

#[test]
fn an_observerless_run_has_no_ghosts_and_no_view_with_no_view() {
    let tmp = tempfile::tempdir().unwrap();
    run(
        tmp.path(),
        OBSERVERLESS,
        "ol",
        &["--set", "simulation.duration=1"],
    );
    let d = data(&fs::read_to_string(tmp.path().join("ol/view.html")).unwrap());
    assert_eq!(d["observer"], false);
    assert_eq!(d["frames"]["q_hat"], serde_json::json!([]));
    let svg = fs::read_to_string(tmp.path().join("ol/errors.svg")).unwrap();
    assert!(
        !svg.contains(OBSERVER_CAPTION),
        "an observer panel without an observer"
    );

    run(
        tmp.path(),
        OBSERVERLESS,
        "none",
        &["--set", "simulation.duration=0.1", "--no-view"],
    );
    assert!(tmp.path().join("none/summary.json").is_file());
    assert!(
        !tmp.path().join("none/view.html").exists(),
        "--no-view wrote view.html"
    );
}

#[test]
fn attsync_view_of_a_directory_that_is_no_run_names_the_missing_file() {
    let tmp = tempfile::tempdir().unwrap();
    fs::create_dir(tmp.path().join("empty")).unwrap();
    let out = attsync(tmp.path(), &["view", "empty"]);
    assert_eq!(out.code, Some(1));
    let stderr = &out.stderr;
    assert!(stderr.contains("empty/scenario.toml"), "{stderr}");
    assert!(!tmp.path().join("empty/view.html").exists());
}
