//! `attsync._attsync`: the native module of the `attsync` Python package
//! (`python/attsync/`, built by maturin). It calls the orchestrator's
//! library directly: a scenario is loaded and validated exactly as
//! `attsync check`/`--set` do, and a run is `attsync::run::run`, the CLI's
//! own, so its results directory is byte-identical to the CLI's. The
//! Python layer reads the results into pandas and numpy.
//!
//! Errors cross as exceptions, never as panics: [`ScenarioError`] carries
//! the file and every `(field, reason)`; a run that fails is a
//! [`RunError`]; Ctrl-C stops a run cleanly (its results kept) and raises
//! `KeyboardInterrupt`.

use attsync::interrupt::Interrupt;
use attsync::processes::ProcessOptions;
use attsync::run::{Engine, Judging, RunOptions};
use attsync::scenario::{self, Loaded};
use attsync::until::{DEFAULT_TOLERANCE, Until};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod law;
use law::PyLaw;
use std::time::Duration;

create_exception!(
    _attsync,
    ScenarioError,
    PyValueError,
    "A scenario that cannot be read or is not valid: `args` are (message, file, [(field, reason), …])."
);
create_exception!(
    _attsync,
    LawError,
    PyRuntimeError,
    "A control law given with `law=` raised, or returned a torque that is not 3 finite numbers: `args` are (message,)."
);
create_exception!(
    _attsync,
    RunError,
    PyRuntimeError,
    "A run that could not start or did not complete: `args` are (message, exit code)."
);

/// The Python exception of a scenario error.
fn scenario_error(e: &scenario::ScenarioError) -> PyErr {
    use scenario::ScenarioError as E;
    let (file, issues): (&Path, Vec<(String, String)>) = match e {
        E::Io { file, error } => (file, vec![(String::new(), error.to_string())]),
        E::Parse { file, issues } | E::Override { file, issues } | E::Invalid { file, issues } => (
            file,
            (issues.iter())
                .map(|i| (i.field.clone(), i.reason.clone()))
                .collect(),
        ),
    };
    ScenarioError::new_err((e.to_string(), file.display().to_string(), issues))
}

/// `path` with the overrides `sets` (`FIELD=VALUE`, as `--set`), loaded and
/// validated.
fn load(path: &str, sets: &[String]) -> PyResult<Loaded> {
    scenario::load(Path::new(path), sets).map_err(|e| scenario_error(&e))
}

/// Validates `path` with `sets`; returns the scenario's name and its
/// warnings.
#[pyfunction]
fn check(path: &str, sets: Vec<String>) -> PyResult<(String, Vec<String>)> {
    let loaded = load(path, &sets)?;
    let warnings = loaded
        .resolved
        .warnings
        .iter()
        .map(|w| w.to_string())
        .collect();
    Ok((loaded.name(), warnings))
}

/// The effective TOML of `path` with `sets` (what a run writes as `scenario.toml`).
#[pyfunction]
fn effective_toml(path: &str, sets: Vec<String>) -> PyResult<String> {
    let loaded = load(path, &sets)?;
    toml::to_string(&loaded.document).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Runs `path` with `sets` on `engine` (`"in-process"` or `"processes"`)
/// with `threads` into `out`, as `attsync run --out OUT` does; returns
/// `summary.json`'s text. The GIL is released while it runs; Ctrl-C stops
/// it as SIGINT stops the CLI (the results so far are kept) and raises
/// `KeyboardInterrupt`.
#[pyfunction]
#[pyo3(signature = (path, sets, out, engine="in-process", threads=None, law=None))]
#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    path: &str,
    sets: Vec<String>,
    out: PathBuf,
    engine: &str,
    threads: Option<usize>,
    law: Option<Py<PyAny>>,
) -> PyResult<String> {
    let law = law.map(|f| Arc::new(PyLaw::new(f)));
    let loaded = load(path, &sets)?;
    let engine = engine_of(engine)?;
    let opts = RunOptions {
        engine,
        out,
        processes: ProcessOptions::default(),
        progress: false,
        threads: threads.unwrap_or_else(attsync::run::default_threads),
        view: true,
        hosts: None,
        judging: Judging {
            tolerance: DEFAULT_TOLERANCE,
            until: Until::Horizon,
        },
        law: law.clone().map(|l| l as attitude::law::SharedLaw),
    };
    let interrupt = Interrupt::new();
    let ran = watched(py, &interrupt, || {
        attsync::run::run(&loaded, &opts, &interrupt)
    })?;
    if let Some(why) = law.and_then(|l| l.failure()) {
        return Err(LawError::new_err(why));
    }
    let summary = ran.map_err(|e| RunError::new_err((e.to_string(), e.exit_code())))?;
    if interrupt.is_set() {
        return Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(
            "the run was interrupted; its results so far are kept",
        ));
    }
    serde_json::to_string(&summary).map_err(|e| RunError::new_err((e.to_string(), 1u8)))
}

