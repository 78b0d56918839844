//! `attsync host`: the daemon of one machine of a run across hosts, and
//! `attsync host --gen-certs DIR`: a lab's certificates for it.

use attsync::Error;
use attsync::interrupt::Interrupt;
use attsync::remote::daemon::{self, HostError, HostOptions};
use attsync::trust::allow::Allowlist;
use attsync::trust::certs::{self, Subject};
use attsync::trust::{self, INSECURE_WARNING, Security};
use std::path::PathBuf;

/// `attsync host --name NAME --listen ENDPOINT [--connect ENDPOINT]…
/// (--ca CA --cert CERT --key KEY | --insecure) [--allow-plugin PATH]…`,
/// or `attsync host --gen-certs DIR [--for NAME[=ADDR,…]]…`.
#[derive(Debug, clap::Args)]
pub struct Host {
    /// This host's name, as HOSTS.toml's `[[host]] name`.
    #[arg(long, required_unless_present = "gen_certs")]
    pub name: Option<String>,
    /// Endpoint to listen on, in Zenoh's syntax (`quic/0.0.0.0:7447`, or
    /// `tcp/…` with --insecure); repeatable.
    #[arg(long, required_unless_present = "gen_certs")]
    pub listen: Vec<String>,
    /// Endpoint of another host to dial for good; repeatable. Not needed:
    /// a run dials the peers it needs from HOSTS.toml (docs/hosts.md).
    #[arg(long)]
    pub connect: Vec<String>,
    /// The lab's CA certificate (PEM): only peers with a certificate it
    /// signed may connect (mutual TLS).
    #[arg(long, value_name = "CA.pem")]
    pub ca: Option<PathBuf>,
    /// This host's certificate (PEM, signed by the CA, naming the
    /// addresses it is dialled at).
    #[arg(long, value_name = "HOST.pem")]
    pub cert: Option<PathBuf>,
    /// This host's private key (PEM).
    #[arg(long, value_name = "HOST.key")]
    pub key: Option<PathBuf>,
    /// Plain TCP, nobody authenticated, nothing encrypted: anyone who
    /// reaches the port can start a run here (warned about).
    #[arg(long)]
    pub insecure: bool,
    /// A plug-in program this daemon may start (an executable file; the
    /// built-in nodes always); repeatable. A run asking for any other is
    /// refused before anything starts.
    #[arg(long, value_name = "PATH")]
    pub allow_plugin: Vec<PathBuf>,
    /// Make the lab's CA in DIR (or reuse the one there) and a certificate
    /// and key for each --for, then exit.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["name", "listen", "insecure"])]
    pub gen_certs: Option<PathBuf>,
    /// With --gen-certs: a host or user, `NAME=ADDR[,ADDR…]` (the IP
    /// addresses or DNS names it is dialled at) or `NAME`; repeatable.
    #[arg(long = "for", value_name = "NAME[=ADDR,…]", requires = "gen_certs")]
    pub subjects: Vec<String>,
}

/// Serves until SIGINT, SIGTERM or SIGHUP (exit 0); or makes certificates.
pub fn exec(a: Host, interrupt: &Interrupt) -> Result<(), Error> {
    if let Some(dir) = &a.gen_certs {
        return gen_certs(dir, &a.subjects);
    }
    let security = trust::choose(a.ca, a.cert, a.key, a.insecure, trust::FLAGS)?;
    let opts = HostOptions {
        name: a.name.unwrap_or_default(),
        listen: a.listen,
        connect: a.connect,
        security,
        allow: Allowlist::new(&a.allow_plugin)?,
    };
    opts.check()?;
    if opts.security == Security::Insecure {
        eprintln!("attsync host: warning: {INSECURE_WARNING}");
    }
    interrupt.arm();
    // One line when it listens, one per run it starts or refuses.
    let print = |e: attsync::remote::report::DaemonEvent| {
        use std::io::Write;
        let mut out = std::io::stdout().lock();
        let _ = writeln!(out, "{e}");
        let _ = out.flush();
    };
    daemon::serve(&opts, interrupt.flag(), std::sync::Arc::new(print))?;
    Ok(())
}

/// `--gen-certs DIR --for …`: prints what it wrote.
fn gen_certs(dir: &std::path::Path, subjects: &[String]) -> Result<(), Error> {
    let subjects = (subjects.iter())
        .map(|s| s.parse::<Subject>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| HostError::Invalid(format!("--for: {e}")))?;
    let issued = certs::generate(dir, &subjects)?;
    let ca = if issued.new_ca { "made" } else { "kept" };
    println!("{}: the lab's CA ({ca})", dir.join("ca.pem").display());
    for f in &issued.files {
        println!("{}", f.display());
    }
    Ok(())
}
