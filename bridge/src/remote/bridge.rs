//! The bridge of a run's cut edges on one side: for each session, a thread
//! that reads the iceoryx2 state services of the local senders with
//! receivers elsewhere and sends their states, a bundle at a time, on one
//! [`TrunkSender`] per side they go to; for each remote sender with
//! receivers here, a thread that takes its states off its
//! [`TrunkReceiver`]'s inbox and publishes them into a local state service
//! for that sender, with attsync's own service settings
//! (`msgs::open::state`), waking the receivers. The receiving node sees a
//! normal local input. The exact bytes travel, in order, losslessly:
//! lockstep stays byte-identical. In real time the trunks carry the newest
//! states first, as a network would.

use super::Side;
pub use super::bridge_error::BridgeError;
use super::bridge_error::debug;
use super::keys;
use super::link::{Flow, LinkError, Window};
use super::local::{LocalNs, Shared};
use super::mesh::Sessions;
use super::trunk::{BUNDLE_MOST, Direct, TrunkInput, TrunkReceiver, TrunkSender};
use super::wire::StateLink;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use msgs::StateMsg;
use msgs::bytes::Bytes;
use msgs::iox::iox;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// How long a bridge thread sleeps on its wake event or queue before it
/// looks at the stop flag again.
const SLICE: Duration = Duration::from_millis(1);

/// The running bridge threads of one side; stopped and joined on drop.
pub struct Bridges {
    shared: Shared,
    threads: Vec<JoinHandle<()>>,
    _trunks: Vec<TrunkReceiver>,
}

impl Bridges {
    /// Starts the threads of `links` on side `me`: one per session that
    /// sends the links leaving `me` over it (a [`TrunkSender`] per side
    /// they go to), one per link reaching `me` (fed by the
    /// [`TrunkReceiver`] of the side it comes from).
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
        for (s, out) in outgoing(sessions, me, links) {
            let (ns, run, sh) = (ns.clone(), run.to_string(), shared.clone());
            let all = links.to_vec();
            threads.push(std::thread::spawn(move || {
                if let Err(e) = send_states(&s, &ns, &run, (&out, &all), &sh) {
                    sh.fail(format!(
                        "bridge of the states leaving {}: {e}",
                        out[0].from_side
                    ));
                }
            }));
        }
        let mut trunks = Vec::new();
        for (from, inc) in incoming(me, links) {
            let key = keys::state_trunk(run, &from, me);
            let senders = inc.iter().map(|l| l.from).collect();
            let session = sessions.towards(&from);
            let trunk = match TrunkReceiver::open(session, &key, senders, state_flow(ns)) {
                Ok(t) => t,
                Err(e) => {
                    shared.fail(format!("bridge of the states from {from}: {e}"));
                    continue;
                }
            };
            for l in inc {
                let Some(input) = trunk.input(l.from) else {
                    continue;
                };
                let (ns, sh) = (ns.clone(), shared.clone());
                threads.push(std::thread::spawn(move || {
                    if let Err(e) = receive_states(&ns, input, &l, &sh) {
                        sh.fail(format!(
                            "bridge of node {}'s states to {}: {e}",
                            l.from, l.to_side
                        ));
                    }
                }));
            }
            trunks.push(trunk);
        }
        Self {
            shared: shared.clone(),
            threads,
            _trunks: trunks,
        }
    }
}

/// The links leaving `me`, grouped by the session they go over.
fn outgoing(
    sessions: &Sessions,
    me: &Side,
    links: &[StateLink],
) -> Vec<(zenoh::Session, Vec<StateLink>)> {
    let mut out: Vec<(zenoh::Session, Vec<StateLink>)> = Vec::new();
    for l in links.iter().filter(|l| l.from_side == *me) {
        let s = sessions.towards(&l.to_side);
        match out.iter_mut().find(|(o, _)| o.zid() == s.zid()) {
            Some((_, group)) => group.push(l.clone()),
            None => out.push((s.clone(), vec![l.clone()])),
        }
    }
    out
}

