//! Scenario files edited for a test: an agent given TOML lines of its own
//! (most often a plug-in `command`), written into the test's sandbox.

use crate::results::read;
use crate::sandbox::Sandbox;
use crate::workspace::bin;
use std::path::{Path, PathBuf};

/// `base` with the TOML lines `extra` (each ending in a newline) added to
/// the table of agent `id`, written to `tmp/<name>.toml`; panics if `base`
/// has no such agent.
#[must_use]
pub fn with_agent_lines(tmp: &Sandbox, base: &Path, id: u32, name: &str, extra: &str) -> PathBuf {
    let text = read(base);
    let anchor = format!("[[agent]]\nid = {id}\n");
    assert!(
        text.contains(&anchor),
        "agent {id} not found in {}",
        base.display()
    );
    let file = tmp.join(format!("{name}.toml"));
    std::fs::write(&file, text.replace(&anchor, &format!("{anchor}{extra}")))
        .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    file
}

/// The line that makes an agent the plug-in `sh -c SCRIPT`.
#[must_use]
pub fn sh_plugin(script: &str) -> String {
    format!("command = [\"sh\", \"-c\", {script:?}]\n")
}

/// The lines that make an agent the fixture `broken_agent`
/// (`tests/src/bin/broken_agent.rs`) injecting `fault` (`ATTSYNC_FAULT`).
#[must_use]
pub fn broken_agent(fault: &str) -> String {
    format!(
        "command = [{:?}]\nenv = {{ ATTSYNC_FAULT = {fault:?} }}\n",
        bin("broken_agent").display().to_string()
    )
}
