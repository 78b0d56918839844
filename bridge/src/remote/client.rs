//! The orchestrator's side of a run placed over hosts ([`Remote`]): one
//! Zenoh session dialling every host, a liveliness token for the run, a
//! watch on the hosts' tokens, the run handed to each host, the bridges of
//! the cut edges touching local nodes, one telemetry sink per host, `Start`
//! and `Stop` relayed, each host's node exits and failures as they happen,
//! and at the end every host's exits and logs.

use super::RemoteError;
use super::Side;
use super::bridge::Bridges;
use super::keys;
use super::local::{LocalNs, Shared};
use super::mesh::{self, Sessions};
use super::pieces;
use super::plan::{Plan, links};
use super::telemetry::{self, End, TelemetryThread};
use super::wire::{
    Answer, EndReply, EndRequest, HostEvent, NodeEnd, RemoteNode, RunOffer, RunRequest,
};
use super::zconfig;
use launch::node_log::cut_note;
use launch::site_exit::SiteExit;
use msgs::ControlMsg;
use msgs::bytes::Bytes;
use msgs::config::NodeConfig;
use std::io::Write;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::handlers::{FifoChannel, FifoChannelHandler};
use zenoh::pubsub::Subscriber;
use zenoh::query::ConsolidationMode;
use zenoh::sample::Sample;

/// How long a host may take to answer its first ping (its daemon starting,
/// the connection being dialled).
pub const REACH_TIMEOUT: Duration = Duration::from_secs(5);
/// Longest wait for a host to start its nodes, or to end them.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(30);

/// The orchestrator's connection to the hosts of one run. Dropping it stops
/// the bridges, then withdraws the run's token (the hosts clean up).
pub struct Remote {
    sinks: Vec<TelemetryThread>,
    bridges: Option<Bridges>,
    shared: Shared,
    events: Subscriber<FifoChannelHandler<Sample>>,
    lost: Arc<Mutex<Vec<String>>>,
    _watch: Subscriber<()>,
    _token: zenoh::liveliness::LivelinessToken,
    plan: Plan,
    run: String,
    /// Hosts that accepted the run (and must be asked to end it).
    started: Vec<String>,
    session: zenoh::Session,
}

impl std::fmt::Debug for Remote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Remote")
            .field("run", &self.run)
            .field("plan", &self.plan)
            .finish_non_exhaustive()
    }
}

fn zerr(e: impl std::fmt::Display) -> RemoteError {
    RemoteError::Zenoh(e.to_string())
}

impl Remote {
    /// Dials every host of `plan` for run `run` and waits until each answers
    /// a ping (an error names the first host that does not).
    pub fn connect(plan: &Plan, run: &str) -> Result<Self, RemoteError> {
        let endpoints: Vec<String> = plan.hosts.iter().map(|h| h.endpoint.clone()).collect();
        let session = zconfig::open(&[], &endpoints, &plan.security)
            .map_err(|e| RemoteError::Session(e.to_string()))?;
        let token = (session.liveliness())
            .declare_token(keys::orchestrator_alive(run))
            .wait()
            .map_err(zerr)?;
        let lost = Arc::new(Mutex::new(Vec::new()));
        let l = lost.clone();
        let watch = (session.liveliness())
            .declare_subscriber(keys::ANY_HOST_ALIVE)
            .callback(move |s: Sample| {
                if s.kind() == zenoh::sample::SampleKind::Delete {
                    let name = s
                        .key_expr()
                        .as_str()
                        .split('/')
                        .nth(2)
                        .unwrap_or("")
                        .to_string();
                    if let Ok(mut v) = l.lock() {
                        v.push(name);
                    }
                }
            })
            .wait()
            .map_err(zerr)?;
        let events = session
            .declare_subscriber(keys::events(run, "*"))
            .with(FifoChannel::new(1024))
            .wait()
            .map_err(zerr)?;
        let remote = Self {
            sinks: Vec::new(),
            bridges: None,
            shared: Shared::default(),
            events,
            lost,
            _watch: watch,
            _token: token,
            plan: plan.clone(),
            run: run.to_string(),
            started: Vec::new(),
            session,
        };
        for h in &plan.hosts {
            remote.ping(&h.name, &h.endpoint)?;
        }
        Ok(remote)
    }

