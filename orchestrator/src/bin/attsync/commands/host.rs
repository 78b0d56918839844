//! `attsync host`: the daemon of one machine of a run across hosts.

use attsync::Error;
use attsync::interrupt::Interrupt;
use attsync::remote::daemon::{self, HostOptions};

/// `attsync host --name NAME --listen ENDPOINT [--connect ENDPOINT]…`.
#[derive(Debug, clap::Args)]
pub struct Host {
    /// This host's name, as HOSTS.toml's `[[host]] name`.
    #[arg(long)]
    pub name: String,
    /// Endpoint to listen on, in Zenoh's syntax (`tcp/0.0.0.0:7447`); repeatable.
    #[arg(long, required = true)]
    pub listen: Vec<String>,
    /// Endpoint of another host to dial (every pair of hosts that share a
    /// cut edge must be connected: dial the hosts started before); repeatable.
    #[arg(long)]
    pub connect: Vec<String>,
}

/// Serves until SIGINT, SIGTERM or SIGHUP (exit 0).
pub fn exec(a: Host, interrupt: &Interrupt) -> Result<(), Error> {
    let opts = HostOptions {
        name: a.name,
        listen: a.listen,
        connect: a.connect,
    };
    interrupt.arm();
    daemon::serve(&opts, interrupt.flag())?;
    Ok(())
}
