//! One run on a host daemon, on a thread of its own: a fresh local
//! iceoryx2 namespace, the nodes placed here started with the rules of a
//! local run, the run's bridges (its cut edges, its telemetry), `Start` and
//! `Stop` relayed into the namespace, exits reported at once; at the end
//! (the orchestrator asks, its liveliness token is gone, or the daemon
//! stops) every node is killed or waited for and everything is removed.

use super::Side;
use super::bridge::Bridges;
pub use super::host_run_error::{RequestError, StartError};
use super::keys;
use super::local::{LocalNs, Shared};
use super::mesh::Sessions;
use super::pieces;
use super::report::{DaemonEvent, Report};
use super::telemetry::{self, End, TelemetryThread};
use super::wire::{Answer, EndReply, EndRequest, HostEvent, NodeEnd, RunOffer, RunRequest};
use crate::trust::Security;
use crate::trust::allow::{Allowlist, Asked};
use iceoryx2::prelude::*;
use launch::namespace::Namespace;
use launch::node_log::last_bytes;
use launch::supervise::{Exit, Launch, Supervisor, describe, find_binaries, tail};
use msgs::bytes::Bytes;
use msgs::config::Contention;
use msgs::iox::iox;
use msgs::{ControlCommand, ControlMsg};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::query::Query;

/// What the daemon tells a run's thread.
pub enum Command {
    /// The orchestrator ends the run; reply to the query.
    End(EndRequest, Query),
    /// The daemon stops: kill everything.
    Abort,
}

/// Longest wait for the nodes to exit after `Stop`.
const STOP_TIMEOUT: Duration = Duration::from_secs(10);
/// Longest wait for killed nodes to be gone.
const KILL_TIMEOUT: Duration = Duration::from_secs(5);
/// How long the run's orchestrator may take to show its liveliness token.
const ORCHESTRATOR_GRACE: Duration = Duration::from_secs(5);
/// The run thread's poll period.
const TICK: Duration = Duration::from_millis(5);

/// A run's resources, dropped in this order: bridges, ports, processes, namespace.
struct Resources {
    _telemetry: TelemetryThread,
    _bridges: Bridges,
    _sessions: Sessions,
    control: iceoryx2::port::publisher::Publisher<ipc::Service, ControlMsg, ()>,
    _node: iceoryx2::node::Node<ipc::Service>,
    sup: Supervisor,
    ns: Namespace,
}

/// The nodes of a run here: (id, name, log file).
type Nodes = Vec<(u32, String, PathBuf)>;

/// Starts `req`'s nodes and bridges; an error says why, for the orchestrator.
fn start(
    session: &zenoh::Session,
    req: &RunRequest,
    shared: &Shared,
    security: &Security,
) -> Result<(Resources, Nodes), StartError> {
    let (agent_bin, leader_bin) = find_binaries()?;
    let sessions = Sessions::dial(session, &req.host, &req.dial, security)?;
    let ns = Namespace::create().map_err(StartError::Namespace)?;
    let logs = ns.dir().join("logs");
    std::fs::create_dir_all(&logs).map_err(io_at(&logs))?;
    let first = req.nodes.first().ok_or(StartError::NoNodes)?;
    let local = LocalNs {
        run: ns.run().to_string(),
        dir: ns.dir().to_owned(),
        limits: first.config.limits,
        stage_timeout: Duration::from_secs_f64(first.config.stage_timeout),
        realtime: first.config.realtime.is_some(),
    };
    let node = local.node("host")?;
    let control = msgs::open::control(&node, &local.run, &local.limits)?
        .publisher_builder()
        .create()
        .map_err(iox("control publisher"))?;
    let me = Side::Host(req.host.clone());
    let bridges = Bridges::start(&sessions, &local, &req.run, &me, &req.links, shared);
    let ids = req.nodes.iter().map(|n| n.config.id).collect();
    let telemetry = telemetry::start(
        End::Forward,
        session,
        &local,
        (&req.run, &req.host),
        ids,
        shared,
    );
    let mut sup = Supervisor::new().map_err(StartError::Runtime)?;
    let mut nodes = Vec::new();
    for (i, n) in req.nodes.iter().enumerate() {
        let mut c = n.config.clone();
        c.run.clone_from(&local.run);
        c.iox_root = local.dir.to_string_lossy().into_owned();
        c.contention = Contention::Waiter; // no placer watches this machine
        let file = local.dir.join(launch::namespace::node_config_file(c.id));
        c.write(&file)
            .map_err(|e| io_at(&file)(std::io::Error::other(e)))?;
        let log = logs.join(launch::node_log::node_log_file(&n.name));
        let launch = match &n.plugin {
            Some(p) => Launch::Plugin {
                command: &p.command,
                env: &p.env,
                dir: &p.dir,
            },
            None => Launch::Builtin(if c.id == 0 { &leader_bin } else { &agent_bin }),
        };
        sup.spawn_node(i, &launch, &file, &log)
            .map_err(io_at(&log))?;
        nodes.push((c.id, n.name.clone(), log));
    }
    let r = Resources {
        _telemetry: telemetry,
        _bridges: bridges,
        _sessions: sessions,
        control,
        _node: node,
        sup,
        ns,
    };
    Ok((r, nodes))
}

