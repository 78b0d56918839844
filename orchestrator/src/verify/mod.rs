//! `attsync verify DIR`: a replay that is checked, not just run.
//!
//! 1. Read `DIR/manifest.json` ([`Manifest`]); refuse a real-time run (not
//!    deterministic) and an interrupted or failed one (no end to reproduce;
//!    a diverged run is reproduced, divergence included).
//! 2. Check that `DIR/scenario.toml` is the scenario that ran
//!    (`scenario_sha256`), else refuse, and check every listed file's size
//!    and SHA-256 ([`files`]): a changed file is named.
//! 3. Re-run `DIR/scenario.toml` into a temporary directory with the
//!    recorded engine, wait strategy, placement, stage timeout and threads
//!    (`--engine`, `--wait` override them: a processes run may be verified
//!    in-process and the reverse, the engines being bit-identical).
//! 4. Compare ([`compare`]) the recorded `states.bin` with the re-run's,
//!    sample by sample (the first differing sample: time, node, field, both
//!    values), and `errors.csv` row by row.
//!
//! The verdict is `bit-identical` only if every file is as recorded and
//! both comparisons find nothing ([`Report::is_identical`]). Exit codes
//! (`attsync verify`): 0 bit-identical; 1 different, or the re-run failed;
//! 2 a missing or bad manifest, a scenario that is not the one that ran, a
//! run that cannot be verified, an invalid option ([`VerifyError::exit_code`]);
//! 128 + N interrupted by signal N.
//!
//! # Layout
//! - this file: [`verify`] and its phases, [`VerifyOptions`];
//! - [`files`]: the listed files against their recorded SHA-256;
//! - [`compare`]: the first difference of `states.bin` and of `errors.csv`;
//! - `report`: [`Report`], what is printed;
//! - `error`: [`VerifyError`].

pub mod compare;
mod error;
pub mod files;
mod report;

pub use error::VerifyError;
pub use report::Report;

use crate::interrupt::Interrupt;
use crate::processes::ProcessOptions;
use crate::processes::placement::Placement;
use crate::results::digest::sha256_hex;
use crate::results::fmt_time;
use crate::results::layout::RunLayout;
use crate::results::manifest::Manifest;
use crate::run::{self, Engine, RunOptions};
use crate::scenario::StiffnessCheck;
use crate::scenario::{self, Loaded};
use msgs::config::WaitStrategy;
use std::path::Path;

/// How to re-run.
#[derive(Debug, Clone, Default)]
pub struct VerifyOptions {
    /// The engine (`None`: the recorded one).
    pub engine: Option<Engine>,
    /// The processes engine's wait strategy (`None`: the recorded one, else adaptive).
    pub wait: Option<WaitStrategy>,
    /// Draw the re-run's progress bar on stderr.
    pub progress: bool,
}

/// Refuses, saying what to verify instead, a directory without
/// `manifest.json` that holds a sweep's or a Monte Carlo's results.
fn not_a_sweep_or_mc(dir: &Path, layout: &RunLayout) -> Result<(), VerifyError> {
    use crate::results::layout::{MC_JSON, RUNS, SWEEP_CSV};
    if layout.manifest().exists() {
        return Ok(());
    }
    let not = |what, instead: String| {
        Err(VerifyError::NotARun {
            dir: dir.to_owned(),
            what,
            instead,
        })
    };
    if dir.join(SWEEP_CSV).is_file() {
        let first = std::fs::read_dir(dir.join(RUNS))
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .min();
        let example = first.map_or_else(
            || format!("{}/{RUNS}/<run>", dir.display()),
            |p| p.display().to_string(),
        );
        return not(
            "a sweep's directory",
            format!("verify each of its runs, e.g. `attsync verify {example}`"),
        );
    }
    if dir.join(MC_JSON).is_file() {
        return not(
            "a Monte Carlo's directory",
            "its trials keep no results of their own: run one with `attsync mc SCENARIO --seed S \
             --trial K --out DIR` (mc.json has the seed) and verify that DIR"
                .into(),
        );
    }
    Ok(())
}

/// Verifies the run in `dir`: its files against `manifest.json`, and a
/// re-run of its scenario against its `states.bin` and `errors.csv`.
///
/// # Errors
/// See [`VerifyError`]: the run could not be verified at all (a
/// difference is not an error: see [`Report::is_identical`]).
pub fn verify(
    dir: &Path,
    opts: &VerifyOptions,
    interrupt: &Interrupt,
) -> Result<Report, VerifyError> {
    let layout = RunLayout::new(dir);
    not_a_sweep_or_mc(dir, &layout)?;
    let manifest = Manifest::read(&layout)?;
    refuse(dir, &manifest)?;
    let text = scenario_text(&layout, &manifest)?;
    let changed = files::check(dir, &manifest.files);
    let loaded = load(&layout, &manifest, &text)?;
    interrupt.arm();
    let tmp = tempfile::Builder::new()
        .prefix("attsync-verify-")
        .tempdir()
        .map_err(VerifyError::TempDir)?;
    let rerun = RunLayout::new(tmp.path().join("rerun"));
    let run_opts = options(&layout, &manifest, opts, rerun.root())?;
    tracing::debug!(dir = %dir.display(), engine = run_opts.engine.name(), "verify: re-run");
    let summary = run::run(&loaded, &run_opts, interrupt)?;
    if interrupt.is_set() {
        let signal = interrupt.signal().unwrap_or(signal_hook::consts::SIGINT);
        return Err(VerifyError::Interrupted(signal));
    }
    if let (false, None) = (summary.complete, &summary.diverged) {
        let reason = (summary.incomplete_reason).map_or_else(String::new, |f| f.to_string());
        return Err(VerifyError::Rerun(reason));
    }
    Ok(Report {
        dir: dir.to_owned(),
        recorded_by: recorded_by(&manifest),
        listed: manifest.files.len(),
        changed,
        engine: run_opts.engine,
        steps: (summary.steps, fmt_time(summary.steps, summary.dt)),
        states: compare::states(&layout.states(), &rerun.states())?,
        errors: compare::errors_csv(&layout.errors_csv(), &rerun.errors_csv())?,
    })
}

