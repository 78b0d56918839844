//! `--placement`: where a run's node processes may run. `pack` puts every
//! node on one core, `spread` leaves them on every core, `pin` pins each
//! node to one core (the graph cut into a part per core), `auto` (the
//! default) pins like `pin` while the machine is idle (unit tests:
//! `placement::tests`) and packs while other programs keep it busy — tested
//! here with as many CPU-bound competitors as cores. The placement never
//! changes what a node computes: results are byte-identical.
//!
//! Packed, every thread of every node asks for short time slices
//! (`attsync_sched::timeslice::SHORT_SLICE`, Linux ≥ 6.12); spread, the kernel's
//! default.
//!
//! The test reads each node's allowed CPUs from `/proc/<pid>/status`
//! (`Cpus_allowed_list`) and its time slice from `/proc/<pid>/sched`
//! (`se.slice`, ns) while the run steps; every wait is bounded.

use attsync_tests::{
    Attsync, Sandbox, assert_same_results, node_pid, owned_runs, paper, run_args, wait_until,
};
use std::path::Path;
use std::process::{Child, Command};
use std::time::Duration;

const POLL: Duration = Duration::from_millis(10);

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
}

/// Where a node may run and the time slice it asked for.
#[derive(Debug)]
struct Placed {
    /// The CPUs it may run on, as `/proc` lists them ("0-1", "1").
    cpus: String,
    /// Its time slice, ns (`None` where the kernel does not say).
    slice_ns: Option<u64>,
}

/// Where node `id` of `run` may run, and its slice.
fn placed(run: &str, id: u32) -> Option<Placed> {
    let pid = node_pid(run, id)?;
    let status = attsync_sched::status::of(pid).ok()?;
    let cpus = attsync_sched::status::field(&status, "Cpus_allowed_list")?.to_string();
    // The slice as the kernel reports it, a witness independent of the
    // system call the orchestrator made.
    let sched = std::fs::read_to_string(format!("/proc/{pid}/sched")).ok()?;
    let slice_ns = sched.lines().find_map(|l| {
        l.strip_prefix("se.slice")?
            .split(':')
            .nth(1)?
            .trim()
            .parse()
            .ok()
    });
    Some(Placed { cpus, slice_ns })
}

/// The paper run's nodes: the leader and 7 agents.
const NODES: u32 = 8;

/// Where every node of `run` may run, if every node is there.
fn placed_all(run: &str) -> Option<Vec<Placed>> {
    (0..NODES).map(|id| placed(run, id)).collect()
}

/// Every node asked for short slices (where the kernel has them).
fn short_slices(nodes: &[Placed]) -> bool {
    let short = u64::try_from(attsync_sched::timeslice::SHORT_SLICE.as_nanos()).expect("ns");
    !attsync_sched::timeslice::custom_slices() || nodes.iter().all(|n| n.slice_ns == Some(short))
}

/// No node asked for short slices.
fn default_slices(nodes: &[Placed]) -> bool {
    let short = u64::try_from(attsync_sched::timeslice::SHORT_SLICE.as_nanos()).expect("ns");
    nodes.iter().all(|n| n.slice_ns != Some(short))
}

/// Runs the paper's scheme-1 scenario for `duration` s with `args`, and
/// waits (bounded) until `seen(where each node may run)` holds while it
/// steps. Returns whether it was seen; the run is waited for and must succeed.
fn run_and_watch(
    sb: &Sandbox,
    out: &str,
    duration: &str,
    args: &[&str],
    seen: impl Fn(&[Placed]) -> bool,
) -> bool {
    let set = format!("simulation.duration={duration}");
    let running = Attsync::new(sb.path())
        .args(run_args(
            &paper("timevarying"),
            "processes",
            &sb.join(out),
            &[&set],
        ))
        .args(args.iter().copied())
        .spawn();
    let pid = running.pid();
    let run = wait_until(Duration::from_secs(30), POLL, || {
        owned_runs(pid).into_iter().next()
    })
    .expect("the run's namespace");
    let hit = wait_until(Duration::from_secs(60), POLL, || {
        placed_all(&run).filter(|a| seen(a)).map(|_| ())
    })
    .is_some();
    running
        .wait(attsync_tests::RUN_TIMEOUT)
        .assert_ok()
        .assert_no_leftovers();
    hit
}

fn single_core(list: &str) -> bool {
    !list.contains('-') && !list.contains(',')
}

/// Every node on one and the same core, with short slices.
fn packed(nodes: &[Placed]) -> bool {
    nodes.iter().all(|n| single_core(&n.cpus))
        && nodes.iter().all(|n| n.cpus == nodes[0].cpus)
        && short_slices(nodes)
}

/// Every node on a single core, the nodes over more than one core, with
/// the kernel's slices.
fn pinned_apart(nodes: &[Placed]) -> bool {
    nodes.iter().all(|n| single_core(&n.cpus))
        && nodes.iter().any(|n| n.cpus != nodes[0].cpus)
        && default_slices(nodes)
}

/// CPU-bound competitors, killed when dropped.
struct Burners(Vec<Child>);

impl Burners {
    fn start(k: usize) -> Self {
        Self(
            (0..k)
                .map(|_| {
                    Command::new("sh")
                        .args(["-c", "while :; do :; done"])
                        .spawn()
                        .expect("sh")
                })
                .collect(),
        )
    }
}

impl Drop for Burners {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

#[test]
fn pack_puts_every_node_on_one_core_and_changes_no_result() {
    if cores() < 2 {
        eprintln!("one core: packing and spreading are the same here");
        return;
    }
    let sb = Sandbox::new("placement-pack");
    let was_packed = run_and_watch(&sb, "packed", "20", &["--placement", "pack"], packed);
    assert!(
        was_packed,
        "the nodes never ran on one core with short slices with --placement pack"
    );
    let spread = run_and_watch(&sb, "spread", "20", &["--placement", "spread"], |a| {
        a.iter().all(|n| !single_core(&n.cpus)) && default_slices(a)
    });
    assert!(
        spread,
        "with --placement spread a node ran on a single core or with short slices"
    );
    assert_same_results(&sb.join("packed"), &sb.join("spread"));
}

#[test]
fn pin_puts_each_node_on_one_core_of_several_and_changes_no_result() {
    if cores() < 2 {
        eprintln!("one core: nothing to pin apart");
        return;
    }
    let sb = Sandbox::new("placement-pin");
    let pinned = run_and_watch(&sb, "pinned", "20", &["--placement", "pin"], pinned_apart);
    assert!(
        pinned,
        "with --placement pin the nodes were never each on one core, over several"
    );
    let spread = run_and_watch(&sb, "spread", "20", &["--placement", "spread"], |_| true);
    assert!(spread);
    assert_same_results(&sb.join("pinned"), &sb.join("spread"));
}

#[test]
fn auto_packs_while_competitors_keep_every_core_busy() {
    if cores() < 2 {
        eprintln!("one core: nothing to pack");
        return;
    }
    let sb = Sandbox::new("placement-auto");
    let burners = Burners::start(cores());
    let was_packed = run_and_watch(&sb, "auto", "10", &[], packed);
    drop(burners);
    assert!(
        was_packed,
        "with {} competitors the nodes were never packed",
        cores()
    );
    assert!(Path::new(&sb.join("auto/errors.csv")).is_file());
}
