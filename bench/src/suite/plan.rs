//! What `attsync-bench run` measures: the durations ([`Plan`]), the cases
//! ([`Case`]: three paper scenarios and two generated trees), and the spin
//! rule (shortened or skipped with more processes than cores).

use super::Options;
use crate::bare::{BareSpec, NodeTopo};
use crate::error::{BenchError, Result};
use attsync::processes::{ProcessOptions, node_configs};
use msgs::config::WaitStrategy;
use std::path::{Path, PathBuf};
use std::process::Command;

/// How long each run is.
#[derive(Debug, Clone, Copy)]
pub(super) struct Plan {
    pub reps: usize,
    /// Simulated seconds: paper scenarios, tree-32, tree-100.
    pub paper: f64,
    pub tree32: f64,
    pub tree100: f64,
    /// Steps of a shortened spin run.
    pub spin_steps: u64,
    /// No spin runs above this many processes.
    pub spin_max_nodes: u32,
    /// Steps of the contention case (adaptive, block; a tenth for yield, a
    /// hundredth for spin): the whole 40 s paper run, so that placement's
    /// first windows (the run starts spread) weigh as little as in a user's run.
    pub contend_steps: u64,
}

impl Plan {
    pub fn new(o: &Options) -> Self {
        let (paper, tree32, tree100, spin_steps) = if o.quick {
            (10.0, 0.5, 0.25, 20)
        } else {
            (40.0, 2.0, 1.0, 50)
        };
        let d = |default: f64| o.duration.unwrap_or(default);
        Self {
            reps: o.reps.unwrap_or(if o.quick { 1 } else { 3 }),
            paper: d(paper),
            tree32: d(tree32),
            tree100: d(tree100),
            spin_steps,
            spin_max_nodes: 16,
            contend_steps: if o.quick { 1000 } else { 40_000 },
        }
    }

    /// The steps of a `wait` run of `case` on `cores` cores, and a note if
    /// shortened; [`Skipped`] if it is skipped.
    pub fn steps_for(
        &self,
        case: &Case,
        wait: WaitStrategy,
        cores: u32,
    ) -> Result<(u64, String), Skipped> {
        if wait != WaitStrategy::Spin || case.nodes <= cores {
            Ok((case.steps, String::new()))
        } else if case.nodes <= self.spin_max_nodes {
            Ok((
                self.spin_steps.min(case.steps),
                format!(
                    "shortened to {} steps: {} spinning processes on {cores} cores",
                    self.spin_steps, case.nodes
                ),
            ))
        } else {
            Err(Skipped {
                label: case.label.clone(),
                nodes: case.nodes,
                cores,
            })
        }
    }
}

/// A spinning run of more processes than cores (and than
/// `spin_max_nodes`): skipped, it would progress only by preemption.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{label} (N = {nodes}): spin skipped — {nodes} busy-polling processes on {cores} cores \
     progress only when the scheduler preempts one (see the N = 8 spin rows)"
)]
pub(super) struct Skipped {
    /// The case's label.
    pub label: String,
    /// Its nodes.
    pub nodes: u32,
    /// The cores.
    pub cores: u32,
}

/// One scenario to measure.
#[derive(Debug, Clone)]
pub(super) struct Case {
    pub label: String,
    pub scenario: PathBuf,
    /// `--set` overrides (the duration).
    pub sets: Vec<String>,
    pub nodes: u32,
    pub dt: f64,
    pub steps: u64,
    /// The node graph the process engine uses, and its fan-out limit.
    pub topo: Vec<NodeTopo>,
    pub max_fanout: usize,
}

impl Case {
    fn load(label: &str, scenario: PathBuf, duration: f64) -> Result<Self> {
        let sets = vec![format!("simulation.duration={duration:?}")];
        let loaded = attsync::scenario::load(&scenario, &sets)?;
        let net = &loaded.resolved.network;
        let configs = node_configs(net, "x", Path::new("/tmp"), &ProcessOptions::default());
        Ok(Self {
            label: label.into(),
            scenario,
            sets,
            nodes: configs.len() as u32,
            dt: net.dt,
            steps: net.steps,
            max_fanout: configs.first().map_or(1, |c| c.limits.max_fanout),
            topo: configs
                .iter()
                .map(|c| NodeTopo {
                    id: c.id,
                    inputs: c.inputs.clone(),
                    outputs: c.outputs.clone(),
                })
                .collect(),
        })
    }

