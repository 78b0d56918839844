//! `attsync host`: the daemon of one machine. One Zenoh session (peer,
//! explicit endpoints, mutual TLS unless `--insecure`: [`crate::trust`]), a
//! liveliness token `attsync/host/<name>/alive`, and three queryables:
//! `ping`, `run` (start a run's nodes here, one thread per run, runs
//! isolated by run id; plug-ins only if allowed, [`Allowlist`]) and `end`.
//! It runs until SIGINT, SIGTERM or SIGHUP, then kills and cleans up every
//! run it still serves.

use super::host_run::{self, Command};
use super::keys;
use super::report::{DaemonEvent, Report};
use super::wire::{Answer, EndRequest, RunOffer};
use super::zconfig::{self, ConfigError};
use crate::trust::Security;
use crate::trust::allow::Allowlist;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Sender};
use std::thread::JoinHandle;
use std::time::Duration;
use thiserror::Error;
use zenoh::Wait;
use zenoh::query::Query;

/// What `attsync host` is told.
#[derive(Debug, Clone)]
pub struct HostOptions {
    /// The host's name (`[[host]] name` in HOSTS.toml).
    pub name: String,
    /// Endpoints it listens on.
    pub listen: Vec<String>,
    /// Endpoints of other hosts it dials.
    pub connect: Vec<String>,
    /// How its links are secured (every endpoint's protocol must match).
    pub security: Security,
    /// The plug-in programs it may start.
    pub allow: Allowlist,
}

/// The daemon could not start or serve.
#[derive(Debug, Error)]
pub enum HostError {
    /// A bad option (exit 2).
    #[error("{0}")]
    Invalid(String),
    /// Zenoh's configuration or session.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A Zenoh declaration failed.
    #[error("zenoh: {0}")]
    Zenoh(String),
}

impl HostError {
    /// A bad option or endpoint: the user's input is at fault (exit code 2).
    #[must_use]
    pub fn is_invalid(&self) -> bool {
        matches!(
            self,
            Self::Invalid(_) | Self::Config(ConfigError::Endpoint { .. })
        )
    }
}

/// Checks `name`: a Zenoh key chunk of letters, digits, `-` and `_`.
///
/// # Errors
/// [`HostError::Invalid`] naming `flag`.
pub fn check_name(flag: &str, name: &str) -> Result<(), HostError> {
    let ok = !name.is_empty()
        && (name.chars()).all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if ok {
        Ok(())
    } else {
        Err(HostError::Invalid(format!(
            "{flag}: `{name}` is not a host name (letters, digits, `-`, `_`)"
        )))
    }
}

impl HostOptions {
    /// Checks every option, naming the first bad one.
    pub fn check(&self) -> Result<(), HostError> {
        check_name("--name", &self.name)?;
        if self.listen.is_empty() {
            return Err(HostError::Invalid("--listen: at least one endpoint".into()));
        }
        for e in &self.listen {
            zconfig::check_endpoint("--listen", e, &self.security)?;
        }
        for e in &self.connect {
            zconfig::check_endpoint("--connect", e, &self.security)?;
        }
        Ok(())
    }
}

fn zerr(e: impl std::fmt::Display) -> HostError {
    HostError::Zenoh(e.to_string())
}

/// The daemon's answer to a ping.
#[must_use]
pub fn ping_text(name: &str) -> String {
    format!("attsync host {name} {}", env!("CARGO_PKG_VERSION"))
}

