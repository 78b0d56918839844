//! How many nodes this machine can run, checked before anything starts: a
//! run that cannot fit is refused ([`CapacityError`], exit code 2) naming
//! the limit, what the run needs and what to do, instead of failing minutes
//! later with thousands of processes and shared-memory files behind it.
//!
//! [`processes`] (the process engine) and [`in_process`] (the in-process
//! engine) are pure functions of a [`Host`] snapshot ([`Host::read`] reads
//! the real one) and of what the run needs ([`Need::of`]).
//!
//! The per-node figures were measured on attsync's own nodes (iceoryx2
//! 0.10, observerless trees of 8, 32 and 100 nodes, and a star of 32 for
//! the fan-out term) and are rounded up; see BENCHMARKS.md, "Start-up and
//! capacity".

use attitude::network::Network;
use msgs::config::WaitStrategy;
use std::path::Path;
use thiserror::Error;

/// File descriptors the orchestrator holds per node: stdout and stderr
/// pipes, a pidfd, the log file, the telemetry subscriber's port tag and
/// dynamic segment (measured 9.0 per node between 8 and 100 nodes).
pub const FDS_PER_NODE: u64 = 10;
/// File descriptors the orchestrator holds besides (std streams, results
/// files, its own iceoryx2 node, control and wake; measured ≈ 20).
pub const FDS_BASE: u64 = 64;
/// File descriptors a node holds per port beyond its fixed ones.
pub const NODE_FDS_PER_PORT: u64 = 3;
/// File descriptors a node holds besides its per-port ones.
pub const NODE_FDS_BASE: u64 = 64;
/// Shared memory per node, bytes (measured 225–253 KB at a fan-out of ≤ 5).
pub const SHM_PER_NODE: u64 = 256 << 10;
/// Shared memory per node per unit of the run's largest fan-out, bytes
/// (every state service is sized for it; measured ≈ 12 KB).
pub const SHM_PER_FANOUT: u64 = 16 << 10;
/// Files per node under the namespace root, bytes (measured ≈ 13 KB).
pub const ROOT_PER_NODE: u64 = 16 << 10;
/// Memory of one node process, bytes: its private pages (measured 2.4–2.9
/// MB `RssAnon`) and the kernel's share (page tables, stacks).
pub const MEM_PER_NODE: u64 = 4 << 20;
/// Threads of the orchestrator (main, tokio's worker and blocking pool).
pub const ORCHESTRATOR_TASKS: u64 = 16;
/// Memory of one agent in the in-process engine besides its samples, bytes.
pub const MEM_PER_AGENT: u64 = 16 << 10;
/// Memory per agent per output sample in the in-process engine's series
/// (5 × f64, up to twice that while a vector grows), bytes.
pub const MEM_PER_SAMPLE: u64 = 80;
/// Nodes per core past which a warning says start-up will be slow: 100
/// nodes on 2 cores start in ~1 s, 300 in tens of seconds.
pub const NODES_PER_CORE_WARN: u64 = 100;

/// What the checks read from the machine (all counts, sizes in bytes;
/// `None`: unlimited or unknown, never refused on).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Host {
    /// RLIMIT_NPROC (soft): tasks the user may have (`None` for root).
    pub max_user_tasks: Option<u64>,
    /// Tasks (threads) of the user now.
    pub user_tasks: u64,
    /// `/proc/sys/kernel/pid_max`.
    pub pid_max: Option<u64>,
    /// `/proc/sys/kernel/threads-max`.
    pub threads_max: Option<u64>,
    /// Tasks on the machine now.
    pub tasks: u64,
    /// RLIMIT_NOFILE (soft) of this process (inherited by the nodes).
    pub max_open_files: Option<u64>,
    /// File descriptors this process has open now.
    pub open_files: u64,
    /// Free space in `/dev/shm`.
    pub shm_free: Option<u64>,
    /// Free space where namespaces are created.
    pub root_free: Option<u64>,
    /// `MemAvailable` of `/proc/meminfo`.
    pub mem_available: Option<u64>,
    /// Cores this process may run on.
    pub cores: u64,
}

/// What a run asks of the machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Need {
    /// Nodes: the leader and the agents.
    pub nodes: u64,
    /// Largest number of receivers of any node's state (`msgs::Limits`).
    pub max_fanout: u64,
    /// Largest number of ports of one node (inputs + outputs).
    pub max_ports: u64,
    /// Output samples per agent (in-process series).
    pub samples: u64,
    /// Nodes busy-poll (`--wait spin`).
    pub spin: bool,
}

