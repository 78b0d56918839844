//! Where a run's node processes may run: spread over every core the
//! orchestrator may use, or packed onto one core while other programs keep
//! the machine busy ([`Placement::Auto`], the default). `Auto` spreads a run
//! with more nodes than cores by pinning each node to one core, the graph
//! cut into a part per core ([`super::partition`]): the scheduler would
//! otherwise migrate them and every migration costs cold caches.
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
//! The [`Placer`] thread samples the busy time of every core and the CPU
//! time of each node ([`attsync_sched::busy`], [`attsync_sched::schedstat`])
//! every [`WINDOW`]; [`decide`] is the policy, pure.

use super::partition::{cut_edges, partition};
use attsync_sched::{affinity, process, timeslice::SHORT_SLICE};
use msgs::config::Contention;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// How node processes are placed on the cores.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Placement {
    /// Spread while the machine is idle (each node pinned to the core of
    /// its part of the graph when nodes outnumber cores), pack onto one core
    /// while it is busy.
    #[default]
    Auto,
    /// Every core the orchestrator may use (the scheduler decides).
    Spread,
    /// One core for the whole run.
    Pack,
    /// Each node pinned to one core, the graph cut into a part per core,
    /// whatever the load (for a machine kept for the run).
    Pin,
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
    /// Every allowed core (each node on its part's core, if the run is
    /// partitioned: see `Cores::of`).
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

/// Moves every thread of `pid` onto `cores` with time slices of `slice`
/// (`None`: the kernel's default); threads started later inherit both.
fn apply(pid: u32, cores: &[usize], slice: Option<Duration>) {
    for tid in process::threads(pid) {
        let _ = affinity::set(tid, cores);
        if let Err(e) = attsync_sched::timeslice::set_slice(tid, slice) {
            tracing::debug!(pid, tid, "time slice unchanged: {e}");
        }
    }
}

/// Whether a [`Placer`] for `placement` watches the load with `cores`
/// cores to place on (`Auto` and `Pack`, not on a single core).
fn watches(placement: Placement, cores: usize) -> bool {
    cores > 1 && matches!(placement, Placement::Auto | Placement::Pack)
}

