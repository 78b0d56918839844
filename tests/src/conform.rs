//! `attsync conform` of a candidate in a test's sandbox ([`run_conform`]),
//! and the line of one rule in its report ([`rule_line`]).

use crate::command::Attsync;
use crate::running::Finished;
use crate::sandbox::Sandbox;
use std::ffi::OsString;

/// `attsync conform --log TMP/candidate.log ARGS… -- CANDIDATE…` in `tmp`,
/// with the environment variables `env`, run to its end.
#[must_use]
pub fn run_conform(
    tmp: &Sandbox,
    args: &[OsString],
    candidate: &[OsString],
    env: &[(&str, &str)],
) -> Finished {
    let mut a = Attsync::new(tmp.path())
        .args(["conform", "--log"])
        .args([tmp.join("candidate.log")])
        .args(args);
    for (k, v) in env {
        a = a.env(k, v);
    }
    a.args(["--"]).args(candidate).output()
}

/// The report line of `rule` in `r`'s stdout, with its reason line(s): up
/// to the next line that starts with a verdict (`PASS`, `FAIL`, `SKIP`,
/// `INFO`).
#[must_use]
pub fn rule_line<'a>(r: &'a Finished, rule: &str) -> &'a str {
    let start = r
        .stdout
        .find(&format!("  {rule} "))
        .unwrap_or_else(|| panic!("no rule {rule}:\n{}", r.describe()));
    let start = r.stdout[..start].rfind('\n').map_or(0, |i| i + 1);
    let rest = &r.stdout[start + 6..];
    let end = ["\nPASS", "\nFAIL", "\nSKIP", "\nINFO"]
        .iter()
        .filter_map(|t| rest.find(t))
        .min()
        .map_or(r.stdout.len(), |e| start + 6 + e);
    &r.stdout[start..end]
}
