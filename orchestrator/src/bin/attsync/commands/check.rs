//! `attsync check`: validate a scenario and print its network, or the
//! configuration one node would receive.

use super::ScenarioArgs;
use attsync::Error;
use attsync::hosts::{self, Placement};
use attsync::processes::{self, ProcessOptions};
use attsync::scenario::StiffnessCheck;
use std::path::PathBuf;

/// `attsync check SCENARIO [--set K=V]… [--hosts FILE] [--node-config ID] [--no-stiffness-check]`.
#[derive(Debug, clap::Args)]
pub struct Check {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Print instead the JSON configuration node ID (0 = leader) would
    /// receive (PROTOCOL.md; `run` and `iox_root` are placeholders).
    #[arg(long, value_name = "ID")]
    pub node_config: Option<u32>,
    /// Do not refuse a simulation.dt beyond the largest stable RK4 step of
    /// the scenario's loops (docs/stiffness.md): warn, and run anyway.
    #[arg(long)]
    pub no_stiffness_check: bool,
    /// Also print where the nodes would run across machines: each host of
    /// this placement file (HOSTS.toml), the local nodes, the cut edges.
    #[arg(long, value_name = "HOSTS.toml", conflicts_with = "node_config")]
    pub hosts: Option<PathBuf>,
}

/// Prints the network (and its placement, `--hosts`), or node
/// `--node-config`'s configuration. A bad hosts file is refused first.
pub fn exec(a: Check) -> Result<(), Error> {
    let hosts = a.hosts.as_deref().map(hosts::load).transpose()?;
    let loaded = a
        .scenario
        .load(StiffnessCheck::from_flag(a.no_stiffness_check))?;
    let Some(id) = a.node_config else {
        let placement = hosts
            .as_ref()
            .map(|h| Placement::of(h, &loaded.resolved.network))
            .transpose()?;
        print!("{}", attsync::scenario::report::describe(&loaded));
        if let (Some(h), Some(p)) = (&hosts, &placement) {
            print!("{}", hosts::report::describe(&h.path, p));
        }
        // The process ends here: freeing a large scenario's tables one by
        // one (~4 % of `check` at 10⁴ agents) is left to the OS.
        std::mem::forget(loaded);
        return Ok(());
    };
    let net = &loaded.resolved.network;
    let index = attsync::options::node_index(net, id, "--node-config", true, &loaded.file)?;
    let root = attsync::launch::namespace::base_dir().join("RUN");
    let cfg =
        processes::node_configs(net, "RUN", &root, &ProcessOptions::default()).swap_remove(index);
    println!(
        "{}",
        serde_json::to_string_pretty(&cfg).expect("a config serialises")
    );
    Ok(())
}