    /// Waits up to [`REACH_TIMEOUT`] for host `name`'s answer to a ping.
    fn ping(&self, name: &str, endpoint: &str) -> Result<(), RemoteError> {
        let until = Instant::now() + REACH_TIMEOUT;
        while Instant::now() < until {
            let replies = (self.session.get(keys::ping(name)))
                .consolidation(ConsolidationMode::None)
                .timeout(Duration::from_millis(500))
                .wait()
                .map_err(zerr)?;
            if replies.recv().is_ok_and(|r| r.result().is_ok()) {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Err(RemoteError::Unreachable {
            name: name.into(),
            endpoint: endpoint.into(),
            seconds: REACH_TIMEOUT.as_secs(),
        })
    }

    /// Whether node `id` runs on a host.
    #[must_use]
    pub fn places(&self, id: u32) -> bool {
        self.plan.side_of(id) != Side::Orchestrator
    }

    /// The host of node `id`, if it runs on one.
    #[must_use]
    pub fn host_of(&self, id: u32) -> Option<String> {
        match self.plan.side_of(id) {
            Side::Host(h) => Some(h),
            Side::Orchestrator => None,
        }
    }

    /// Starts the local bridges and telemetry sinks in namespace `ns`,
    /// then hands each host its nodes (of `nodes`, every node of the run).
    pub fn start(&mut self, ns: &LocalNs, nodes: &[RemoteNode]) -> Result<(), RemoteError> {
        let configs: Vec<NodeConfig> = nodes.iter().map(|n| n.config.clone()).collect();
        let links = links(&configs, &self.plan);
        let (s, run) = (&self.session, self.run.as_str());
        self.bridges = Some(Bridges::start(
            &Sessions::single(s),
            ns,
            run,
            &Side::Orchestrator,
            &links,
            &self.shared,
        ));
        for h in &self.plan.hosts {
            let ids = h.nodes.clone();
            let sink = telemetry::start(End::Sink, s, ns, (run, &h.name), ids, &self.shared);
            self.sinks.push(sink);
        }
        let mut dials = mesh::dials(&self.plan, &links);
        let mut pending = Vec::new();
        for h in &self.plan.hosts {
            let me = Side::Host(h.name.clone());
            let req = RunRequest {
                run: self.run.clone(),
                host: h.name.clone(),
                nodes: (nodes.iter())
                    .filter(|n| h.nodes.contains(&n.config.id))
                    .cloned()
                    .collect(),
                links: (links.iter())
                    .filter(|l| l.from_side == me || l.to_side == me)
                    .cloned()
                    .collect(),
                dial: dials.remove(&h.name).unwrap_or_default(),
            };
            // The host fetches the request (in pieces) before it answers.
            let body = serde_json::to_vec(&req).expect("serialises");
            tracing::debug!(host = %h.name, bytes = body.len(), "run request");
            let served = (s.declare_queryable(keys::request(run, &h.name)))
                .callback(move |q| pieces::reply(&q, &body))
                .wait()
                .map_err(zerr)?;
            let offer = RunOffer {
                run: self.run.clone(),
                host: h.name.clone(),
            };
            let replies = (s.get(keys::run(&h.name)))
                .payload(serde_json::to_vec(&offer).expect("serialises"))
                .consolidation(ConsolidationMode::None)
                .timeout(ANSWER_TIMEOUT)
                .wait()
                .map_err(zerr)?;
            pending.push((h.name.clone(), replies, served));
        }
        for (name, replies, _served) in pending {
            let answer: Answer = match pieces::collect(&replies) {
                Ok(b) => serde_json::from_slice(&b)
                    .unwrap_or_else(|e| Answer::Err(format!("a bad answer: {e}"))),
                Err(pieces::CollectError::NoAnswer) => {
                    Answer::Err(format!("no answer within {} s", ANSWER_TIMEOUT.as_secs()))
                }
                Err(e) => Answer::Err(e.to_string()),
            };
            if let Answer::Err(why) = answer {
                return Err(RemoteError::NotStarted { host: name, why });
            }
            self.started.push(name);
        }
        Ok(())
    }

    /// Relays control message `m` to every host.
    pub fn control(&self, m: ControlMsg) -> Result<(), RemoteError> {
        (self.session.put(keys::control(&self.run), m.to_bytes()))
            .congestion_control(zenoh::qos::CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(zerr)
    }

    /// A lost host, a host's failure, or a bridge's: the run cannot go on.
    /// `Ok` carries the node exits the hosts reported since the last call.
    pub fn check(&self) -> Result<Vec<SiteExit>, RemoteError> {
        if let Some(h) = self.lost_host() {
            let nodes: Vec<String> = (self.plan.hosts.iter())
                .find(|p| p.name == h)
                .map(|p| p.nodes.iter().map(|&id| node_name(id)).collect())
                .unwrap_or_default();
            return Err(RemoteError::HostLost { host: h, nodes });
        }
        if let Some(f) = self.shared.failure() {
            return Err(RemoteError::Bridge(f));
        }
        let mut exits = Vec::new();
        while let Ok(Some(s)) = self.events.try_recv() {
            let host = s
                .key_expr()
                .as_str()
                .rsplit('/')
                .next()
                .unwrap_or("")
                .to_string();
            match serde_json::from_slice::<HostEvent>(&s.payload().to_bytes()) {
                Ok(HostEvent::Exited {
                    id,
                    status,
                    clean,
                    tail,
                }) => exits.push(SiteExit {
                    id,
                    host,
                    status,
                    clean,
                    tail,
                }),
                Ok(HostEvent::Failed(why)) => return Err(RemoteError::HostFailed { host, why }),
                Err(e) => {
                    let why = e.to_string();
                    return Err(RemoteError::BadEvent { host, why });
                }
            }
        }
        Ok(exits)
    }

    /// A host of the run whose liveliness token is gone.
    fn lost_host(&self) -> Option<String> {
        let lost = self.lost.lock().ok()?;
        (lost.iter())
            .find(|h| self.plan.hosts.iter().any(|p| &p.name == *h))
            .cloned()
    }

    /// Ends the run on every host that started it (`kill`: at once), writes
    /// each node's log into `logs`, and returns the exits that were not clean.
    pub fn finish(&mut self, kill: bool, logs: &Path) -> Vec<SiteExit> {
        let mut bad = Vec::new();
        let lost = self.lost_host();
        let mut pending = Vec::new();
        for name in std::mem::take(&mut self.started) {
            if lost.as_deref() == Some(name.as_str()) {
                continue;
            }
            let req = EndRequest {
                run: self.run.clone(),
                kill,
            };
            let got = (self.session.get(keys::end(&name)))
                .payload(serde_json::to_vec(&req).expect("serialises"))
                .consolidation(ConsolidationMode::None)
                .timeout(ANSWER_TIMEOUT)
                .wait();
            if let Ok(r) = got {
                pending.push((name, r));
            }
        }
        for (name, replies) in pending {
            let reply: Option<EndReply> = pieces::collect(&replies)
                .ok()
                .and_then(|b| serde_json::from_slice(&b).ok());
            let Some(reply) = reply else {
                bad.push(SiteExit {
                    id: u32::MAX,
                    host: name.clone(),
                    status: "did not report how its nodes ended".into(),
                    clean: false,
                    tail: String::new(),
                });
                continue;
            };
            for n in reply.nodes {
                let file = logs.join(launch::node_log::node_log_file(&node_name(n.id)));
                let _ = write_log(&file, &name, &n);
                if !n.clean {
                    bad.push(SiteExit {
                        id: n.id,
                        host: name.clone(),
                        status: n.status,
                        clean: false,
                        tail: String::new(),
                    });
                }
            }
            for f in reply.leftovers {
                tracing::warn!(host = %name, "left behind: {f}");
            }
        }
        self.shared.stop();
        self.sinks.clear();
        self.bridges = None;
        bad
    }
}

/// Writes a remote node's log: the end the host sent, headed by
/// [`cut_note`] if the host cut its beginning.
fn write_log(file: &Path, host: &str, n: &NodeEnd) -> std::io::Result<()> {
    let mut f = std::fs::File::create(file)?;
    if n.cut > 0 {
        writeln!(f, "{}", cut_note(host, n.cut))?;
    }
    f.write_all(&n.log)
}

/// `leader`, `agent-<id>`.
fn node_name(id: u32) -> String {
    if id == 0 {
        "leader".into()
    } else {
        format!("agent-{id}")
    }
}