    pub fn sim_seconds(&self) -> f64 {
        self.steps as f64 * self.dt
    }

    /// The overrides for a run of `steps` steps.
    pub fn sets_for(&self, steps: u64) -> Vec<String> {
        if steps == self.steps {
            self.sets.clone()
        } else {
            vec![format!(
                "simulation.duration={:?}",
                round9(steps as f64 * self.dt)
            )]
        }
    }

    /// The overrides of the "telemetry off" diagnostic: samples only at the
    /// first and last step.
    pub fn quiet_sets(&self) -> Vec<String> {
        let mut sets = self.sets.clone();
        sets.push(format!(
            "output.sample_period={:?}",
            round9(self.sim_seconds())
        ));
        sets
    }

    /// The bare lockstep over this case's own graph (adaptive).
    pub fn graph_spec(&self) -> BareSpec {
        BareSpec {
            n: self.nodes,
            steps: self.steps,
            wait: WaitStrategy::Adaptive,
            graph: Some((self.topo.clone(), self.max_fanout)),
            pinned: false,
        }
    }

    /// The same, each node pinned to one core as attsync's placement pins a run.
    pub fn pinned_graph_spec(&self) -> BareSpec {
        BareSpec {
            pinned: true,
            ..self.graph_spec()
        }
    }
}

/// The cases selected by `o.only`, the trees generated into `o.work`.
pub(super) fn cases(o: &Options, plan: &Plan) -> Result<Vec<Case>> {
    // (label, the paper scenario's file or the tree's agent count, duration)
    let mut all: Vec<(String, Result<PathBuf, u32>, f64)> = Vec::new();
    for (label, file) in [
        ("paper-timevarying", "timevarying.toml"),
        ("paper-constant-observer", "constant-observer.toml"),
        ("paper-constant-observerless", "constant-observerless.toml"),
    ] {
        all.push((label.into(), Ok(o.scenarios.join(file)), plan.paper));
    }
    for (agents, duration) in [(31, plan.tree32), (99, plan.tree100)] {
        all.push((format!("tree-{}", agents + 1), Err(agents), duration));
    }
    let selected = |label: &str| o.only.is_empty() || o.only.iter().any(|s| label.contains(s));
    let mut out = Vec::new();
    for (label, source, duration) in all {
        if selected(&label) {
            let file = match source {
                Ok(file) => file,
                Err(agents) => generate_tree(o, agents)?,
            };
            out.push(Case::load(&label, file, duration)?);
        }
    }
    Ok(out)
}

/// `attsync gen tree --agents N --leader-links 2 --seed 1` into the work directory.
fn generate_tree(o: &Options, agents: u32) -> Result<PathBuf> {
    let file = o.work.join(format!("tree-{}.toml", agents + 1));
    let status = Command::new(&o.bins.attsync)
        .args(["gen", "tree", "--agents", &agents.to_string()])
        .args(["--leader-links", "2", "--seed", "1", "--out"])
        .arg(&file)
        .status()
        .map_err(|source| BenchError::Spawn {
            program: "attsync gen tree".into(),
            source,
        })?;
    if !status.success() {
        return Err(BenchError::Failed {
            program: format!("attsync gen tree --agents {agents}"),
            outcome: format!("failed ({status})"),
        });
    }
    Ok(file)
}

/// The bare ring of `n` processes.
pub(super) fn ring_spec(n: u32, steps: u64, wait: WaitStrategy) -> BareSpec {
    BareSpec {
        n,
        steps,
        wait,
        graph: None,
        pinned: false,
    }
}

pub(super) fn round9(x: f64) -> f64 {
    (x * 1e9).round() / 1e9
}
