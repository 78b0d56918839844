//! Where everything a run or a sweep writes goes: every output file and
//! directory name, in one place (as cargo's `core/compiler/layout.rs` names
//! everything under `target/`).
//!
//! ```text
//! results/<scenario>/             a run (`attsync run`, default --out)
//!   .attsync-run                  marker: the directory is attsync's (holds the run id)
//!   summary.json                  the results
//!   errors.csv                    error time series, one row per agent per sample
//!   errors.svg                    plot of errors.csv
//!   view.html                     the run in 3D in a browser (`attsync view`; not per sweep run)
//!   states.bin                    full state trajectory (see `states`)
//!   states.mcap                   `attsync export --mcap`'s default output (a recording)
//!   scenario.toml                 the scenario as run (copied)
//!   logs/<node>.log               processes engine: leader.log, agent-<id>.log
//!   manifest.json                 versions, seeds, platform, SHA-256 of every other file (written last)
//! results/<scenario>-sweep-<param>/   a sweep (`attsync sweep`, default --out)
//!   .attsync-run  summary.json    marker; summary.json has the content of sweep.json
//!   sweep.csv  sweep.json  sweep.svg
//!   runs/<k>-<value>/             one run each (the run layout above)
//! results/<scenario>-mc/          a Monte Carlo (`attsync mc`, default --out)
//!   .attsync-run                  marker
//!   trials.csv  initial.csv  mc.json  mc.svg
//!   logs/trial-<k>/<node>.log     processes engine: the logs of a trial that failed
//! .<name>.partial-<pid>/          staging directory beside `<name>` while it is written
//! .<name>.partial-<pid>.old/      the replaced results, while the new ones move in
//! .<name>.lock                    held (flock) by the run writing `<name>`; removed after
//! <base>/attsync-iox2/<run>/node-<id>.json   a node's configuration (processes engine)
//! ```

use std::path::{Path, PathBuf};

/// `.attsync-run`: marks a directory as attsync results (holds the run id);
/// only a directory holding it, and nothing but [`OWNED`], is ever replaced.
pub const MARKER: &str = ".attsync-run";
/// `summary.json`: a run's results, or a sweep's marker.
pub const SUMMARY: &str = "summary.json";
/// `errors.csv`.
pub const ERRORS_CSV: &str = "errors.csv";
/// `errors.svg`.
pub const ERRORS_SVG: &str = "errors.svg";
/// `view.html`: the run in 3D, one self-contained page (`crate::view`).
pub const VIEW: &str = "view.html";
/// `states.bin`.
pub const STATES: &str = "states.bin";
/// `states.mcap`: `attsync export DIR/states.bin --mcap`'s default output.
pub const STATES_MCAP: &str = "states.mcap";
/// `scenario.toml`: the scenario as run.
pub const SCENARIO: &str = "scenario.toml";
/// `logs/`: one log per node (processes engine).
pub const LOGS: &str = "logs";
/// `sweep.csv`.
pub const SWEEP_CSV: &str = "sweep.csv";
/// `sweep.json`.
pub const SWEEP_JSON: &str = "sweep.json";
/// `sweep.svg`.
pub const SWEEP_SVG: &str = "sweep.svg";
/// `runs/`: a sweep's runs.
pub const RUNS: &str = "runs";
/// `trials.csv`: a Monte Carlo's trials.
pub const TRIALS_CSV: &str = "trials.csv";
/// `initial.csv`: a Monte Carlo's draws.
pub const INITIAL_CSV: &str = "initial.csv";
/// `mc.json`: a Monte Carlo's summary.
pub const MC_JSON: &str = "mc.json";
/// `mc.svg`: a Monte Carlo's plot.
pub const MC_SVG: &str = "mc.svg";
/// `manifest.json`: what the run was and the SHA-256 of every other file
/// (`results::manifest`; read by `attsync verify`).
pub const MANIFEST: &str = "manifest.json";
/// Default parent of results directories (relative to the working directory).
pub const RESULTS: &str = "results";

/// Every name attsync writes at the top of a run's or a sweep's directory.
pub const OWNED: [&str; 18] = [
    MARKER,
    SUMMARY,
    ERRORS_CSV,
    ERRORS_SVG,
    STATES,
    SCENARIO,
    LOGS,
    SWEEP_CSV,
    SWEEP_JSON,
    SWEEP_SVG,
    RUNS,
    TRIALS_CSV,
    INITIAL_CSV,
    MC_JSON,
    MC_SVG,
    VIEW,
    STATES_MCAP,
    MANIFEST,
];

