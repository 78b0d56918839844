//! The scenario reader with `--set`: the input is a scenario file's text;
//! each of its lines `#--set key.path=value` (a TOML comment, so the file
//! still parses as it is) is also given as an override, as `attsync run
//! --set` would. Then `attsync check`'s report of a scenario that loads.
#![no_main]

use attsync::scenario::StiffnessCheck;
use attsync::scenario::{self, report};
// Its allocator: a request over MAX_ALLOCATION is a crash.
use attsync_fuzz as _;
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

/// A scenario file's path in a directory of its own (plug-in programs are
/// looked up relative to it: nothing is there).
fn file() -> &'static PathBuf {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    let dir = DIR.get_or_init(|| tempfile::tempdir().expect("a temp dir"));
    static FILE: OnceLock<PathBuf> = OnceLock::new();
    FILE.get_or_init(|| dir.path().join("scenario.toml"))
}

fuzz_target!(|data: &[u8]| {
    // The reader refuses non-UTF-8 before parsing (scenario::input).
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let overrides: Vec<String> = (text.lines())
        .filter_map(|l| l.strip_prefix("#--set "))
        .map(str::to_owned)
        .collect();
    for check in [StiffnessCheck::Refuse, StiffnessCheck::Warn] {
        match scenario::load_str_with(file(), text, &overrides, check) {
            Ok(loaded) => {
                let _ = report::describe(&loaded);
                let _ = loaded.document;
                return;
            }
            Err(e) => {
                let _ = e.to_string();
            }
        }
    }
});
