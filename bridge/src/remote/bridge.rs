//! The bridge of a run's cut edges on one side: for each local sender with
//! receivers elsewhere, a thread that reads its iceoryx2 state service and
//! puts every message on a [`LinkSender`]; for each remote sender with
//! receivers here, a thread that takes its messages off a [`LinkReceiver`]
//! and publishes them into a local state service for that sender, with
//! attsync's own service settings (`msgs::open::state`), waking the
//! receivers. The receiving node sees a normal local input. The exact
//! bytes travel, in order, losslessly: lockstep stays byte-identical. In
//! real time the links carry the newest states first
//! ([`super::link::STATE_FRESHEST`]), as a network would.

use super::Side;
pub use super::bridge_error::BridgeError;
use super::bridge_error::debug;
use super::keys;
use super::link::{Flow, LinkReceiver, LinkSender, STATE_DEPTH, STATE_FRESHEST, STATE_WINDOW};
use super::local::{LocalNs, Shared};
use super::mesh::Sessions;
use super::wire::StateLink;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use msgs::StateMsg;
use msgs::bytes::Bytes;
use msgs::iox::iox;
use std::thread::JoinHandle;
use std::time::Duration;

/// How long a bridge thread sleeps on its wake event or queue before it
/// looks at the stop flag again.
const SLICE: Duration = Duration::from_millis(1);

/// The running bridge threads of one side; stopped and joined on drop.
pub struct Bridges {
    shared: Shared,
    threads: Vec<JoinHandle<()>>,
}

impl Bridges {
    /// Starts the threads of `links` on side `me`: one per session that
    /// sends the links leaving `me` over it, one per link reaching `me`;
    /// each link over the session towards its other side.
    #[must_use]
    pub fn start(
        sessions: &Sessions,
        ns: &LocalNs,
        run: &str,
        me: &Side,
        links: &[StateLink],
        shared: &Shared,
    ) -> Self {
        let mut threads = Vec::new();
        let mut out: Vec<(zenoh::Session, Vec<StateLink>)> = Vec::new();
        for l in links.iter().filter(|l| l.from_side == *me) {
            let s = sessions.towards(&l.to_side);
            match out.iter_mut().find(|(o, _)| o.zid() == s.zid()) {
                Some((_, group)) => group.push(l.clone()),
                None => out.push((s.clone(), vec![l.clone()])),
            }
        }
        for (s, out) in out {
            let (ns, run, sh) = (ns.clone(), run.to_string(), shared.clone());
            threads.push(std::thread::spawn(move || {
                if let Err(e) = send_states(&s, &ns, &run, &out, &sh) {
                    sh.fail(format!(
                        "bridge of the states leaving {}: {e}",
                        out[0].from_side
                    ));
                }
            }));
        }
        for l in links.iter().filter(|l| l.to_side == *me) {
            let (s, ns, key) = (
                sessions.towards(&l.from_side).clone(),
                ns.clone(),
                keys::state_link(run, l.from, &l.to_side),
            );
            let (l, sh) = (l.clone(), shared.clone());
            threads.push(std::thread::spawn(move || {
                if let Err(e) = receive_states(&s, &ns, &key, &l, &sh) {
                    sh.fail(format!(
                        "bridge of node {}'s states to {}: {e}",
                        l.from, l.to_side
                    ));
                }
            }));
        }
        Self {
            shared: shared.clone(),
            threads,
        }
    }
}

