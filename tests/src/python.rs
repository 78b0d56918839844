//! Agents written in Python (`examples/python/agent.py`,
//! `tests/independent_agent/agent.py`): their prerequisite and
//! `attsync conform` of one.

use crate::conform::run_conform;
use crate::running::Finished;
use crate::sandbox::Sandbox;
use std::ffi::OsString;
use std::path::Path;
use std::process::Command;

/// Panics, saying how to install it, unless `python3` can import the
/// `iceoryx2` binding (PyPI `iceoryx2`, `examples/python/requirements.txt`).
pub fn require_iceoryx2_module() {
    require_python_modules(
        "iceoryx2",
        "`python3 -m pip install -r examples/python/requirements.txt`",
    );
}

/// Panics, saying to run `install`, unless `python3` can import every
/// module of `modules` (comma-separated, as `import` takes them).
pub fn require_python_modules(modules: &str, install: &str) {
    let ok = Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "python3 cannot import {modules}: run {install}");
}

/// `attsync conform ARGS… -- python3 SCRIPT` in `tmp` ([`run_conform`]),
/// after [`require_iceoryx2_module`].
#[must_use]
pub fn conform_python(tmp: &Sandbox, args: &[OsString], script: &Path) -> Finished {
    require_iceoryx2_module();
    run_conform(tmp, args, &["python3".into(), script.into()], &[])
}