impl Need {
    /// What `net` needs, run with `wait`.
    #[must_use]
    pub fn of(net: &Network, wait: WaitStrategy) -> Self {
        let limits = msgs::Limits::of(net);
        let leader_links = (net.agents.iter())
            .filter(|a| a.model.leader_gain.is_some())
            .count();
        let max_ports = (net.agents.iter())
            .map(|a| 2 * a.model.neighbours.len() + usize::from(a.model.leader_gain.is_some()))
            .chain([leader_links])
            .max()
            .unwrap_or(0);
        Self {
            nodes: limits.nodes as u64,
            max_fanout: limits.max_fanout as u64,
            max_ports: max_ports as u64,
            samples: net.steps / net.sample_every.max(1) + 2,
            spin: wait == WaitStrategy::Spin,
        }
    }
}

/// A run this machine cannot take.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error(
    "the {engine} engine cannot run {nodes} nodes here: they need {need}, but {limit} {have}; {advice}"
)]
pub struct CapacityError {
    /// `processes` or `in-process`.
    pub engine: &'static str,
    /// Nodes of the run.
    pub nodes: u64,
    /// The limit, as a person finds it (`open files (RLIMIT_NOFILE, ulimit -n)`).
    pub limit: String,
    /// What the run needs of it.
    pub need: String,
    /// What the limit allows (`is 64, 12 in use`).
    pub have: String,
    /// What to do.
    pub advice: String,
}

/// The in-process engine as the way out of a process-engine limit.
const OR_IN_PROCESS: &str = "or use `--engine in-process` (one process, no limit per node)";

/// Checks that the process engine can run `need` on `host`; the warnings
/// (slow start-up, busy-polling nodes on too few cores) are for the log.
///
/// # Errors
/// The first limit `need` does not fit in.
pub fn processes(host: &Host, need: &Need) -> Result<Vec<String>, CapacityError> {
    let refuse = |limit: &str, need_s: String, have: String, advice: String| CapacityError {
        engine: "processes",
        nodes: need.nodes,
        limit: limit.into(),
        need: need_s,
        have,
        advice,
    };
    let tasks = need.nodes + ORCHESTRATOR_TASKS;
    if let Some(max) = host.max_user_tasks {
        let free = max.saturating_sub(host.user_tasks);
        if tasks > free {
            return Err(refuse(
                "the user's process limit (RLIMIT_NPROC, `ulimit -u`)",
                format!("{tasks} processes"),
                format!("is {max} with {} in use", host.user_tasks),
                format!(
                    "raise it (`ulimit -u {}`) {OR_IN_PROCESS}",
                    host.user_tasks + tasks
                ),
            ));
        }
    }
    for (name, max) in [
        ("/proc/sys/kernel/pid_max", host.pid_max),
        ("/proc/sys/kernel/threads-max", host.threads_max),
    ] {
        if let Some(max) = max.filter(|&m| tasks > m.saturating_sub(host.tasks)) {
            return Err(refuse(
                &format!("the machine's task limit ({name})"),
                format!("{tasks} processes"),
                format!("is {max} with {} tasks running", host.tasks),
                format!("raise it (as root) {OR_IN_PROCESS}"),
            ));
        }
    }
    check_files(host, need).map_err(|(l, n, h, a)| refuse(l, n, h, a))?;
    check_space(host, need).map_err(|(l, n, h, a)| refuse(l, n, h, a))?;
    Ok(warnings(host, need))
}