/// The engine named `name`.
fn engine_of(name: &str) -> PyResult<Engine> {
    match name {
        "in-process" => Ok(Engine::InProcess),
        "processes" => Ok(Engine::Processes),
        other => Err(PyValueError::new_err(format!(
            "engine must be \"in-process\" or \"processes\", not {other:?}"
        ))),
    }
}

/// `attsync sweep PATH --param P --values V… [--param P2 --values V2…]
/// [--find-margin] --out OUT` with `sets`; values are TOML literals.
#[pyfunction]
#[pyo3(signature = (path, sets, param, values, out, grid=None, engine="in-process", jobs=None, find_margin=false))]
#[allow(clippy::too_many_arguments)]
fn sweep(
    py: Python<'_>,
    path: &str,
    sets: Vec<String>,
    param: String,
    values: Vec<String>,
    out: PathBuf,
    grid: Option<(String, Vec<String>)>,
    engine: &str,
    jobs: Option<usize>,
    find_margin: bool,
) -> PyResult<()> {
    use attsync::sweep::{self as sw, Axis, Bisection, SweepOptions};
    let base = load(path, &sets)?;
    let net = &base.resolved.network;
    let engine = engine_of(engine)?;
    let nodes = net.agents.len() + 1;
    let (jobs, threads) = match jobs {
        Some(j) => sw::jobs_and_threads(Some(j), None),
        None => (sw::default_jobs(engine, nodes, sw::cores()), 1),
    };
    let until = if find_margin {
        Until::Settled {
            max_duration: attsync::until::DEFAULT_MAX_FACTOR * net.steps as f64 * net.dt,
        }
    } else {
        Until::Horizon
    };
    let o = SweepOptions {
        scenario: PathBuf::from(path),
        param,
        values,
        grid: grid.map(|(param, values)| Axis { param, values }),
        jobs,
        set: sets,
        run: RunOptions {
            engine,
            out,
            processes: ProcessOptions::default(),
            progress: false,
            threads,
            view: false,
            hosts: None,
            judging: Judging {
                tolerance: DEFAULT_TOLERANCE,
                until,
            },
            law: None,
        },
        find_margin: find_margin.then_some(Bisection {
            iterations: 8,
            quantum: None,
        }),
        stiffness: scenario::StiffnessCheck::Refuse,
    };
    let interrupt = Interrupt::new();
    let swept = watched(py, &interrupt, || sw::sweep(&o, &interrupt))?;
    match swept {
        Ok(_) => Ok(()),
        Err(sw::SweepError::Scenario(e)) => Err(scenario_error(&e)),
        Err(e) => Err(RunError::new_err((e.to_string(), e.exit_code()))),
    }
}