/// Who copes with competing programs when the run is placed by
/// `placement` on this machine: the placement where it watches the load,
/// else the nodes' waiters. Goes into every node's configuration.
#[must_use]
pub fn contention(placement: Placement) -> Contention {
    let cores = affinity::of(0).map_or(1, |list| list.len());
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

/// The cores a run may use, and where each of its nodes goes while spread.
#[derive(Debug, Clone)]
pub(super) struct Cores {
    /// Every core the orchestrator may use, ascending.
    pub list: Vec<usize>,
    /// Per node (in `pids` order) its core while spread; empty: any allowed core.
    pub pinned: Vec<usize>,
}

impl Cores {
    /// For `placement` of nodes whose graph is `adjacency` (one entry per
    /// node, in `pids` order): pinned by [`partition`] under `Pin`, and
    /// under `Auto` when the nodes outnumber the cores.
    fn of(placement: Placement, list: Vec<usize>, adjacency: &[Vec<usize>]) -> Self {
        let pin = match placement {
            Placement::Auto => adjacency.len() > list.len(),
            Placement::Pin => true,
            Placement::Spread | Placement::Pack => false,
        };
        let pinned = if pin && list.len() > 1 {
            let part = partition(adjacency, list.len());
            tracing::debug!(
                nodes = part.len(),
                cores = list.len(),
                cut_edges = cut_edges(adjacency, &part),
                "placement: each node pinned to its part's core"
            );
            part.iter().map(|&p| list[p]).collect()
        } else {
            Vec::new()
        };
        Self { list, pinned }
    }
}

impl Placer {
    /// Starts placing the processes `pids` by `placement`; `adjacency[k]`
    /// lists the positions in `pids` of node `k`'s neighbours.
    #[must_use]
    pub fn start(placement: Placement, pids: Vec<u32>, adjacency: &[Vec<usize>]) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let Ok(allowed) = affinity::of(0) else {
            return Self { stop, thread: None };
        };
        let cores = Cores::of(placement, allowed, adjacency);
        let flag = Arc::clone(&stop);
        if !cores.pinned.is_empty() {
            place(&pids, Placed::Spread, &cores);
        }
        let thread = watches(placement, cores.list.len()).then(|| {
            std::thread::spawn(move || super::load::watch(placement, &pids, &cores, &flag))
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

/// Pins each of `pids` to its part's core as `--placement pin` does
/// (`adjacency[k]`: the positions in `pids` of node `k`'s neighbours); for
/// the benchmark's bare lockstep, placed like a run.
pub fn pin(pids: &[u32], adjacency: &[Vec<usize>]) {
    if let Ok(allowed) = affinity::of(0) {
        let cores = Cores::of(Placement::Pin, allowed, adjacency);
        if !cores.pinned.is_empty() {
            place(pids, Placed::Spread, &cores);
        }
    }
}

/// Places `pids` as `placed` on `cores`: packed, every thread also gets
/// short time slices ([`slice`]), spread the kernel's default again.
pub(super) fn place(pids: &[u32], placed: Placed, cores: &Cores) {
    for (k, &pid) in pids.iter().enumerate() {
        let set = match (placed, cores.pinned.get(k)) {
            (Placed::Spread, None) => cores.list.clone(),
            (Placed::Spread, Some(&core)) | (Placed::Packed(core), _) => vec![core],
        };
        apply(pid, &set, slice(placed));
    }
}

/// The time slice of a node placed as `placed`: packed onto a core that a
/// competitor may share, the shortest the kernel grants
/// ([`SHORT_SLICE`]), so that a node whose input has come
/// runs within microseconds instead of after the competitor's slice, and a
/// yield hands the competitor a fourteenth of what it did (docs/waiting.md,
/// "Short slices"); spread, the kernel's default.
fn slice(placed: Placed) -> Option<Duration> {
    match placed {
        Placed::Packed(_) => Some(SHORT_SLICE),
        Placed::Spread => None,
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
        assert!(!watches(Placement::Pin, 2));
        assert!(!watches(Placement::Auto, 1));
    }

    /// A path of `n` nodes.
    fn path(n: usize) -> Vec<Vec<usize>> {
        (0..n)
            .map(|i| [i.checked_sub(1), (i + 1 < n).then_some(i + 1)])
            .map(|ws| ws.into_iter().flatten().collect())
            .collect()
    }

    /// The CPUs process `pid` may run on, and its slice.
    fn placed(pid: u32) -> (Vec<usize>, Option<Duration>) {
        let slice = attsync_sched::timeslice::slice_of(pid).expect("slice");
        (affinity::of(pid).expect("affinity"), slice)
    }

    #[test]
    fn packed_a_node_gets_one_core_and_short_slices_spread_every_core_and_the_default_again() {
        let allowed = affinity::of(0).expect("affinity");
        let cores = Cores::of(Placement::Auto, allowed, &[Vec::new()]);
        let mut node = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .expect("sleep");
        let pid = node.id();
        let (all, default) = placed(pid);
        place(&[pid], Placed::Packed(all[0]), &cores);
        let packed = placed(pid);
        place(&[pid], Placed::Spread, &cores);
        let spread = placed(pid);
        let _ = node.kill();
        let _ = node.wait();
        let short = if attsync_sched::timeslice::custom_slices() {
            Some(SHORT_SLICE)
        } else {
            default
        };
        assert_eq!(packed, (vec![all[0]], short));
        assert_eq!(spread, (all, default));
    }

    fn two_cores() -> Vec<usize> {
        vec![3, 5]
    }

    #[test]
    fn auto_pins_a_run_with_more_nodes_than_cores_each_node_to_its_parts_core() {
        let cores = Cores::of(Placement::Auto, two_cores(), &path(6));
        assert_eq!(cores.list, vec![3, 5]);
        assert_eq!(cores.pinned, vec![3, 3, 3, 5, 5, 5]);
        // No more nodes than cores: the scheduler places them.
        assert!(
            Cores::of(Placement::Auto, two_cores(), &path(2))
                .pinned
                .is_empty()
        );
    }

    #[test]
    fn pin_always_pins_spread_and_pack_never_do() {
        assert_eq!(
            Cores::of(Placement::Pin, two_cores(), &path(2)).pinned,
            vec![3, 5]
        );
        for p in [Placement::Spread, Placement::Pack] {
            assert!(
                Cores::of(p, two_cores(), &path(6)).pinned.is_empty(),
                "{p:?}"
            );
        }
        // One core: nothing to choose.
        let one = vec![0];
        assert!(Cores::of(Placement::Pin, one, &path(6)).pinned.is_empty());
    }
}