impl Drop for Bridges {
    fn drop(&mut self) {
        self.shared.stop();
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// One link's sending end: a subscriber per receiver over there (the
/// sender counts its receivers before it is ready), the first forwarded,
/// the others drained.
/// The first is read into `queue` (at most a window) also while the
/// window is shut.
struct Outgoing {
    subs: Vec<StateSubscriber>,
    queue: std::collections::VecDeque<Vec<u8>>,
    link: LinkSender,
}

impl Outgoing {
    /// Reads what the queue holds and forwards what the window allows;
    /// whether anything moved.
    fn pump(&mut self) -> Result<bool, BridgeError> {
        let mut moved = false;
        for s in &self.subs[1..] {
            while s
                .receive()
                .map_err(|e| BridgeError::Receive(debug(e)))?
                .is_some()
            {}
        }
        while self.queue.len() < QUEUE {
            let Some(m) = self.subs[0]
                .receive()
                .map_err(|e| BridgeError::Receive(debug(e)))?
            else {
                break;
            };
            self.queue.push_back(m.to_bytes());
            moved = true;
        }
        while self.link.has_credit() {
            let Some(bytes) = self.queue.pop_front() else {
                break;
            };
            self.link.send_now(bytes)?;
            moved = true;
        }
        Ok(moved)
    }
}

/// The states a link's sending end reads ahead of its window.
const QUEUE: usize = STATE_DEPTH;

/// How `ns`'s cut edges carry states: every one in lockstep, the newest
/// first in real time.
fn state_flow(ns: &LocalNs) -> Flow {
    if ns.realtime {
        STATE_FRESHEST
    } else {
        STATE_WINDOW
    }
}

/// The sending side of every link leaving this side, on one thread that
/// sleeps on the wake events of the receivers over there (nobody else
/// listens to them on this side). A link without credit leaves its
/// messages in iceoryx2 (holding its sender back) and never blocks another.
fn send_states(
    session: &zenoh::Session,
    ns: &LocalNs,
    run: &str,
    links: &[StateLink],
    sh: &Shared,
) -> Result<(), BridgeError> {
    let node = ns.node("bridge-out")?;
    let mut out = Vec::new();
    for l in links {
        let svc = msgs::open::state(&node, &ns.run, l.from, &ns.limits)?;
        let key = keys::state_link(run, l.from, &l.to_side);
        let link = LinkSender::open(session, &key, state_flow(ns))?;
        if !publisher_is_up(&svc, sh) {
            return Ok(()); // the run ended first
        }
        let subs = (l.receivers.iter())
            .map(|_| subscribe(&svc, ns.limits.state_buffer))
            .collect::<Result<Vec<_>, _>>()?;
        out.push(Outgoing {
            subs,
            queue: std::collections::VecDeque::new(),
            link,
        });
    }
    let mut remote: Vec<u32> = links
        .iter()
        .flat_map(|l| l.receivers.iter().copied())
        .collect();
    remote.sort_unstable();
    remote.dedup();
    let listeners = (remote.iter())
        .map(|&r| {
            msgs::open::wake(&node, &ns.run, r, &ns.limits)?
                .listener_builder()
                .create()
                .map_err(|e| BridgeError::from(iox("bridge wake listener")(e)))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| BridgeError::WaitSet(debug(e)))?;
    let _guards = (listeners.iter())
        .map(|l| waitset.attach_notification(l))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| BridgeError::WaitSet(debug(e)))?;
    while !sh.stopping() {
        let _ =
            waitset.wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, SLICE);
        for l in &listeners {
            let _ = l.try_wait(|_| {});
        }
        let mut moved = true;
        while moved {
            moved = false;
            for o in &mut out {
                moved |= o.pump()?;
            }
        }
    }
    Ok(())
}

/// Waits until the sender's publisher exists (a node opens it before it
/// waits for its receivers); `false` if the run stops first.
fn publisher_is_up(svc: &StateService, sh: &Shared) -> bool {
    while svc.dynamic_config().number_of_publishers() == 0 {
        if sh.stopping() {
            return false;
        }
        std::thread::sleep(Duration::from_micros(100));
    }
    true
}

/// A subscriber of the sender's states with its side of the connection to
/// the (existing) publisher established before the sender can count it:
/// iceoryx2 0.10 holds a publisher back for a full subscriber only once
/// the subscriber's side is connected; before that its blocking send skips
/// the subscriber without an error, and a sender that runs ahead (the
/// leader) would lose its states from the 65th on.
fn subscribe(svc: &StateService, buffer: usize) -> Result<StateSubscriber, BridgeError> {
    let sub = (svc.subscriber_builder().buffer_size(buffer).create())
        .map_err(iox("bridge state subscriber"))?;
    sub.update_connections()
        .map_err(|e| BridgeError::Connect(debug(e)))?;
    Ok(sub)
}

type StateService =
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, StateMsg, ()>;
type StateSubscriber = iceoryx2::port::subscriber::Subscriber<ipc::Service, StateMsg, ()>;

/// The receiving side of `l`: the sender's only publisher on this side,
/// holding back (like a node's own publisher) while a receiver's buffer is
/// full, at most the stage timeout.
fn receive_states(
    session: &zenoh::Session,
    ns: &LocalNs,
    key: &str,
    l: &StateLink,
    sh: &Shared,
) -> Result<(), BridgeError> {
    let node = ns.node(&format!("bridge-in-{}", l.from))?;
    let svc = msgs::open::state(&node, &ns.run, l.from, &ns.limits)?;
    let publisher = svc
        .publisher_builder()
        .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
        .set_backpressure_handler(hold_back(ns.stage_timeout, sh.clone()))
        .create()
        .map_err(iox("bridge state publisher"))?;
    let notifiers = (l.receivers.iter())
        .map(|&r| {
            msgs::open::wake(&node, &ns.run, r, &ns.limits)?
                .notifier_builder()
                .create()
                .map_err(|e| BridgeError::from(iox("bridge wake notifier")(e)))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut link = LinkReceiver::open(session, key, state_flow(ns))?;
    while !sh.stopping() {
        let Some(bytes) = link.recv(SLICE * 20)? else {
            continue;
        };
        let m = StateMsg::from_bytes(&bytes)?;
        if sh.stopping() {
            break;
        }
        let to = Receivers {
            notifiers: &notifiers,
            want: l.receivers.len(),
        };
        deliver(&publisher, &to, m, ns.stage_timeout, sh)?;
        link.delivered()?;
    }
    Ok(())
}

/// The local receivers of a bridged state: their wake events and how many
/// subscribers a message must reach.
struct Receivers<'a> {
    notifiers: &'a [iceoryx2::port::notifier::Notifier<ipc::Service>],
    want: usize,
}

/// Publishes `m` to every local receiver and wakes them. iceoryx2 0.10
/// skips, without an error, a receiver whose buffer is full while its side
/// of the connection is not established yet (it connects when it next
/// polls): a send that reached nobody is repeated every 50 µs, waking the
/// receivers, until it is delivered, at most `timeout`. Lockstep cannot
/// lose a message, so one that reached only some of several receivers
/// fails the run, named, instead of being skipped.
fn deliver(
    publisher: &iceoryx2::port::publisher::Publisher<ipc::Service, StateMsg, ()>,
    to: &Receivers<'_>,
    m: StateMsg,
    timeout: Duration,
    sh: &Shared,
) -> Result<(), BridgeError> {
    let start = std::time::Instant::now();
    loop {
        let got = (publisher.send_copy(m)).map_err(iox("bridge state send"))?;
        for n in to.notifiers {
            let _ = n.notify();
        }
        if got >= to.want {
            return Ok(());
        }
        let (step, stage) = (m.step, m.stage);
        if got > 0 {
            let want = to.want;
            return Err(BridgeError::Partial {
                step,
                stage,
                got,
                want,
            });
        }
        if sh.stopping() {
            return Ok(()); // the run is ending: nobody waits for it
        }
        if start.elapsed() > timeout {
            let seconds = timeout.as_secs_f64();
            return Err(BridgeError::Undelivered {
                step,
                stage,
                seconds,
            });
        }
        std::thread::sleep(Duration::from_micros(50));
    }
}

/// A backpressure handler: retry every 50 µs, give up after `timeout` or
/// when the run stops.
fn hold_back(
    timeout: Duration,
    sh: Shared,
) -> impl Fn(&iceoryx2::port::BackpressureInfo) -> iceoryx2::port::BackpressureAction + Send + 'static
{
    move |info| {
        if info.elapsed_time > timeout || sh.stopping() {
            iceoryx2::port::BackpressureAction::DiscardDataAndFail
        } else {
            std::thread::sleep(Duration::from_micros(50));
            iceoryx2::port::BackpressureAction::Retry
        }
    }
}