/// `attsync mc PATH --trials N --seed S --out OUT [--shard K/N]` with `sets`.
#[pyfunction]
#[pyo3(signature = (path, sets, trials, seed, out, engine="in-process", jobs=None, law=None, shard=None))]
#[allow(clippy::too_many_arguments)]
fn mc(
    py: Python<'_>,
    path: &str,
    sets: Vec<String>,
    trials: u64,
    seed: u64,
    out: PathBuf,
    engine: &str,
    jobs: Option<usize>,
    law: Option<Py<PyAny>>,
    shard: Option<(u64, u64)>,
) -> PyResult<()> {
    let law = law.map(|f| Arc::new(PyLaw::new(f)));
    use attsync::mc::{self as m, McOptions};
    let shard = shard.map(|(index, count)| m::Shard { index, count });
    let base = load(path, &sets)?;
    let engine = engine_of(engine)?;
    let nodes = base.resolved.network.agents.len() + 1;
    let o = McOptions {
        scenario: PathBuf::from(path),
        set: sets,
        trials,
        seed,
        jobs: jobs.unwrap_or_else(|| {
            attsync::sweep::default_jobs(engine, nodes, attsync::sweep::cores())
        }),
        engine,
        processes: ProcessOptions::default(),
        judging: Judging {
            tolerance: DEFAULT_TOLERANCE,
            until: Until::Horizon,
        },
        out,
        progress: false,
        stiffness: scenario::StiffnessCheck::Refuse,
        law: law.clone().map(|l| l as attitude::law::SharedLaw),
        shard,
    };
    let interrupt = Interrupt::new();
    let done = watched(py, &interrupt, || m::monte_carlo(&o, &interrupt))?;
    if let Some(why) = law.and_then(|l| l.failure()) {
        return Err(LawError::new_err(why));
    }
    match done {
        Ok(_) => Ok(()),
        Err(m::McError::Scenario(e)) => Err(scenario_error(&e)),
        Err(e) => Err(RunError::new_err((e.to_string(), e.exit_code()))),
    }
}

/// `attsync mc merge DIRS… --out OUT`.
#[pyfunction]
fn mc_merge(dirs: Vec<PathBuf>, out: PathBuf) -> PyResult<()> {
    attsync::mc::merge(&dirs, &out)
        .map(drop)
        .map_err(|e| RunError::new_err((e.to_string(), e.exit_code())))
}

/// `attsync margin PATH --json` with `sets`: the delay margin of the
/// linearisation, as JSON text.
#[pyfunction]
fn margin(path: &str, sets: Vec<String>) -> PyResult<String> {
    let loaded = load(path, &sets)?;
    let report = attsync::margin::margin(&loaded).map_err(|e| {
        let field = e.field.unwrap_or("").to_string();
        ScenarioError::new_err((
            e.to_string(),
            e.file.display().to_string(),
            vec![(field, e.reason.to_string())],
        ))
    })?;
    serde_json::to_string(&report.json()).map_err(|e| RunError::new_err((e.to_string(), 1u8)))
}

/// Runs `work` on a thread of its own without the GIL while this thread
/// looks for Python's signals every 50 ms: a pending one (Ctrl-C) raises
/// `interrupt`, so that `work` stops as the CLI would on SIGINT.
fn watched<T: Send + pyo3::marker::Ungil>(
    py: Python<'_>,
    interrupt: &Interrupt,
    work: impl FnOnce() -> T + pyo3::marker::Ungil + Send,
) -> PyResult<T> {
    std::thread::scope(|s| {
        // The worker keeps a Python thread state for the whole run (attached
        // once, then detached): a law's every call then only takes the GIL,
        // instead of creating and destroying a thread state (~15 µs a call).
        let handle = s.spawn(|| Python::attach(|py| py.detach(work)));
        while !handle.is_finished() {
            py.detach(|| std::thread::sleep(Duration::from_millis(50)));
            if py.check_signals().is_err() {
                interrupt.trigger(2);
            }
        }
        handle
            .join()
            .map_err(|_| PyRuntimeError::new_err("the run panicked (a bug in attsync)"))
    })
}

/// The module.
#[pymodule]
fn _attsync(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(effective_toml, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(mc, m)?)?;
    m.add_function(wrap_pyfunction!(mc_merge, m)?)?;
    m.add_function(wrap_pyfunction!(margin, m)?)?;
    m.add("ScenarioError", m.py().get_type::<ScenarioError>())?;
    m.add("RunError", m.py().get_type::<RunError>())?;
    m.add("LawError", m.py().get_type::<LawError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // Each agent's look in every figure (orchestrator/src/results/palette.rs).
    m.add(
        "PALETTE_COLOURS",
        attsync::results::palette::COLOURS.to_vec(),
    )?;
    m.add("PALETTE_DASHES", attsync::results::palette::DASHES.to_vec())?;
    Ok(())
}