/// Refuses a run that cannot be reproduced: real time, or incomplete but not diverged.
fn refuse(dir: &Path, m: &Manifest) -> Result<(), VerifyError> {
    if let Some(factor) = m.realtime {
        let dir = dir.to_owned();
        return Err(VerifyError::Realtime { dir, factor });
    }
    if !m.complete && !m.diverged {
        return Err(VerifyError::Incomplete {
            dir: dir.to_owned(),
            reason: (m.incomplete_reason.clone()).unwrap_or_else(|| "no reason recorded".into()),
        });
    }
    Ok(())
}

/// The text of the run's `scenario.toml`, if it is the one that ran.
fn scenario_text(layout: &RunLayout, m: &Manifest) -> Result<String, VerifyError> {
    let unreadable = |source| VerifyError::ScenarioFile {
        path: layout.scenario(),
        source,
    };
    let bytes = std::fs::read(layout.scenario()).map_err(unreadable)?;
    let found = sha256_hex(&bytes);
    if found != m.scenario_sha256 {
        return Err(VerifyError::ScenarioHash {
            manifest: layout.manifest(),
            scenario: layout.scenario(),
            recorded: m.scenario_sha256.clone(),
            found,
        });
    }
    String::from_utf8(bytes).map_err(|e| unreadable(std::io::Error::other(e)))
}

/// The effective scenario, loaded as it ran: under its recorded name (a
/// scenario without `name` is named after its original file), plug-in
/// programs found beside the original file, and the stiffness check only
/// warning (the run passed whichever check it had).
fn load(layout: &RunLayout, m: &Manifest, text: &str) -> Result<Loaded, VerifyError> {
    let file = if has_plugins(text) {
        m.scenario_file.clone()
    } else {
        layout.scenario()
    };
    let mut loaded = scenario::load_str_with(&file, text, &[], StiffnessCheck::Warn)?;
    loaded.scenario.name = Some(m.scenario.clone());
    Ok(loaded)
}

/// Whether some `[[agent]]` of `text` has a `command` (a plug-in).
fn has_plugins(text: &str) -> bool {
    let Ok(doc) = toml::from_str::<toml::Table>(text) else {
        return false;
    };
    let agents = doc.get("agent").and_then(toml::Value::as_array);
    agents.is_some_and(|a| a.iter().any(|x| x.get("command").is_some()))
}

/// The re-run's options: the recorded ones, `--engine` and `--wait` first.
fn options(
    layout: &RunLayout,
    m: &Manifest,
    opts: &VerifyOptions,
    out: &Path,
) -> Result<RunOptions, VerifyError> {
    let engine = match opts.engine {
        Some(e) => e,
        None => setting(layout, "engine", &m.engine)?,
    };
    let placement = match &m.placement {
        Some(p) => setting(layout, "placement", p)?,
        None => Placement::Auto,
    };
    let processes = ProcessOptions {
        wait: opts.wait.or(m.wait).unwrap_or(WaitStrategy::Adaptive),
        stage_timeout: m.stage_timeout,
        placement,
        ..ProcessOptions::default()
    };
    Ok(RunOptions {
        engine,
        out: out.to_owned(),
        processes,
        progress: opts.progress,
        threads: m.threads.unwrap_or_else(run::default_threads),
        // The re-run is compared by states.bin and errors.csv only.
        view: false,
        hosts: None,
        // A run `--until settled` extended recorded its final horizon in
        // its scenario.toml: the re-run goes exactly that far.
        judging: run::Judging::default(),
        law: None,
    })
}

/// A recorded setting `field` = `value` as a value of `T`.
fn setting<T: clap::ValueEnum>(
    layout: &RunLayout,
    field: &'static str,
    value: &str,
) -> Result<T, VerifyError> {
    T::from_str(value, false).map_err(|_| VerifyError::Setting {
        manifest: layout.manifest(),
        field,
        value: value.into(),
        expected: (T::value_variants().iter())
            .filter_map(|v| Some(v.to_possible_value()?.get_name().to_owned()))
            .collect::<Vec<_>>()
            .join(", "),
    })
}

/// "attsync 0.1.0 (git abc…, dirty), the processes engine, started …".
fn recorded_by(m: &Manifest) -> String {
    let dirty = match m.git_dirty {
        Some(true) => ", dirty",
        Some(false) => "",
        None => ", dirty: unknown",
    };
    format!(
        "attsync {} (git {}{dirty}), {} engine, started {} on {} {} ({})",
        m.attsync_version,
        m.git_commit,
        m.engine,
        m.started_at,
        m.platform.os,
        m.platform.arch,
        m.platform.cpu_model
    )
}