/// A node's name in file names and messages: `leader` (id 0), `agent-<id>`.
#[must_use]
pub fn node_name(id: u32) -> String {
    if id == 0 {
        "leader".into()
    } else {
        format!("agent-{id}")
    }
}

pub use launch::namespace::node_config_file;
pub use launch::node_log::node_log_file;

/// `.<name>.partial-<pid>`: the staging directory of `<name>` written by process `pid`.
#[must_use]
pub fn staging_name(name: &str, pid: u32) -> String {
    format!(".{name}.partial-{pid}")
}

/// The pid in `name` if it is a staging directory of `<dest_name>`
/// (`.<dest_name>.partial-<pid>`, or that with `.old`).
#[must_use]
pub fn staging_pid(dest_name: &str, name: &str) -> Option<u32> {
    let rest = name.strip_prefix(&format!(".{dest_name}.partial-"))?;
    rest.strip_suffix(".old").unwrap_or(rest).parse().ok()
}

/// `.<name>.lock`: the lock file of results directory `<name>`.
#[must_use]
pub fn lock_name(name: &str) -> String {
    format!(".{name}.lock")
}

/// `<staging>.old`: where the replaced results wait while the new ones move in.
#[must_use]
pub fn replaced_name(staging: &str) -> String {
    format!("{staging}.old")
}

/// `<k>-<value>` (k with 3 digits, `/`, space and `"` of the value made `_`):
/// the directory of a sweep's k-th run, under [`RUNS`].
#[must_use]
pub fn sweep_run_name(k: usize, value: &str) -> String {
    format!("{k:03}-{}", value.replace(['/', ' ', '"'], "_"))
}

/// `results/<scenario>`: a run's default directory.
#[must_use]
pub fn default_run_dir(scenario: &str) -> PathBuf {
    Path::new(RESULTS).join(scenario)
}

/// `results/<scenario>-sweep-<param>` (`.`, `[`, `]` of the parameter made
/// `_`): a sweep's default directory.
#[must_use]
pub fn default_sweep_dir(scenario: &str, param: &str) -> PathBuf {
    Path::new(RESULTS).join(format!(
        "{scenario}-sweep-{}",
        param.replace(['.', '[', ']'], "_")
    ))
}

/// The files of one run's results directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunLayout {
    root: PathBuf,
}

impl RunLayout {
    /// The layout of results directory `root` (which may be a staging directory).
    #[must_use]
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    /// The directory itself.
    #[must_use]
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// `summary.json`.
    #[must_use]
    pub fn summary(&self) -> PathBuf {
        self.root.join(SUMMARY)
    }

    /// `errors.csv`.
    #[must_use]
    pub fn errors_csv(&self) -> PathBuf {
        self.root.join(ERRORS_CSV)
    }

    /// `errors.svg`.
    #[must_use]
    pub fn errors_svg(&self) -> PathBuf {
        self.root.join(ERRORS_SVG)
    }

    /// `states.bin`.
    #[must_use]
    pub fn states(&self) -> PathBuf {
        self.root.join(STATES)
    }

    /// `view.html`.
    #[must_use]
    pub fn view(&self) -> PathBuf {
        self.root.join(VIEW)
    }

    /// `scenario.toml`.
    #[must_use]
    pub fn scenario(&self) -> PathBuf {
        self.root.join(SCENARIO)
    }

    /// `logs/`.
    #[must_use]
    pub fn logs(&self) -> PathBuf {
        self.root.join(LOGS)
    }

    /// `manifest.json`.
    #[must_use]
    pub fn manifest(&self) -> PathBuf {
        self.root.join(MANIFEST)
    }

    /// `logs/<node>.log` of node `id` (see [`node_name`]).
    #[must_use]
    pub fn node_log(&self, id: u32) -> PathBuf {
        self.logs().join(node_log_file(&node_name(id)))
    }
}

/// The files of a sweep's directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SweepLayout {
    root: PathBuf,
}

impl SweepLayout {
    /// The layout of sweep directory `root` (which may be a staging directory).
    #[must_use]
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    /// The directory itself.
    #[must_use]
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// `summary.json` (the marker).
    #[must_use]
    pub fn summary(&self) -> PathBuf {
        self.root.join(SUMMARY)
    }

    /// `sweep.csv`.
    #[must_use]
    pub fn csv(&self) -> PathBuf {
        self.root.join(SWEEP_CSV)
    }

