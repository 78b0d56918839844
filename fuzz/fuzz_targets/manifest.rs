//! `manifest.json` as `verify` reads it, and the run's other JSON,
//! `summary.json`, as `view` reads it: the input is written as each in a
//! run directory holding the fixture's files; the manifest is read and
//! checked (`Manifest::read`), then the files it lists are checked against
//! the directory (`verify::files::check`); `view::regenerate` reads the
//! summary.
#![no_main]

use attsync::results::layout::RunLayout;
use attsync::results::manifest::Manifest;
use attsync::verify::files;
use attsync::view;
use attsync_fuzz::{RunDir, fixture, run_dir};
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

static RUN: OnceLock<RunDir> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let run = run_dir(&RUN);
    let layout = RunLayout::new(run.path());
    std::fs::write(layout.manifest(), data).expect("manifest.json written");
    match Manifest::read(&layout) {
        Ok(m) => {
            let _ = files::check(run.path(), &m.files);
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
    std::fs::write(layout.summary(), data).expect("summary.json written");
    if let Err(e) = view::regenerate(run.path()) {
        let _ = e.to_string();
    }
    std::fs::write(layout.summary(), fixture("summary.json")).expect("summary.json restored");
});