/// A limit not met: (limit, need, have, advice).
type Shortfall = (&'static str, String, String, String);

/// Open files: the orchestrator's, and the busiest node's (both under the
/// same RLIMIT_NOFILE, which the nodes inherit).
fn check_files(host: &Host, need: &Need) -> Result<(), Shortfall> {
    let Some(max) = host.max_open_files else {
        return Ok(());
    };
    let orchestrator = host.open_files + FDS_BASE + need.nodes * FDS_PER_NODE;
    let node = NODE_FDS_BASE + need.max_ports * NODE_FDS_PER_PORT;
    let fds = orchestrator.max(node);
    if fds <= max {
        return Ok(());
    }
    Err((
        "the open-file limit (RLIMIT_NOFILE, `ulimit -n`)",
        format!("{fds} open files in attsync (≈ {FDS_PER_NODE} per node)"),
        format!("is {max} with {} open", host.open_files),
        format!(
            "raise it (`ulimit -n {}`) {OR_IN_PROCESS}",
            fds.next_multiple_of(1024)
        ),
    ))
}

/// Shared memory, the namespace root's files, and memory.
fn check_space(host: &Host, need: &Need) -> Result<(), Shortfall> {
    let mib = |b: u64| format!("{} MiB", b.div_ceil(1 << 20));
    let shm = need.nodes * (SHM_PER_NODE + need.max_fanout * SHM_PER_FANOUT);
    let root = need.nodes * ROOT_PER_NODE;
    let mem = need.nodes * MEM_PER_NODE;
    let checks = [
        (
            "the free space of /dev/shm",
            shm,
            host.shm_free,
            "free space in /dev/shm (or enlarge it: `mount -o remount,size=… /dev/shm`)",
        ),
        (
            "the free space of the namespace root (/dev/shm/attsync-iox2 or $TMPDIR/attsync-iox2)",
            root,
            host.root_free,
            "free space there, or set TMPDIR to a larger file system",
        ),
        (
            "the available memory (MemAvailable)",
            mem,
            host.mem_available,
            "free memory",
        ),
    ];
    for (limit, bytes, free, what) in checks {
        if let Some(free) = free.filter(|&f| bytes > f) {
            return Err((
                limit,
                mib(bytes),
                format!("is {}", mib(free)),
                format!("{what}, {OR_IN_PROCESS}"),
            ));
        }
    }
    Ok(())
}

/// Start-up will be slow, or spinning nodes starve each other.
fn warnings(host: &Host, need: &Need) -> Vec<String> {
    let cores = host.cores.max(1);
    let mut out = Vec::new();
    if need.nodes > NODES_PER_CORE_WARN * cores {
        out.push(format!(
            "{} nodes on {cores} cores: start-up alone may take tens of seconds \
             and reach the start-up timeout (or use --engine in-process)",
            need.nodes
        ));
    }
    if need.spin && need.nodes > cores {
        out.push(format!(
            "--wait spin with {} nodes on {cores} cores: busy-polling nodes progress only \
             when the scheduler preempts one (use --wait adaptive)",
            need.nodes
        ));
    }
    out
}

/// Checks that the in-process engine can hold `need`'s agents and their
/// samples in `host`'s available memory.
///
/// # Errors
/// The estimate exceeds `MemAvailable`.
pub fn in_process(host: &Host, need: &Need) -> Result<(), CapacityError> {
    let agents = need.nodes.saturating_sub(1);
    let bytes = agents.saturating_mul(MEM_PER_AGENT + need.samples.saturating_mul(MEM_PER_SAMPLE));
    match host.mem_available {
        Some(free) if bytes > free => Err(CapacityError {
            engine: "in-process",
            nodes: need.nodes,
            limit: "the available memory (MemAvailable)".into(),
            need: format!(
                "≈ {} MiB ({agents} agents × {} samples)",
                bytes.div_ceil(1 << 20),
                need.samples
            ),
            have: format!("is {} MiB", free >> 20),
            advice: "sample less often (`--set output.sample_period=…`), shorten the run, \
                     or free memory"
                .into(),
        }),
        _ => Ok(()),
    }
}

impl Host {
    /// Reads this machine's limits and usage; `root` is where namespaces
    /// are created. What cannot be read is `None` (not checked).
    #[must_use]
    pub fn read(root: &Path) -> Self {
        use attsync_sched::{limits, machine};
        // Root has no RLIMIT_NPROC.
        let uid = limits::effective_uid();
        let max_user_tasks = limits::soft_limit("Max processes").filter(|_| uid != 0);
        let user_tasks = max_user_tasks.map_or(0, |_| limits::user_threads(uid));
        Self {
            max_user_tasks,
            user_tasks,
            pid_max: limits::pid_max(),
            threads_max: limits::threads_max(),
            tasks: machine::tasks().unwrap_or(0),
            max_open_files: limits::soft_limit("Max open files"),
            open_files: limits::open_files(),
            shm_free: limits::free_space(Path::new("/dev/shm")),
            root_free: limits::free_space(root),
            mem_available: machine::mem_available(),
            cores: std::thread::available_parallelism().map_or(1, |n| n.get() as u64),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A roomy machine: 2 cores, 20 000 open files, 24 GiB.
    fn host() -> Host {
        Host {
            max_user_tasks: Some(96_364),
            user_tasks: 300,
            pid_max: Some(4_194_304),
            threads_max: Some(192_728),
            tasks: 400,
            max_open_files: Some(20_000),
            open_files: 12,
            shm_free: Some(24 << 30),
            root_free: Some(40 << 30),
            mem_available: Some(23 << 30),
            cores: 2,
        }
    }

    fn need(nodes: u64) -> Need {
        Need {
            nodes,
            max_fanout: 3,
            max_ports: 6,
            samples: 11,
            spin: false,
        }
    }

    #[test]
    fn a_hundred_nodes_fit_without_a_word() {
        assert_eq!(processes(&host(), &need(100)), Ok(vec![]));
        assert_eq!(in_process(&host(), &need(100)), Ok(()));
    }

    #[test]
    fn five_thousand_nodes_are_refused_on_open_files() {
        let e = processes(&host(), &need(5_001)).unwrap_err();
        assert_eq!(e.engine, "processes");
        assert!(e.limit.contains("RLIMIT_NOFILE"), "{e}");
        let text = e.to_string();
        assert!(
            text.contains("5001 nodes") && text.contains("ulimit -n 50176"),
            "{text}"
        );
        assert!(text.contains("--engine in-process"), "{text}");
    }

    #[test]
    fn a_low_open_file_limit_refuses_a_small_run() {
        let h = Host {
            max_open_files: Some(64),
            ..host()
        };
        let e = processes(&h, &need(8)).unwrap_err();
        assert!(e.to_string().contains("is 64 with 12 open"), "{e}");
        let unlimited = Host {
            max_open_files: None,
            ..host()
        };
        assert!(processes(&unlimited, &need(5_001)).is_ok());
    }

    #[test]
    fn the_user_process_limit_counts_what_runs_already() {
        let h = Host {
            max_user_tasks: Some(400),
            ..host()
        };
        assert!(processes(&h, &need(80)).is_ok());
        let e = processes(&h, &need(100)).unwrap_err();
        assert!(e.limit.contains("RLIMIT_NPROC"), "{e}");
        assert!(e.to_string().contains("ulimit -u 416"), "{e}");
        let h = Host {
            threads_max: Some(450),
            ..host()
        };
        let e = processes(&h, &need(100)).unwrap_err();
        assert!(e.limit.contains("threads-max"), "{e}");
    }

    #[test]
    fn shared_memory_root_and_memory_are_checked_in_that_order() {
        let small = |shm, root, mem| Host {
            shm_free: Some(shm),
            root_free: Some(root),
            mem_available: Some(mem),
            ..host()
        };
        let big = 1 << 40;
        let e = processes(&small(10 << 20, 1, 1), &need(100)).unwrap_err();
        assert!(e.limit.contains("/dev/shm"), "{e}");
        assert!(e.to_string().contains("they need 30 MiB"), "{e}");
        let e = processes(&small(big, 1 << 20, 1), &need(100)).unwrap_err();
        assert!(e.limit.contains("namespace root"), "{e}");
        let e = processes(&small(big, big, 100 << 20), &need(100)).unwrap_err();
        assert!(e.limit.contains("MemAvailable"), "{e}");
        assert!(e.to_string().contains("400 MiB"), "{e}");
    }

    #[test]
    fn many_nodes_per_core_and_spinning_nodes_are_warned_about() {
        let w = processes(&host(), &need(201)).expect("fits");
        assert!(
            w.len() == 1 && w[0].contains("201 nodes on 2 cores"),
            "{w:?}"
        );
        let spin = Need {
            spin: true,
            ..need(3)
        };
        let w = processes(&host(), &spin).expect("fits");
        assert!(w.len() == 1 && w[0].contains("--wait spin"), "{w:?}");
    }

    #[test]
    fn in_process_memory_grows_with_agents_and_samples() {
        let h = Host {
            mem_available: Some(1 << 30),
            ..host()
        };
        assert!(in_process(&h, &need(5_001)).is_ok());
        let long = Need {
            samples: 4_000_001,
            ..need(5_001)
        };
        let e = in_process(&h, &long).unwrap_err();
        assert_eq!(e.engine, "in-process");
        assert!(
            e.to_string().contains("5000 agents × 4000001 samples"),
            "{e}"
        );
    }

    #[test]
    fn the_real_host_is_read() {
        let h = Host::read(&std::env::temp_dir());
        assert!(h.cores >= 1 && h.open_files >= 3, "{h:?}");
        assert!(h.mem_available.is_some_and(|m| m > 0), "{h:?}");
        assert!(h.shm_free.is_some() && h.max_open_files.is_some(), "{h:?}");
    }
}