/// Serves until `stop` is set, telling `report` that it listens and each
/// run it starts or refuses.
pub fn serve(opts: &HostOptions, stop: &AtomicBool, report: Report) -> Result<(), HostError> {
    opts.check()?;
    let session = zconfig::open(&opts.listen, &opts.connect, &opts.security)?;
    let name = opts.name.clone();
    let _token = (session.liveliness())
        .declare_token(keys::host_alive(&name))
        .wait()
        .map_err(zerr)?;
    let text = ping_text(&name);
    let _ping = (session.declare_queryable(keys::ping(&name)))
        .callback(move |q| {
            let _ = q.reply(q.key_expr().clone(), text.clone()).wait();
        })
        .wait()
        .map_err(zerr)?;
    let run_q = session
        .declare_queryable(keys::run(&name))
        .wait()
        .map_err(zerr)?;
    let end_q = session
        .declare_queryable(keys::end(&name))
        .wait()
        .map_err(zerr)?;
    let allowed: Vec<_> = opts.allow.programs().iter().map(|p| p.display()).collect();
    tracing::info!(host = %name, listen = ?opts.listen, connect = ?opts.connect,
        security = opts.security.name(), plugins = ?allowed, "serving");
    report(DaemonEvent::Listening {
        name: name.clone(),
        listen: opts.listen.clone(),
        connect: opts.connect.clone(),
    });
    let mut runs: HashMap<String, (Sender<Command>, JoinHandle<()>)> = HashMap::new();
    while !stop.load(Ordering::Relaxed) {
        if let Ok(Some(q)) = run_q.recv_timeout(Duration::from_millis(50)) {
            accept(&session, (&name, opts, &report), q, &mut runs);
        }
        while let Ok(Some(q)) = end_q.try_recv() {
            route_end(q, &runs);
        }
        runs.retain(|_, (_, t)| !t.is_finished());
    }
    tracing::info!(host = %name, runs = runs.len(), "stopping");
    for (tx, t) in runs.into_values() {
        let _ = tx.send(Command::Abort);
        let _ = t.join();
    }
    Ok(())
}

/// The payload of `q` as `T`, or the reason it is not one.
fn payload<T: serde::de::DeserializeOwned>(q: &Query) -> Result<T, serde_json::Error> {
    let b = q
        .payload()
        .map(|p| p.to_bytes().into_owned())
        .unwrap_or_default();
    serde_json::from_slice(&b)
}

/// Refuses query `q`, saying `why`.
fn refuse(q: &Query, why: String) {
    host_run::answer(q, &Answer::Err(why));
}

/// Starts the run offered by `q` on its own thread, which fetches the
/// run's request and checks its plug-ins against `allow`
/// ([`host_run::serve_offer`]).
fn accept(
    session: &zenoh::Session,
    (name, opts, report): (&str, &HostOptions, &Report),
    q: Query,
    runs: &mut HashMap<String, (Sender<Command>, JoinHandle<()>)>,
) {
    let req: RunOffer = match payload(&q) {
        Ok(r) => r,
        Err(e) => return refuse(&q, format!("a bad request: {e}")),
    };
    if req.host != name {
        return refuse(&q, format!("this is host {name}, not {}", req.host));
    }
    if runs.contains_key(&req.run) {
        return refuse(&q, format!("run {} is already here", req.run));
    }
    let (tx, rx) = mpsc::channel();
    let s = session.clone();
    let run = req.run.clone();
    let (allow, report, security) = (opts.allow.clone(), report.clone(), opts.security.clone());
    let t = std::thread::spawn(move || {
        host_run::serve_offer(s, req, q, rx, (&allow, &report, &security));
    });
    runs.insert(run, (tx, t));
}

/// Hands end request `q` to its run's thread.
fn route_end(q: Query, runs: &HashMap<String, (Sender<Command>, JoinHandle<()>)>) {
    let req: EndRequest = match payload(&q) {
        Ok(r) => r,
        Err(e) => return refuse(&q, format!("a bad request: {e}")),
    };
    match runs.get(&req.run) {
        Some((tx, _)) => {
            if let Err(mpsc::SendError(Command::End(_, q))) = tx.send(Command::End(req, q)) {
                refuse(&q, "the run has ended".into());
            }
        }
        None => refuse(&q, format!("no run {} here", req.run)),
    }
}