/// Maps an I/O error at `path` to a [`StartError::Io`].
fn io_at(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> StartError + use<> {
    let path = path.to_owned();
    move |source| StartError::Io { path, source }
}

/// Longest wait for the orchestrator to hand over a run's request.
const FETCH_TIMEOUT: Duration = Duration::from_secs(10);

/// Fetches the request of the run `offer` offers (from the orchestrator's
/// `attsync/<run>/request/<host>`, in pieces), then [`serve`]s it.
pub fn serve_offer(
    session: zenoh::Session,
    offer: RunOffer,
    reply: Query,
    commands: Receiver<Command>,
    (allow, report, security): (&Allowlist, &Report, &Security),
) {
    match fetch(&session, &offer).and_then(|r| admit(r, allow)) {
        Ok(req) => serve(session, req, reply, (commands, report, security)),
        Err(e) => {
            tracing::warn!(run = %offer.run, "refused: {e}");
            report(DaemonEvent::Refused {
                run: offer.run.clone(),
                why: e.to_string(),
            });
            answer(&reply, &Answer::Err(e.to_string()));
        }
    }
}

/// `req` with each plug-in's program and directory as [`Allowlist::admit`]
/// checked them (canonical), or the first refusal, naming the host, the
/// node and its command (nothing has started).
fn admit(mut req: RunRequest, allow: &Allowlist) -> Result<RunRequest, RequestError> {
    for n in &mut req.nodes {
        let Some(p) = &mut n.plugin else { continue };
        let asked = Asked {
            command: &p.command,
            env: &p.env,
            dir: &p.dir,
        };
        let admitted = allow
            .admit(&asked)
            .map_err(|reason| RequestError::Refused {
                host: req.host.clone(),
                node: n.name.clone(),
                command: p.command.clone(),
                reason,
            })?;
        p.command[0] = admitted.program.to_string_lossy().into_owned();
        p.dir = admitted.dir;
    }
    Ok(req)
}

/// The request of the run `offer` offers.
fn fetch(session: &zenoh::Session, offer: &RunOffer) -> Result<RunRequest, RequestError> {
    let replies = (session.get(super::keys::request(&offer.run, &offer.host)))
        .consolidation(zenoh::query::ConsolidationMode::None)
        .timeout(FETCH_TIMEOUT)
        .wait()
        .map_err(|e| RequestError::Zenoh(e.to_string()))?;
    let bytes = pieces::collect(&replies)?;
    decode_request(&bytes, offer)
}

/// The run request in `bytes` (put back together from its pieces) for the
/// run `offer` offered: its JSON, for that run and host, each node's values
/// usable (`check_node`).
///
/// # Errors
/// [`RequestError`]: bad JSON, another run or host, or a node that cannot start.
pub fn decode_request(bytes: &[u8], offer: &RunOffer) -> Result<RunRequest, RequestError> {
    let req: RunRequest = serde_json::from_slice(bytes)?;
    if (req.run.as_str(), req.host.as_str()) != (offer.run.as_str(), offer.host.as_str()) {
        return Err(RequestError::Mismatch {
            offered_run: offer.run.clone(),
            offered_host: offer.host.clone(),
            run: req.run,
            host: req.host,
        });
    }
    req.nodes.iter().try_for_each(check_node)?;
    Ok(req)
}

/// Why node `n` of a request cannot be started here: a name that is not a
/// file name of its own (its log is `<name>.log` in the run's directory),
/// or timeouts and a real-time factor outside what `attsync run` accepts
/// (`Duration::from_secs_f64` panics on a negative or huge one).
fn check_node(n: &super::wire::RemoteNode) -> Result<(), RequestError> {
    let bad = |e: &dyn std::fmt::Display| RequestError::BadNode {
        node: n.name.clone(),
        why: e.to_string(),
    };
    let safe = |ch: char| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_';
    if n.name.is_empty() || !n.name.chars().all(safe) {
        return Err(bad(&"its name is not letters, digits, `-`, `_`"));
    }
    let c = &n.config;
    launch::bounds::seconds("stage_timeout", c.stage_timeout).map_err(|e| bad(&e))?;
    launch::bounds::seconds("start_timeout", c.start_timeout).map_err(|e| bad(&e))?;
    match c.realtime {
        Some(f) => launch::bounds::realtime("realtime", f).map_err(|e| bad(&e)),
        None => Ok(()),
    }
}

/// Serves run `req` until it ends; `reply` gets the answer to the run request.
pub fn serve(
    session: zenoh::Session,
    req: RunRequest,
    reply: Query,
    (commands, report, security): (Receiver<Command>, &Report, &Security),
) {
    let shared = Shared::default();
    // Declared before the answer, so that no command of the run is missed.
    let Some(ports) = RunPorts::declare(&session, &req) else {
        let why = "zenoh: cannot declare the run's subscribers";
        answer(&reply, &Answer::Err(why.into()));
        return;
    };
    let (mut res, nodes) = match start(&session, &req, &shared, security) {
        Ok(x) => x,
        Err(e) => {
            tracing::warn!(run = %req.run, "cannot start the run: {e}");
            report(DaemonEvent::Refused {
                run: req.run.clone(),
                why: e.to_string(),
            });
            answer(&reply, &Answer::Err(e.to_string()));
            return;
        }
    };
    report(DaemonEvent::Started {
        run: req.run.clone(),
        nodes: req.nodes.iter().map(|n| n.name.clone()).collect(),
        dialled: req.dial.iter().map(|p| p.host.clone()).collect(),
    });
    answer(&reply, &Answer::Ok(()));
    drop(reply); // its final reply: the orchestrator's query completes
    tracing::info!(run = %req.run, nodes = nodes.len(), "run started");
    let mut exits: Vec<Option<Exit>> = (0..nodes.len()).map(|_| None).collect();
    let end = watch(
        &req, &ports, &mut res, &nodes, &shared, &mut exits, &commands,
    );
    let kill = end.as_ref().is_none_or(|(e, _)| e.kill);
    let (logs, leftovers) = wind_down(&req, res, &nodes, &mut exits, kill);
    if let Some((_, q)) = end {
        reply_end(&q, &nodes, exits, logs, leftovers);
    }
}

/// The run's Zenoh ports on this host: the orchestrator's commands, this
/// host's events, and whether the orchestrator is (still) alive.
struct RunPorts {
    control: zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<zenoh::sample::Sample>>,
    events: zenoh::pubsub::Publisher<'static>,
    _watch: zenoh::pubsub::Subscriber<()>,
    alive: Arc<AtomicBool>,
    lost: Arc<AtomicBool>,
}

impl RunPorts {
    /// Declares them (`None` if Zenoh refuses one).
    fn declare(session: &zenoh::Session, req: &RunRequest) -> Option<RunPorts> {
        let control = session.declare_subscriber(keys::control(&req.run)).wait();
        let events = session
            .declare_publisher(keys::events(&req.run, &req.host))
            .wait();
        let (alive, lost) = (
            Arc::new(AtomicBool::new(false)),
            Arc::new(AtomicBool::new(false)),
        );
        let (a, l) = (alive.clone(), lost.clone());
        let watch = session
            .liveliness()
            .declare_subscriber(keys::orchestrator_alive(&req.run))
            .history(true)
            .callback(move |s| match s.kind() {
                zenoh::sample::SampleKind::Put => a.store(true, Ordering::Relaxed),
                zenoh::sample::SampleKind::Delete => l.store(true, Ordering::Relaxed),
            })
            .wait();
        let (Ok(control), Ok(events), Ok(_watch)) = (control, events, watch) else {
            return None;
        };
        Some(RunPorts {
            control,
            events,
            _watch,
            alive,
            lost,
        })
    }

    /// Sends a [`HostEvent`] to the orchestrator.
    fn put(&self, e: &HostEvent) {
        let _ = self
            .events
            .put(serde_json::to_vec(e).expect("serialises"))
            .wait();
    }
}

/// The running phase: reports exits and the first failure, relays the
/// orchestrator's control messages, until the orchestrator ends the run
/// (`Some`), or aborts it or is gone (`None`).
fn watch(
    req: &RunRequest,
    ports: &RunPorts,
    res: &mut Resources,
    nodes: &Nodes,
    shared: &Shared,
    exits: &mut [Option<Exit>],
    commands: &Receiver<Command>,
) -> Option<(EndRequest, Query)> {
    let began = Instant::now();
    let mut failed_said = false;
    loop {
        while let Some(e) = res.sup.try_exit() {
            let (id, _, log) = &nodes[e.index];
            ports.put(&HostEvent::Exited {
                id: *id,
                status: describe(&e.status),
                clean: matches!(&e.status, Ok(s) if s.success()),
                tail: bounded(tail(log, 10)),
            });
            let k = e.index;
            exits[k] = Some(e);
        }
        relay_control(ports, res);
        if let (Some(f), false) = (shared.failure(), failed_said) {
            failed_said = true;
            ports.put(&HostEvent::Failed(bounded(f)));
        }
        let gone = ports.lost.load(Ordering::Relaxed)
            || (!ports.alive.load(Ordering::Relaxed) && began.elapsed() > ORCHESTRATOR_GRACE);
        if gone {
            tracing::warn!(run = %req.run, "the orchestrator is gone: cleaning the run up");
            return None;
        }
        match commands.recv_timeout(TICK) {
            Ok(Command::End(e, q)) => {
                relay_control(ports, res);
                if !e.kill {
                    // A clean end comes after the orchestrator's `Stop`,
                    // but on another Zenoh path that may overtake it.
                    let _ = res.control.send_copy(ControlMsg::new(ControlCommand::Stop));
                }
                return Some((e, q));
            }
            Ok(Command::Abort) | Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return None;
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
        }
    }
}

/// Relays the orchestrator's control messages received so far into the namespace.
fn relay_control(ports: &RunPorts, res: &Resources) {
    while let Ok(Some(s)) = ports.control.try_recv() {
        if let Ok(m) = ControlMsg::from_bytes(&s.payload().to_bytes()) {
            let _ = res.control.send_copy(m);
        }
    }
}

/// Stops the nodes (killed unless the run ended cleanly), collects their
/// exits and the ends of their logs, removes the namespace; the logs'
/// ends and what was left.
fn wind_down(
    req: &RunRequest,
    mut res: Resources,
    nodes: &Nodes,
    exits: &mut [Option<Exit>],
    kill: bool,
) -> (Vec<(Vec<u8>, u64)>, Vec<String>) {
    if kill {
        res.sup.kill_all();
    }
    let timeout = if kill { KILL_TIMEOUT } else { STOP_TIMEOUT };
    for e in res.sup.wait_all(timeout) {
        let k = e.index;
        exits[k] = Some(e);
    }
    let logs: Vec<(Vec<u8>, u64)> = nodes.iter().map(|(_, _, log)| last_bytes(log)).collect();
    let local_run = res.ns.run().to_string();
    drop(res);
    let leftovers = Namespace::leftovers(&local_run)
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    tracing::info!(run = %req.run, "run ended, namespace removed");
    (logs, leftovers)
}

/// Longest text of an event, bytes: JSON escapes it to at most 6× that,
/// far under one Zenoh batch (events are puts, not sent in [`pieces`]).
const EVENT_TEXT: usize = 8 << 10;

/// `s`, or its last [`EVENT_TEXT`] bytes (from a character's start) after
/// a mark saying it was cut.
fn bounded(s: String) -> String {
    if s.len() <= EVENT_TEXT {
        return s;
    }
    let mut start = s.len() - EVENT_TEXT;
    while !s.is_char_boundary(start) {
        start += 1;
    }
    format!("[…] {}", &s[start..])
}

/// The answer to the orchestrator's end request: each node's exit and the
/// end of its log (bounded: [`last_bytes`]).
fn reply_end(
    q: &Query,
    nodes: &Nodes,
    exits: Vec<Option<Exit>>,
    logs: Vec<(Vec<u8>, u64)>,
    leftovers: Vec<String>,
) {
    let reply = EndReply {
        nodes: (nodes.iter().zip(exits).zip(logs))
            .map(|(((id, _, _), e), (log, cut))| NodeEnd {
                id: *id,
                status: e
                    .as_ref()
                    .map_or("still running".into(), |e| describe(&e.status)),
                clean: e.is_some_and(|e| matches!(&e.status, Ok(s) if s.success())),
                log,
                cut,
            })
            .collect(),
        leftovers,
    };
    pieces::reply(q, &serde_json::to_vec(&reply).expect("serialises"));
}

/// Replies `a` to query `q` (in pieces, like every reply but a ping's).
pub fn answer(q: &Query, a: &Answer) {
    pieces::reply(q, &serde_json::to_vec(a).expect("serialises"));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_events_text_is_bounded_from_a_characters_start() {
        assert_eq!(bounded("short".into()), "short");
        let long = "é".repeat(EVENT_TEXT); // 2 bytes each
        let b = bounded(long);
        assert!(b.starts_with("[…] é"), "{}", &b[..10]);
        assert!(b.len() <= EVENT_TEXT + 8);
        let json = serde_json::to_vec(&HostEvent::Failed("\u{1}".repeat(10 * EVENT_TEXT))).unwrap();
        assert!(json.len() > 64 << 10, "the case the bound is for");
        let json = serde_json::to_vec(&HostEvent::Failed(bounded("\u{1}".repeat(10 * EVENT_TEXT))));
        assert!(json.unwrap().len() < 60 << 10);
    }
}
