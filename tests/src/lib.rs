//! Helpers shared by attsync's cross-process end-to-end tests (`tests/*.rs`).
//!
//! The tests run the real binaries — `attsync`, `attsync-leader` and
//! `attsync-agent` — as OS processes. They are taken from the cargo target
//! directory the test executable was built into (`target/<profile>/`, the
//! parent of `target/<profile>/deps/<test>-<hash>`), so build them first:
//! `cargo build --release --workspace` (`cargo test --workspace --release`
//! builds them too). A binary older than its sources is not detected.
//!
//! # Layout
//! - `workspace.rs`: [`bin`], [`bin_dir`] (the built binaries), [`scenario`],
//!   [`paper`] (scenario files), [`copy_executable`] to run a copy of a binary.
//! - `sandbox.rs`: [`Sandbox`], a temporary directory per test, kept (and its
//!   path printed) if the test fails.
//! - `command.rs`: [`Attsync`], an `attsync` command line ([`run_args`] builds
//!   the usual `run` arguments; [`reference_run`]: the in-process run that
//!   others are compared with).
//! - `running.rs`: [`Running`], a started `attsync`, waited for with a bound
//!   ([`Running::wait`]; [`Running::once_stepping`]: until a node steps)
//!   and killed together with its node processes if the
//!   test gives up on it; [`Finished`]: its exit status, output, the iceoryx2
//!   runs it owned, and what it left behind ([`Finished::leftovers`]).
//! - `namespace.rs`: run namespaces (`<tmp>/attsync-iox2/<run>/` with an
//!   `owner` file holding the orchestrator's pid, shared memory
//!   `/dev/shm/as<run>_*`): [`iox_base`], [`owned_runs`], [`run_leftovers`],
//!   [`run_processes`], [`node_pid`], [`owned_run`], [`started_by`] (the
//!   processes an orchestrator started, by their environment); [`signal`], [`kill9`].
//! - `results.rs`: [`read`], [`assert_same_file`], [`assert_same_bytes`],
//!   [`csv_agents`], [`csv_rows`], [`summary`], [`summary_without`],
//!   [`assert_same_results`], [`staging_dir`].
//! - `hosts.rs`: [`HostSandbox`], a simulated host (a mount namespace with
//!   its own tmpfs on `/dev/shm` and its own `TMPDIR`) to start commands in
//!   ([`HostProcess`]), its `/dev/shm` listed for leftovers; [`free_port`];
//!   [`HostSandbox::networked`]: with a network namespace of its own too.
//! - `netns.rs`: [`Veth`], the veth pair from our network namespace to a
//!   host's (a /30 of 10.231.0.0/16 per pair, `tc … netem delay`),
//!   [`link_exists`].
//! - `delay_relay.rs`: [`DelayRelay`], a TCP relay adding a fixed delay each
//!   way (the real delay where the kernel has no netem).
//! - `delayed_host.rs`: [`DelayedHost`], a [`Daemon`] in a networked host
//!   whose link has a real delay (netem, else a [`DelayRelay`]).
//! - `conform.rs`: [`run_conform`] (`attsync conform` of a candidate),
//!   [`rule_line`] (one rule's verdict in its report).
//! - `daemon.rs`: [`Daemon`], an `attsync host` in a [`HostSandbox`] of its own;
//!   [`hosts_file`] (a HOSTS.toml of daemons), [`run_on_hosts`], [`assert_hosts_clean`],
//!   [`assert_serves_again`] (the daemons serve the next run, clean).
//! - `python.rs`: [`require_iceoryx2_module`], [`conform_python`] (agents
//!   written in Python).
//! - `variant.rs`: scenario files edited for a test: [`with_agent_lines`]
//!   (an agent given lines of its own), [`sh_plugin`], [`broken_agent`].
//! - this file: [`wait_until`], [`RUN_TIMEOUT`].
//!
//! Every wait is bounded ([`wait_until`], [`RUN_TIMEOUT`]); nothing asserts
//! wall-clock durations.

pub mod certs;
mod command;
mod conform;
mod daemon;
mod delay_relay;
mod delayed_host;
mod hosts;
mod namespace;
mod netns;
mod python;
mod results;
mod running;
mod sandbox;
mod variant;
mod workspace;

pub use command::{Attsync, reference_run, run_args};
pub use conform::{rule_line, run_conform};
pub use daemon::{Daemon, assert_hosts_clean, assert_serves_again, hosts_file, run_on_hosts};
pub use delay_relay::DelayRelay;
pub use delayed_host::{DAEMON_PORT, DelayKind, DelayedHost};
pub use hosts::{HostProcess, HostSandbox, free_port, free_udp_port};
pub use namespace::{
    iox_base, kill9, node_pid, owned_run, owned_runs, run_leftovers, run_processes, signal,
    started_by,
};
pub use netns::{Veth, link_exists};
pub use python::{conform_python, require_iceoryx2_module, require_python_modules};
pub use results::{
    assert_same_bytes, assert_same_file, assert_same_results, csv_agents, csv_rows, read,
    staging_dir, summary, summary_without,
};
pub use running::{Finished, Running};
pub use sandbox::Sandbox;
pub use variant::{broken_agent, sh_plugin, with_agent_lines};
pub use workspace::{bin, bin_dir, copy_executable, paper, scenario};

use std::time::{Duration, Instant};

/// Longest a single `attsync` invocation may take before the test fails
/// (generous: the machine may be shared by several test binaries).
pub const RUN_TIMEOUT: Duration = Duration::from_secs(300);

/// Polls `f` every `poll` until it returns `Some`, at most `timeout`.
pub fn wait_until<T>(
    timeout: Duration,
    poll: Duration,
    mut f: impl FnMut() -> Option<T>,
) -> Option<T> {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(x) = f() {
            return Some(x);
        }
        if Instant::now() > deadline {
            return None;
        }
        std::thread::sleep(poll);
    }
}
