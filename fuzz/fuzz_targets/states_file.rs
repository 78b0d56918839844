//! `states.bin` as `export` (CSV and MCAP), `view` and `verify` read it:
//! the input is written as a run directory's `states.bin` (beside the
//! fixture's `scenario.toml` and `summary.json`), then read by
//! `states::read`, `states::export_csv`, `export::write_mcap`,
//! `view::regenerate` and `verify::compare::states` (both ways round,
//! against the fixture's own `states.bin`).
#![no_main]

use attsync::results::states;
use attsync::verify::compare;
use attsync::{export, view};
use attsync_fuzz::{RunDir, run_dir};
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

static RUN: OnceLock<RunDir> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let run = run_dir(&RUN);
    let file = run.path().join("states.bin");
    std::fs::write(&file, data).expect("states.bin written");
    let _ = states::read(&file);
    let _ = states::export_csv(&file, &mut std::io::sink());
    if let Err(e) = export::write_mcap(&file, &run.path().join("out.mcap")) {
        let _ = e.to_string();
    }
    if let Err(e) = view::regenerate(run.path()) {
        let _ = e.to_string();
    }
    for (a, b) in [(&run.reference, &file), (&file, &run.reference)] {
        if let Err(e) = compare::states(a, b) {
            let _ = e.to_string();
        }
    }
});