/// The links reaching `me`, grouped by the side they come from (a trunk each).
fn incoming(me: &Side, links: &[StateLink]) -> Vec<(Side, Vec<StateLink>)> {
    let mut inc: Vec<(Side, Vec<StateLink>)> = Vec::new();
    for l in links.iter().filter(|l| l.to_side == *me) {
        match inc.iter_mut().find(|(f, _)| *f == l.from_side) {
            Some((_, group)) => group.push(l.clone()),
            None => inc.push((l.from_side.clone(), vec![l.clone()])),
        }
    }
    inc
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
/// the others drained. The first is read into `queue` (at most a window)
/// also while the window is shut.
struct Outgoing {
    subs: Vec<StateSubscriber>,
    queue: std::collections::VecDeque<StateMsg>,
}

impl Outgoing {
    /// Reads what the queue holds room for; whether anything moved.
    fn read(&mut self, most: usize) -> Result<bool, BridgeError> {
        let mut moved = false;
        for s in &self.subs[1..] {
            while s
                .receive()
                .map_err(|e| BridgeError::Receive(debug(e)))?
                .is_some()
            {}
        }
        while self.queue.len() < most {
            let Some(m) = self.subs[0]
                .receive()
                .map_err(|e| BridgeError::Receive(debug(e)))?
            else {
                break;
            };
            self.queue.push_back(*m);
            moved = true;
        }
        Ok(moved)
    }
}

/// The links towards one side: their trunk, their sending ends (in the
/// trunk's order) and how long their states may wait to share a bundle.
struct Towards {
    trunk: TrunkSender,
    links: Vec<Outgoing>,
    hold: Hold,
}

/// How long states may wait for others to share their bundle: never in
/// lockstep without lookahead (each crossing is on the run's path); when
/// every link leaving this side and every link reaching it is delayed by
/// at least `ahead` ≥ 1 steps (so a sender here runs at least that far
/// ahead of its receivers there, whatever path leads back), until a link
/// has half of that lead (2·ahead states) or the first has waited
/// [`HOLD_MOST`]. Holding changes when states arrive, never which.
struct Hold {
    /// States a link may gather: 0 to send at once.
    gather: usize,
    /// When the oldest state not sent was read.
    since: Option<std::time::Instant>,
}

/// The longest a state waits for others to share its bundle.
const HOLD_MOST: Duration = Duration::from_micros(500);

impl Hold {
    /// The hold of `links` on side `me`, whose run's links are `all`.
    fn of(links: &[&StateLink], me: &Side, all: &[StateLink], most: usize) -> Self {
        let back = (all.iter().filter(|l| l.to_side == *me)).map(|l| l.ahead);
        let ahead = (links.iter().map(|l| l.ahead).chain(back))
            .min()
            .unwrap_or(0);
        let gather = usize::try_from(ahead.saturating_mul(2)).unwrap_or(usize::MAX);
        Self {
            gather: gather.min(most / 2),
            since: None,
        }
    }

    /// How long states queued so (per link) may still wait (`None`: send now).
    fn left(&mut self, queued: &[usize]) -> Option<Duration> {
        if queued.iter().all(|&n| n == 0) {
            self.since = None;
            return None;
        }
        let since = *self.since.get_or_insert_with(std::time::Instant::now);
        if queued.iter().any(|&n| n >= self.gather) {
            return None;
        }
        HOLD_MOST
            .checked_sub(since.elapsed())
            .filter(|d| !d.is_zero())
    }
}

impl Towards {
    /// Reads every link and sends what their windows allow, in bundles of
    /// at most [`BUNDLE_MOST`], unless its states may wait for more;
    /// whether anything moved, and how long the states left may wait.
    fn pump(&mut self, most: usize) -> Result<(bool, Option<Duration>), BridgeError> {
        let mut moved = false;
        for o in &mut self.links {
            moved |= o.read(most)?;
        }
        let queued: Vec<usize> = self.links.iter().map(|o| o.queue.len()).collect();
        if let Some(left) = self.hold.left(&queued) {
            return Ok((moved, Some(left)));
        }
        loop {
            let mut bundle = Vec::new();
            let mut counts = vec![0u64; self.links.len()];
            let mut room = BUNDLE_MOST;
            for (i, o) in self.links.iter_mut().enumerate() {
                let n = o.queue.len().min(self.trunk.credit(i)).min(room);
                for m in o.queue.drain(..n) {
                    bundle.extend_from_slice(&m.to_bytes());
                }
                counts[i] = n as u64;
                room -= n;
            }
            if bundle.is_empty() {
                self.hold.since = None;
                return Ok((moved, None));
            }
            self.trunk.send(bundle, &counts)?;
            moved = true;
        }
    }
}

/// How `ns`'s cut edges carry states: every one in lockstep, within a
/// window of a receiver's buffer (`Limits::state_buffer`); the newest
/// `state_buffer` first in real time.
fn state_flow(ns: &LocalNs) -> Flow {
    let depth = ns.limits.state_buffer.max(1);
    if ns.realtime {
        Flow::Freshest { depth }
    } else {
        let window = depth as u64;
        Flow::Window(Window {
            window,
            ack_every: (window / 4).max(1),
        })
    }
}

/// The sending side of every link leaving this side over `session`, on
/// one thread that sleeps on the wake events of the receivers over there
/// (nobody else listens to them on this side). A link without credit
/// leaves its messages in iceoryx2 (holding its sender back) and never
/// blocks another. `all`: every link of the run on this side.
fn send_states(
    session: &zenoh::Session,
    ns: &LocalNs,
    run: &str,
    (links, all): (&[StateLink], &[StateLink]),
    sh: &Shared,
) -> Result<(), BridgeError> {
    let node = ns.node("bridge-out")?;
    let mut towards: Vec<Towards> = Vec::new();
    for (to, group) in by_destination(links) {
        let senders = group.iter().map(|l| l.from).collect();
        let key = keys::state_trunk(run, &group[0].from_side, &to);
        let trunk = TrunkSender::open(session, &key, senders, state_flow(ns))?;
        let mut outs = Vec::new();
        for l in &group {
            let svc = msgs::open::state(&node, &ns.run, l.from, &ns.limits)?;
            if !publisher_is_up(&svc, sh) {
                return Ok(()); // the run ended first
            }
            let subs = (l.receivers.iter())
                .map(|_| subscribe(&svc, ns.limits.state_buffer))
                .collect::<Result<Vec<_>, _>>()?;
            outs.push(Outgoing {
                subs,
                queue: std::collections::VecDeque::new(),
            });
        }
        let hold = Hold::of(&group, &group[0].from_side, all, ns.limits.state_buffer);
        towards.push(Towards {
            trunk,
            links: outs,
            hold,
        });
    }
    let listeners = wake_listeners(&node, ns, links)?;
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| BridgeError::WaitSet(debug(e)))?;
    let _guards = (listeners.iter())
        .map(|l| waitset.attach_notification(l))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| BridgeError::WaitSet(debug(e)))?;
    let most = ns.limits.state_buffer.max(1);
    let mut wait = SLICE;
    while !sh.stopping() {
        let _ = waitset.wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, wait);
        for l in &listeners {
            let _ = l.try_wait(|_| {});
        }
        let mut moved = true;
        while moved {
            (moved, wait) = (false, SLICE);
            for t in &mut towards {
                let (m, left) = t.pump(most)?;
                moved |= m;
                wait = wait.min(left.unwrap_or(SLICE));
            }
        }
    }
    Ok(())
}

