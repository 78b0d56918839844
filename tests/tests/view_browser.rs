//! Issue 14 item 2: `view.html` works in a real browser, offline. A paper
//! run (scheme 1, in-process) writes its page; `tests/browser/cdp_check.py`
//! opens it in headless Chromium (Debian's `/usr/bin/chromium`, which
//! `tools/test-deps.sh` installs) through the DevTools protocol and checks
//! that no request leaves the page, that no console error or exception
//! appears, and that the 3D view at t = 0 and at t = 20 s differs where the
//! bodies are (and is not blank). The checker also proves it would see a
//! request: the page is made to fetch a URL, and its Content-Security-Policy
//! must refuse it with an error the checker sees.

use attsync_tests::{Sandbox, paper, reference_run};
use std::path::{Path, PathBuf};
use std::process::Command;

const CHROMIUM: &str = "/usr/bin/chromium";

fn checker() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("browser/cdp_check.py")
}

#[test]
fn the_view_opens_offline_in_headless_chromium_and_moves() {
    assert!(
        Path::new(CHROMIUM).is_file(),
        "{CHROMIUM} is missing: the browser test needs Debian's chromium; run tools/test-deps.sh as root"
    );
    let tmp = Sandbox::new("view_browser");
    let out = tmp.join("tv");
    let sets = ["simulation.duration=21"];
    reference_run(tmp.path(), &paper("timevarying"), &out, &sets);
    let html = out.join("view.html");
    assert!(html.is_file(), "the run wrote no view.html");
    let check = Command::new("python3")
        .arg(checker())
        .arg(&html)
        .args(["--times", "0", "20"])
        .output()
        .expect("python3 runs");
    let stdout = String::from_utf8_lossy(&check.stdout);
    let stderr = String::from_utf8_lossy(&check.stderr);
    assert!(
        check.status.success(),
        "the browser check failed ({}):\n{stderr}\nreport: {stdout}",
        check.status
    );
    let report: serde_json::Value = serde_json::from_str(stdout.trim()).expect("a JSON report");
    assert_eq!(report["problems"], serde_json::json!([]), "{report:#}");
    assert!(report["changed_pixels"].as_u64() > Some(0), "{report:#}");
}
