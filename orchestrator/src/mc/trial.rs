//! One trial: its draws applied to the scenario (as `--set` overrides,
//! resolved like any run), the network run in memory (in-process, on one
//! thread) or as processes, and its [`Trace`] classified.

use super::dispersion::Dispersion;
use super::draws::Draws;
use super::outcome::{End, Trace, TrialResult, classify};
use super::seed::{trial_rng, trial_seed};
use crate::interrupt::Interrupt;
use crate::processes::{self, ProcessError, ProcessOptions};
use crate::run::Judging;
use crate::scenario::StiffnessCheck;
use crate::scenario::{self, Loaded, ScenarioError};
use crate::until;
use attitude::engine::{InProcess, Snapshot};
use std::path::{Path, PathBuf};

/// The scenario every trial starts from: its text (read once), the
/// user's overrides, and the resolved dispersion.
#[derive(Debug, Clone)]
pub struct Base {
    /// The scenario file (messages; plug-ins run in its directory).
    pub file: PathBuf,
    /// Its text.
    pub text: String,
    /// `--set` overrides, applied before each trial's.
    pub set: Vec<String>,
    /// `--no-stiffness-check`.
    pub check: StiffnessCheck,
    /// What each trial draws.
    pub dispersion: Dispersion,
    /// The master seed.
    pub seed: u64,
    /// The base scenario (with `set`), loaded.
    pub loaded: Loaded,
}

/// One trial, ready to run.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// Trial index.
    pub trial: u64,
    /// Its seed.
    pub seed: u64,
    /// Its draws.
    pub draws: Draws,
    /// The trial's overrides only (after the user's).
    pub overrides: Vec<String>,
    /// The `[[monte_carlo.param]]` fields' values in its scenario.
    pub params: Vec<f64>,
    /// The scenario with every override, resolved.
    pub loaded: Loaded,
}

impl Base {
    /// Trial `k`: its seed, draws, overrides and scenario.
    ///
    /// # Errors
    /// The scenario with the draws is invalid (it cannot be, unless the
    /// scenario was already).
    pub fn prepare(&self, k: u64) -> Result<Prepared, ScenarioError> {
        let seed = trial_seed(self.seed, k);
        let draws = super::draws::draw(&self.dispersion, &mut trial_rng(seed));
        let mut overrides = super::draws::overrides(&self.dispersion, &draws);
        let params = &self.dispersion.params;
        let dt = self.loaded.resolved.network.dt;
        let drawn = super::params::quantised(params, &super::params::draw(params, seed), dt);
        overrides.extend(super::params::overrides(params, &drawn));
        let all: Vec<String> = self.set.iter().chain(&overrides).cloned().collect();
        let loaded = scenario::load_str_with(&self.file, &self.text, &all, self.check)?;
        Ok(Prepared {
            trial: k,
            seed,
            draws,
            overrides,
            params: super::params::used(&loaded, params),
            loaded,
        })
    }

    /// Checks that each `[[monte_carlo.param]]` field takes the ends of
    /// its law (its bounds, or its mean) in a valid scenario.
    ///
    /// # Errors
    /// The first scenario that is not valid, naming the field.
    pub fn check_params(&self) -> Result<(), ScenarioError> {
        for p in &self.dispersion.params {
            for end in p.law.ends() {
                let one = std::slice::from_ref(p);
                let end = super::params::quantised(one, &[end], self.loaded.resolved.network.dt);
                let with = super::params::overrides(one, &end);
                let all: Vec<String> = self.set.iter().chain(&with).cloned().collect();
                scenario::load_str_with(&self.file, &self.text, &all, self.check)?;
            }
        }
        Ok(())
    }
}

impl Prepared {
    /// This trial's result, ended as `end` with `trace` ([`classify`]),
    /// with the values of its dispersed fields.
    #[must_use]
    pub fn classify(&self, end: End, trace: &Trace, judging: &Judging) -> TrialResult {
        let mut r = classify(self.trial, self.seed, end, trace, judging);
        r.params.clone_from(&self.params);
        r
    }
}