/// `links` grouped by the side they go to, in their order.
fn by_destination(links: &[StateLink]) -> Vec<(Side, Vec<&StateLink>)> {
    let mut by: Vec<(Side, Vec<&StateLink>)> = Vec::new();
    for l in links {
        match by.iter_mut().find(|(to, _)| *to == l.to_side) {
            Some((_, group)) => group.push(l),
            None => by.push((l.to_side.clone(), vec![l])),
        }
    }
    by
}

/// A listener of the wake event of every receiver of `links` (a node
/// notifies its receivers when it publishes).
fn wake_listeners(
    node: &iceoryx2::node::Node<ipc::Service>,
    ns: &LocalNs,
    links: &[StateLink],
) -> Result<Vec<iceoryx2::port::listener::Listener<ipc::Service>>, BridgeError> {
    let mut remote: Vec<u32> = (links.iter())
        .flat_map(|l| l.receivers.iter().copied())
        .collect();
    remote.sort_unstable();
    remote.dedup();
    (remote.iter())
        .map(|&r| {
            msgs::open::wake(node, &ns.run, r, &ns.limits)?
                .listener_builder()
                .create()
                .map_err(|e| BridgeError::from(iox("bridge wake listener")(e)))
        })
        .collect()
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
/// full, at most the stage timeout; its states come off `input`, or go
/// straight from Zenoh's callback when `l` has one receiver here and its
/// buffer has room ([`Republisher`]).
fn receive_states(
    ns: &LocalNs,
    input: TrunkInput,
    l: &StateLink,
    sh: &Shared,
) -> Result<(), BridgeError> {
    let node = ns.shared_node(&format!("bridge-in-{}", l.from))?;
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
    let to = Arc::new(Republisher {
        publisher,
        notifiers,
        want: l.receivers.len(),
    });
    if to.want == 1 {
        input.set_direct(to.clone());
    }
    while !sh.stopping() {
        input.take(SLICE * 20, |bytes| {
            let m = StateMsg::from_bytes(&bytes)?;
            if sh.stopping() {
                return Ok(());
            }
            to.deliver(m, ns.stage_timeout, sh)
        })?;
    }
    Ok(())
}

type SharedPublisher = iceoryx2::port::publisher::Publisher<ipc_threadsafe::Service, StateMsg, ()>;
type SharedNotifier = iceoryx2::port::notifier::Notifier<ipc_threadsafe::Service>;

/// A remote sender's publisher on this side and its local receivers' wake
/// events, shared by its bridge thread and Zenoh's callback.
struct Republisher {
    publisher: SharedPublisher,
    notifiers: Vec<SharedNotifier>,
    /// How many subscribers a state must reach.
    want: usize,
}

thread_local! {
    /// This thread delivers from Zenoh's callback: never hold back.
    static AT_ONCE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

impl Direct for Republisher {
    /// With one receiver: a send that cannot deliver at once fails having
    /// reached nobody, and the state goes to the link's thread.
    fn try_now(&self, state: &[u8]) -> Result<bool, LinkError> {
        let m = StateMsg::from_bytes(state).map_err(|e| LinkError::Malformed(e.to_string()))?;
        AT_ONCE.set(true);
        let sent = self.publisher.send_copy(m);
        AT_ONCE.set(false);
        Ok(matches!(sent, Ok(n) if n >= self.want))
    }

    fn wake(&self) {
        for n in &self.notifiers {
            let _ = n.notify();
        }
    }
}

impl Republisher {
    /// Publishes `m` to every local receiver and wakes them. iceoryx2 0.10
    /// skips, without an error, a receiver whose buffer is full while its
    /// side of the connection is not established yet (it connects when it
    /// next polls): a send that reached nobody is repeated every 50 µs,
    /// waking the receivers, until it is delivered, at most `timeout`.
    /// Lockstep cannot lose a message, so one that reached only some of
    /// several receivers fails the run, named, instead of being skipped.
    fn deliver(&self, m: StateMsg, timeout: Duration, sh: &Shared) -> Result<(), BridgeError> {
        let start = std::time::Instant::now();
        loop {
            let got = (self.publisher.send_copy(m)).map_err(iox("bridge state send"))?;
            self.wake();
            if got >= self.want {
                return Ok(());
            }
            let (step, stage) = (m.step, m.stage);
            if got > 0 {
                let want = self.want;
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
}

/// A backpressure handler: retry every 50 µs, give up after `timeout` or
/// when the run stops; at once in Zenoh's callback ([`AT_ONCE`]).
fn hold_back(
    timeout: Duration,
    sh: Shared,
) -> impl Fn(&iceoryx2::port::BackpressureInfo) -> iceoryx2::port::BackpressureAction + Send + 'static
{
    move |info| {
        if AT_ONCE.get() || info.elapsed_time > timeout || sh.stopping() {
            iceoryx2::port::BackpressureAction::DiscardDataAndFail
        } else {
            std::thread::sleep(Duration::from_micros(50));
            iceoryx2::port::BackpressureAction::Retry
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn link(from: u32, from_side: Side, to_side: Side, ahead: u64) -> StateLink {
        StateLink {
            from,
            from_side,
            to_side,
            receivers: vec![9],
            ahead,
        }
    }

    #[test]
    fn states_wait_only_when_every_link_in_and_out_is_delayed() {
        let (me, there) = (Side::Orchestrator, Side::Host("b".into()));
        let out = link(1, me.clone(), there.clone(), 3);
        let all = |back: u64| vec![out.clone(), link(2, there.clone(), me.clone(), back)];
        // an undelayed link back: the sender may wait for what it sends
        assert_eq!(Hold::of(&[&out], &me, &all(0), 64).gather, 0);
        assert_eq!(Hold::of(&[&out], &me, &all(5), 64).gather, 6);
        assert_eq!(Hold::of(&[&out], &me, &all(1), 64).gather, 2);
        assert_eq!(Hold::of(&[&out], &me, &all(50), 64).gather, 6);
        let far = link(1, me.clone(), there.clone(), 100);
        assert_eq!(
            Hold::of(&[&far], &me, std::slice::from_ref(&far), 64).gather,
            32
        );
    }

    #[test]
    fn a_hold_ends_when_a_link_has_gathered_or_its_time_is_up() {
        let mut h = Hold {
            gather: 4,
            since: None,
        };
        assert_eq!(h.left(&[0, 0]), None);
        let wait = h.left(&[1, 0]).expect("waits");
        assert!(wait <= HOLD_MOST);
        assert_eq!(h.left(&[4, 1]), None, "a link gathered enough");
        std::thread::sleep(HOLD_MOST);
        assert_eq!(h.left(&[1, 1]), None, "time is up");
        assert_eq!(h.left(&[0, 0]), None);
        assert!(h.since.is_none(), "nothing queued: the clock restarts");
        let mut never = Hold {
            gather: 0,
            since: None,
        };
        assert_eq!(never.left(&[1]), None, "no lookahead: send at once");
    }
}
