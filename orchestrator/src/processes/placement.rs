//! Where a run's node processes may run: spread over every core the
//! orchestrator may use, or packed onto one core while other programs keep
//! the machine busy ([`Placement::Auto`], the default).
//!
//! Why: in lockstep every exchange hands the turn from node to node. Across
//! cores each hand-off is a wake-up of a sleeping process on another CPU (an
//! inter-processor interrupt, then a preemption of whatever runs there); on a
//! shared machine that other CPU is busy with a competitor, and the wake-up
//! waits for the scheduler. On one core the hand-offs stay local and the run
//! gets that core's fair share (BENCHMARKS.md, "Under contention"). On an idle
//! machine spreading is faster, so `Auto` packs only while the CPU time used
//! by programs other than the run's nodes stays at or above [`BUSY`] cores,
//! and spreads again once it falls below [`QUIET`]. The placement never
//! changes what a node computes: lockstep results stay byte-identical.
//!
//! The [`Placer`] thread samples `/proc/stat` and each node's
//! `/proc/<pid>/stat` every [`WINDOW`]; [`decide`] is the policy, pure.

use msgs::config::Contention;
use nix::sched::{CpuSet, sched_getaffinity, sched_setaffinity};
use nix::unistd::Pid;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// How node processes are placed on the cores.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Placement {
    /// Spread while the machine is idle, pack onto one core while it is busy.
    #[default]
    Auto,
    /// Every core the orchestrator may use (the scheduler decides).
    Spread,
    /// One core for the whole run.
    Pack,
}

/// Foreign load (cores) at or above which `Auto` packs.
pub const BUSY: f64 = 0.5;
/// Foreign load (cores) below which `Auto` spreads again.
pub const QUIET: f64 = 0.25;
/// Sampling period of the load.
pub const WINDOW: Duration = Duration::from_millis(200);
/// The first sampling period (one window decides the first placement).
pub const FIRST_WINDOW: Duration = Duration::from_millis(200);
/// Windows in a row a condition must hold before the placement changes.
pub const HYSTERESIS: u32 = 2;

/// What the run's nodes are placed on now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placed {
    /// Every allowed core.
    Spread,
    /// This core.
    Packed(usize),
}

/// The policy's memory between windows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// Current placement.
    pub placed: Placed,
    /// Windows in a row that argued for a change.
    pub streak: u32,
}

/// One window's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct Window {
    /// CPU time other programs used, in cores (busy time of every allowed
    /// core minus the run's nodes' and the orchestrator's).
    pub foreign: f64,
    /// Busy fraction of each allowed core, for picking the core to pack onto.
    pub per_core: Vec<(usize, f64)>,
}

/// The placement after `w`, given `state` (hysteresis: a change needs
/// [`HYSTERESIS`] windows in a row). Packs onto the least busy core.
#[must_use]
pub fn decide(state: State, w: &Window) -> State {
    let wants_change = match state.placed {
        Placed::Spread => w.foreign >= BUSY,
        Placed::Packed(_) => w.foreign < QUIET,
    };
    if !wants_change {
        return State { streak: 0, ..state };
    }
    if state.streak + 1 < HYSTERESIS {
        return State {
            streak: state.streak + 1,
            ..state
        };
    }
    let placed = match state.placed {
        Placed::Spread => least_busy(w).map_or(Placed::Spread, Placed::Packed),
        Placed::Packed(_) => Placed::Spread,
    };
    State { placed, streak: 0 }
}

/// The least busy core of the window.
#[must_use]
pub fn least_busy(w: &Window) -> Option<usize> {
    w.per_core
        .iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|&(core, _)| core)
}

/// Moves every thread of `pid` onto `set` (threads started later inherit it).
fn apply(pid: u32, set: &CpuSet) {
    let tasks = std::fs::read_dir(format!("/proc/{pid}/task"));
    for t in tasks.into_iter().flatten().flatten() {
        if let Some(tid) = t.file_name().to_str().and_then(|s| s.parse().ok()) {
            let _ = sched_setaffinity(Pid::from_raw(tid), set);
        }
    }
}

/// The cores of `set`.
fn cores_of(set: &CpuSet) -> Vec<usize> {
    (0..CpuSet::count())
        .filter(|&c| set.is_set(c).unwrap_or(false))
        .collect()
}

/// Whether a [`Placer`] for `placement` watches the load with `cores`
/// cores to place on (not for `Spread`, and not on a single core).
fn watches(placement: Placement, cores: usize) -> bool {
    cores > 1 && placement != Placement::Spread
}

/// Who copes with competing programs when the run is placed by
/// `placement` on this machine: the placement where it watches the load,
/// else the nodes' waiters. Goes into every node's configuration.
#[must_use]
pub fn contention(placement: Placement) -> Contention {
    let cores = sched_getaffinity(Pid::from_raw(0)).map_or(1, |set| cores_of(&set).len());
    if watches(placement, cores) {
        Contention::Placement
    } else {
        Contention::Waiter
    }
}

/// Samples the load and moves the run's nodes; stops when dropped.
#[derive(Debug)]
pub struct Placer {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Placer {
    /// Starts placing the processes `pids` by `placement`.
    #[must_use]
    pub fn start(placement: Placement, pids: Vec<u32>) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let Ok(allowed) = sched_getaffinity(Pid::from_raw(0)) else {
            return Self { stop, thread: None };
        };
        let cores = cores_of(&allowed);
        let flag = Arc::clone(&stop);
        let thread = watches(placement, cores.len()).then(|| {
            std::thread::spawn(move || {
                super::load::watch(placement, &pids, &allowed, &cores, &flag)
            })
        });
        Self { stop, thread }
    }
}

impl Drop for Placer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Places `pids` as `placed` (`allowed`: the spread set).
pub(super) fn place(pids: &[u32], placed: Placed, allowed: &CpuSet) {
    let set = match placed {
        Placed::Spread => *allowed,
        Placed::Packed(core) => {
            let mut one = CpuSet::new();
            if one.set(core).is_err() {
                return;
            }
            one
        }
    };
    for &pid in pids {
        apply(pid, &set);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window(foreign: f64) -> Window {
        Window {
            foreign,
            per_core: vec![(0, 0.9), (1, 0.4)],
        }
    }

    const SPREAD: State = State {
        placed: Placed::Spread,
        streak: 0,
    };

    #[test]
    fn a_busy_machine_packs_the_run_onto_the_least_busy_core_after_the_hysteresis() {
        let s = decide(SPREAD, &window(1.8));
        assert_eq!(s.placed, Placed::Spread);
        let s = decide(s, &window(1.7));
        assert_eq!(s.placed, Placed::Packed(1));
    }

    #[test]
    fn a_single_busy_window_changes_nothing() {
        let s = decide(SPREAD, &window(1.8));
        let s = decide(s, &window(0.1));
        assert_eq!(s, SPREAD);
    }

    #[test]
    fn a_quiet_machine_spreads_the_run_again() {
        let packed = State {
            placed: Placed::Packed(1),
            streak: 0,
        };
        // Between QUIET and BUSY nothing changes (no flapping).
        assert_eq!(decide(packed, &window(0.3)), packed);
        let s = decide(decide(packed, &window(0.1)), &window(0.05));
        assert_eq!(s.placed, Placed::Spread);
    }

    #[test]
    fn only_a_watching_placement_takes_contention_off_the_waiters() {
        assert!(watches(Placement::Auto, 2));
        assert!(watches(Placement::Pack, 2));
        assert!(!watches(Placement::Spread, 2));
        assert!(!watches(Placement::Auto, 1));
    }
}