    /// `sweep.json`.
    #[must_use]
    pub fn json(&self) -> PathBuf {
        self.root.join(SWEEP_JSON)
    }

    /// `sweep.svg`.
    #[must_use]
    pub fn svg(&self) -> PathBuf {
        self.root.join(SWEEP_SVG)
    }

    /// `runs/`.
    #[must_use]
    pub fn runs(&self) -> PathBuf {
        self.root.join(RUNS)
    }

    /// `runs/<k>-<value>` relative to the sweep directory, as `sweep.csv` lists it.
    #[must_use]
    pub fn run_rel(k: usize, value: &str) -> String {
        format!("{RUNS}/{}", sweep_run_name(k, value))
    }

    /// The layout of the k-th run, `runs/<k>-<value>/`.
    #[must_use]
    pub fn run(&self, k: usize, value: &str) -> RunLayout {
        RunLayout::new(self.runs().join(sweep_run_name(k, value)))
    }
}

/// The files of a Monte Carlo's directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct McLayout {
    root: PathBuf,
}

impl McLayout {
    /// The layout of Monte Carlo directory `root` (which may be a staging directory).
    #[must_use]
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    /// `trials.csv`.
    #[must_use]
    pub fn trials(&self) -> PathBuf {
        self.root.join(TRIALS_CSV)
    }

    /// `initial.csv`.
    #[must_use]
    pub fn initial(&self) -> PathBuf {
        self.root.join(INITIAL_CSV)
    }

    /// `mc.json`.
    #[must_use]
    pub fn json(&self) -> PathBuf {
        self.root.join(MC_JSON)
    }

    /// `mc.svg`.
    #[must_use]
    pub fn svg(&self) -> PathBuf {
        self.root.join(MC_SVG)
    }

    /// `logs/trial-<k>/`: the node logs of trial `k` (processes engine).
    #[must_use]
    pub fn trial_logs(&self, k: u64) -> PathBuf {
        self.root.join(LOGS).join(format!("trial-{k}"))
    }
}

/// `results/<scenario>-mc`: a Monte Carlo's default directory.
#[must_use]
pub fn default_mc_dir(scenario: &str) -> PathBuf {
    Path::new(RESULTS).join(format!("{scenario}-mc"))
}

/// `dest`'s parent (`.` for a bare name), where its staging directories and
/// lock file live (`None` if `dest` has no file name).
#[must_use]
pub fn beside(dest: &Path) -> Option<(&Path, String)> {
    let name = dest.file_name()?.to_string_lossy().into_owned();
    let parent = dest
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    Some((parent, name))
}

/// The staging directory beside `dest` that process `pid` writes it in:
/// `.<name>.partial-<pid>` (`None` if `dest` has no file name).
#[must_use]
pub fn staging_dir(dest: &Path, pid: u32) -> Option<PathBuf> {
    let name = dest.file_name()?.to_string_lossy();
    let parent = dest
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    Some(parent.join(staging_name(&name, pid)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names() {
        assert_eq!(node_name(0), "leader");
        assert_eq!(node_name(7), "agent-7");
        assert_eq!(
            RunLayout::new("out").node_log(3),
            Path::new("out/logs/agent-3.log")
        );
        assert_eq!(node_config_file(2), "node-2.json");
        assert_eq!(
            staging_dir(Path::new("a/out"), 42),
            Some(PathBuf::from("a/.out.partial-42"))
        );
        assert_eq!(
            staging_dir(Path::new("out"), 42),
            Some(PathBuf::from("./.out.partial-42"))
        );
        assert_eq!(replaced_name(".out.partial-42"), ".out.partial-42.old");
        assert_eq!(staging_pid("out", ".out.partial-42"), Some(42));
        assert_eq!(staging_pid("out", ".out.partial-42.old"), Some(42));
        assert_eq!(staging_pid("out", ".other.partial-42"), None);
        assert_eq!(lock_name("out"), ".out.lock");
        assert_eq!(SweepLayout::run_rel(4, "a b/\"c\""), "runs/004-a_b__c_");
        assert_eq!(
            SweepLayout::new("s").run(4, "0.5").root(),
            Path::new("s/runs/004-0.5")
        );
        assert_eq!(
            default_sweep_dir("paper", "network.link[0].delay"),
            Path::new("results/paper-sweep-network_link_0__delay")
        );
        assert_eq!(default_run_dir("x"), Path::new("results/x"));
    }
}