/// How a trial's run ended, or that an interrupt stopped it.
pub enum Ran {
    /// It ran to an end (complete, diverged or failed).
    Done(TrialResult),
    /// The interrupt stopped it: no result.
    Interrupted,
}

fn has_observer(p: &Prepared) -> bool {
    let net = &p.loaded.resolved.network;
    net.agents
        .first()
        .is_some_and(|a| a.model.scheme.has_observer())
}

/// Runs trial `p` in-process on the calling thread (with `law` in place of
/// the scheme's, if given), keeping only its trace; with `--until settled`
/// its horizon is extended until the verdict is final ([`crate::until`]).
#[must_use]
pub fn run_in_process(
    p: &Prepared,
    (judging, law): (&Judging, Option<&attitude::law::SharedLaw>),
    interrupt: &Interrupt,
) -> Ran {
    let net = &p.loaded.resolved.network;
    let mut trace = Trace::new(net, has_observer(p));
    let mut engine = InProcess::new(net);
    if let Some(law) = law {
        engine = engine.with_law(law.clone());
    }
    let max = judging.max_steps(net.steps, net.dt);
    let mut stopped = false;
    let diverged = loop {
        let on_sample = |snap: &Snapshot<'_>, _: &[()]| {
            stopped = interrupt.is_set();
            if !stopped {
                trace.record(snap);
            }
            !stopped
        };
        let diverged = engine.run_until(|_, _, _| (), on_sample, || interrupt.is_set());
        let ended = stopped || diverged.is_some() || engine.step_index() < engine.horizon();
        if ended || !trace.goes_on(judging) || engine.horizon() >= max {
            break diverged;
        }
        engine.extend_to(until::next_horizon(engine.horizon(), max, net.sample_every));
    };
    if stopped || (diverged.is_none() && engine.step_index() < engine.horizon()) {
        return Ran::Interrupted;
    }
    let end = match diverged {
        Some(d) => End::Diverged(
            d.step as f64 * net.dt,
            d.message(net, p.loaded.resolved.stiffness.as_ref()),
        ),
        None => End::Complete,
    };
    Ran::Done(p.classify(end, &trace, judging))
}

/// Runs trial `p` as processes (its own iceoryx2 namespace; node logs in
/// `logs`), keeping only its trace; with `--until settled` to the horizon
/// the in-process engine finds ([`until::settled_horizon`]), or, with
/// plug-ins, again from t = 0 with a longer horizon until the verdict is final.
///
/// # Errors
/// The process engine could not start.
pub fn run_processes(
    p: &Prepared,
    opts: &ProcessOptions,
    logs: &Path,
    judging: &Judging,
    interrupt: &Interrupt,
) -> Result<Ran, ProcessError> {
    let mut net = p.loaded.resolved.network.clone();
    let max = judging.max_steps(net.steps, net.dt);
    let mut trace = Trace::new(&net, has_observer(p));
    let mut opts = opts.clone();
    opts.plugins = p.loaded.resolved.plugins.clone();
    // Without plug-ins the in-process engine finds the final horizon
    // (bit-identical lockstep): the processes run once, to it.
    let probe = matches!(judging.until, until::Until::Settled { .. }) && opts.plugins.is_empty();
    if probe && let Some((horizon, _)) = until::settled_horizon(&net, judging, interrupt) {
        net.steps = horizon;
    }
    loop {
        trace.clear();
        let outcome = processes::run(&net, &opts, logs, interrupt.flag(), |snap| {
            trace.record(snap);
            true
        })?;
        if interrupt.is_set() {
            return Ok(Ran::Interrupted);
        }
        let stiffness = p.loaded.resolved.stiffness.as_ref();
        let end = match (outcome.diverged, outcome.failure) {
            (Some(d), _) => End::Diverged(d.step as f64 * net.dt, d.message(&net, stiffness)),
            (None, Some(why)) => End::Failed(why),
            (None, None) => End::Complete,
        };
        let again = end == End::Complete && trace.goes_on(judging) && net.steps < max;
        if !again {
            return Ok(Ran::Done(p.classify(end, &trace, judging)));
        }
        net.steps = until::next_horizon(net.steps, max, net.sample_every);
    }
}
