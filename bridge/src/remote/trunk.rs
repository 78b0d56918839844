//! A trunk: every cut edge's states from one side to another over one
//! Zenoh key. Each Zenoh message (a bundle) carries every state the
//! sending side has at hand for that side — one per cut edge at an
//! exchange, several exchanges' when the nodes run ahead (lookahead) —
//! as their exact 152 bytes back to back (each names its sender). The
//! receiving side's Zenoh callback sorts a bundle's states into one inbox
//! per sender, which that sender's bridge thread publishes into iceoryx2.
//!
//! Flow control stays per link, as on a [`super::link`]: a link may have
//! at most its window unacknowledged (lockstep), so one sender whose
//! receivers lag never holds back another's states; a real-time trunk has
//! no window and each inbox keeps its newest messages. Acknowledgements
//! are batched: one message on `<key>/ack` carries every link's delivered
//! count, sent once per `ack_every` deliveries over the whole trunk (and
//! as the hello, every [`HELLO_EVERY`] while idle).
//!
//! A state goes into iceoryx2 straight from the callback when it can
//! ([`Direct`]: its inbox is empty, its thread idle, and it is delivered at
//! once); else it waits in the inbox for its thread, which may hold back.
//! A publish must never block the callback: a receiver whose buffer is full
//! (its sender ran ahead) may be waiting for another sender's state in the
//! same bundle.

use super::link::{Flow, HELLO_EVERY, LinkError, express_publisher};
use msgs::StateMsg;
use msgs::bytes::Bytes;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::sample::Sample;

/// States in one bundle at most: 384 × 152 B = 57 KiB, under the
/// low-latency transport's 64 KiB per message.
pub const BUNDLE_MOST: usize = 384;

/// The byte offset of a state's sender id (`StateMsg::sender`, after `version`).
const SENDER_AT: usize = 4;

fn zerr(e: impl std::fmt::Display) -> LinkError {
    LinkError::Zenoh(e.to_string())
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The sender id of a state's bytes.
fn sender_of(state: &[u8]) -> Option<u32> {
    let b = state.get(SENDER_AT..SENDER_AT + 4)?;
    Some(u32::from_le_bytes(b.try_into().ok()?))
}

/// An acknowledgement's bytes: `(sender u32, delivered u64)` per link, little-endian.
fn ack_bytes(senders: &[u32], delivered: impl Iterator<Item = u64>) -> Vec<u8> {
    let mut out = Vec::with_capacity(senders.len() * 12);
    for (s, d) in senders.iter().zip(delivered) {
        out.extend_from_slice(&s.to_le_bytes());
        out.extend_from_slice(&d.to_le_bytes());
    }
    out
}

/// Each link's acknowledged count (`None` before the hello).
type Acked = Arc<(Mutex<Option<Vec<u64>>>, Condvar)>;

/// The sending end of a trunk: one publisher, a window per link.
pub struct TrunkSender {
    publisher: Publisher<'static>,
    senders: Vec<u32>,
    acked: Acked,
    _acks: Subscriber<()>,
    sent: Vec<u64>,
    flow: Flow,
}

impl TrunkSender {
    /// Declares the publisher of `key` for the states of `senders` (its
    /// links, in this order) and the subscriber of their acknowledgements.
    pub fn open(
        session: &zenoh::Session,
        key: &str,
        senders: Vec<u32>,
        flow: Flow,
    ) -> Result<Self, LinkError> {
        let publisher = express_publisher(session, key.to_string())?;
        let acked: Acked = Arc::new((Mutex::new(None), Condvar::new()));
        let (a, ids) = (acked.clone(), senders.clone());
        let acks = (session.declare_subscriber(super::keys::ack(key)))
            .callback(move |s: Sample| book_ack(&a, &ids, &s.payload().to_bytes()))
            .wait()
            .map_err(zerr)?;
        Ok(Self {
            publisher,
            sent: vec![0; senders.len()],
            senders,
            acked,
            _acks: acks,
            flow,
        })
    }

    /// The links' sender ids, in order.
    #[must_use]
    pub fn senders(&self) -> &[u32] {
        &self.senders
    }

    /// How many more states link `i` may send now (0 before the hello).
    #[must_use]
    pub fn credit(&self, i: usize) -> usize {
        let g = lock(&self.acked.0);
        let Some(acked) = g.as_ref() else {
            return 0;
        };
        match self.flow {
            Flow::Window(w) => {
                let out = self.sent[i] - acked[i];
                usize::try_from(w.window.saturating_sub(out)).unwrap_or(usize::MAX)
            }
            Flow::Freshest { .. } => usize::MAX,
        }
    }

    /// Sends a bundle (states back to back) in which link `i` has
    /// `counts[i]` states.
    pub fn send(&mut self, bundle: Vec<u8>, counts: &[u64]) -> Result<(), LinkError> {
        self.publisher.put(bundle).wait().map_err(zerr)?;
        for (s, c) in self.sent.iter_mut().zip(counts) {
            *s += c;
        }
        Ok(())
    }
}

/// Books an acknowledgement (each link's count only grows).
fn book_ack(acked: &Acked, senders: &[u32], bytes: &[u8]) {
    let (m, cv) = &**acked;
    let mut g = lock(m);
    let counts = g.get_or_insert_with(|| vec![0; senders.len()]);
    for e in bytes.chunks_exact(12) {
        let (s, d) = e.split_at(4);
        let s = u32::from_le_bytes(s.try_into().unwrap_or_default());
        let d = u64::from_le_bytes(d.try_into().unwrap_or_default());
        if let Some(i) = senders.iter().position(|&x| x == s) {
            counts[i] = counts[i].max(d);
        }
    }
    cv.notify_all();
}

/// Delivers a link's state at once from Zenoh's callback, or says it
/// cannot without waiting.
pub trait Direct: Send + Sync {
    /// `Ok(true)`: delivered (its receivers are woken later, once per
    /// bundle: [`Self::wake`]); `Ok(false)`: not now (the link's thread
    /// will); `Err`: the state cannot be delivered, why.
    fn try_now(&self, state: &[u8]) -> Result<bool, LinkError>;
    /// Wakes the receivers of the states delivered.
    fn wake(&self);
}

/// One link's inbox: its states in order, at most `depth` (a window's
/// worth plus slack, or the newest `depth` in real time); `busy` while
/// its thread delivers one, so that a direct delivery never overtakes it.
struct Inbox {
    queue: Mutex<VecDeque<Vec<u8>>>,
    ready: Condvar,
    direct: std::sync::OnceLock<Arc<dyn Direct>>,
    busy: Mutex<()>,
}

impl Inbox {
    /// Delivers `state` from the callback if it is first in line and goes
    /// at once (`q`: the locked queue).
    fn direct(&self, q: &VecDeque<Vec<u8>>, state: &[u8]) -> Result<bool, LinkError> {
        let Some(d) = self.direct.get() else {
            return Ok(false);
        };
        if !q.is_empty() {
            return Ok(false);
        }
        let Ok(_busy) = self.busy.try_lock() else {
            return Ok(false);
        };
        d.try_now(state)
    }
}

/// What the receiving end's callback and its links share.
struct Shared {
    senders: Vec<u32>,
    inboxes: Vec<Inbox>,
    depth: usize,
    lossless: bool,
    fault: Mutex<Option<LinkError>>,
    acks: Mutex<Publisher<'static>>,
    delivered: Vec<AtomicU64>,
    since_ack: AtomicU64,
    last_ack: Mutex<Instant>,
    ack_every: u64,
}

impl Shared {
    /// Sorts a bundle's states into their inboxes (the Zenoh callback);
    /// the receivers of states delivered directly are woken once, after.
    fn sort(&self, bundle: &[u8]) {
        if bundle.len() % StateMsg::SIZE != 0 {
            let what = format!("a bundle of {} bytes", bundle.len());
            return self.fault(LinkError::Malformed(what));
        }
        let mut direct = vec![false; self.inboxes.len()];
        for state in bundle.chunks_exact(StateMsg::SIZE) {
            let Some(i) = sender_of(state).and_then(|s| self.senders.iter().position(|&x| x == s))
            else {
                let what = format!("a state of sender {:?}", sender_of(state));
                return self.fault(LinkError::Malformed(what));
            };
            match self.place(i, state) {
                Ok(d) => direct[i] |= d,
                Err(e) => return self.fault(e),
            }
        }
        for (inbox, _) in self.inboxes.iter().zip(direct).filter(|(_, d)| *d) {
            if let Some(d) = inbox.direct.get() {
                d.wake();
            }
        }
    }

    /// Delivers link `i`'s `state` directly (`true`) or queues it for its
    /// thread.
    fn place(&self, i: usize, state: &[u8]) -> Result<bool, LinkError> {
        let inbox = &self.inboxes[i];
        let mut q = lock(&inbox.queue);
        if inbox.direct(&q, state)? {
            drop(q);
            self.book(i)?;
            return Ok(true);
        }
        if q.len() >= self.depth {
            if self.lossless {
                let what = format!("node {}'s states beyond its window", self.senders[i]);
                return Err(LinkError::Malformed(what));
            }
            q.pop_front();
        }
        q.push_back(state.to_vec());
        inbox.ready.notify_one();
        Ok(false)
    }

    fn fault(&self, e: LinkError) {
        lock(&self.fault).get_or_insert(e);
        for i in &self.inboxes {
            i.ready.notify_all();
        }
    }

    /// Books one of link `i`'s states as delivered; acknowledges every
    /// link's count once the trunk has delivered `ack_every` since the
    /// last acknowledgement.
    fn book(&self, i: usize) -> Result<(), LinkError> {
        self.delivered[i].fetch_add(1, Ordering::SeqCst);
        if self.since_ack.fetch_add(1, Ordering::SeqCst) + 1 >= self.ack_every {
            self.ack()?;
        }
        Ok(())
    }

    /// Puts every link's delivered count.
    fn ack(&self) -> Result<(), LinkError> {
        *lock(&self.last_ack) = Instant::now();
        self.since_ack.store(0, Ordering::SeqCst);
        let counts = self.delivered.iter().map(|d| d.load(Ordering::SeqCst));
        let bytes = ack_bytes(&self.senders, counts);
        lock(&self.acks).put(bytes).wait().map_err(zerr)
    }
}

/// The receiving end of a trunk: its Zenoh subscriber (kept alive here)
/// and one [`TrunkInput`] per link.
pub struct TrunkReceiver {
    _data: Subscriber<()>,
    shared: Arc<Shared>,
}

impl TrunkReceiver {
    /// Declares the subscriber of `key` for the states of `senders` and
    /// the publisher of its acknowledgements, and says hello.
    pub fn open(
        session: &zenoh::Session,
        key: &str,
        senders: Vec<u32>,
        flow: Flow,
    ) -> Result<Self, LinkError> {
        let acks = express_publisher(session, super::keys::ack(key))?;
        let (depth, lossless, ack_every) = match flow {
            Flow::Window(w) => (to_usize(w.window) + 16, true, w.ack_every),
            Flow::Freshest { depth } => (depth, false, u64::MAX),
        };
        let shared = Arc::new(Shared {
            inboxes: (senders.iter())
                .map(|_| Inbox {
                    queue: Mutex::new(VecDeque::new()),
                    ready: Condvar::new(),
                    direct: std::sync::OnceLock::new(),
                    busy: Mutex::new(()),
                })
                .collect(),
            delivered: senders.iter().map(|_| AtomicU64::new(0)).collect(),
            senders,
            depth,
            lossless,
            fault: Mutex::new(None),
            acks: Mutex::new(acks),
            since_ack: AtomicU64::new(0),
            last_ack: Mutex::new(Instant::now()),
            ack_every,
        });
        let s = shared.clone();
        let data = (session.declare_subscriber(key.to_string()))
            .callback(move |m: Sample| s.sort(&m.payload().to_bytes()))
            .wait()
            .map_err(zerr)?;
        shared.ack()?;
        Ok(Self {
            _data: data,
            shared,
        })
    }

    /// The input of the link of `sender`, if the trunk carries it.
    #[must_use]
    pub fn input(&self, sender: u32) -> Option<TrunkInput> {
        let i = self.shared.senders.iter().position(|&s| s == sender)?;
        Some(TrunkInput {
            shared: self.shared.clone(),
            i,
        })
    }
}

fn to_usize(n: u64) -> usize {
    usize::try_from(n).unwrap_or(usize::MAX)
}

/// One link's end of a [`TrunkReceiver`], for its bridge thread.
pub struct TrunkInput {
    shared: Arc<Shared>,
    i: usize,
}

impl TrunkInput {
    /// Lets Zenoh's callback deliver this link's states itself when it
    /// can (set once; later calls are ignored).
    pub fn set_direct(&self, d: Arc<dyn Direct>) {
        let _ = self.shared.inboxes[self.i].direct.set(d);
    }

    /// Hands the next state to `deliver`, waiting at most `timeout` for
    /// one (`Ok(false)`: none came), and books it as delivered; no direct
    /// delivery overtakes it meanwhile. An idle trunk repeats its
    /// acknowledgement every [`HELLO_EVERY`].
    pub fn take<E: From<LinkError>>(
        &self,
        timeout: Duration,
        deliver: impl FnOnce(Vec<u8>) -> Result<(), E>,
    ) -> Result<bool, E> {
        let sh = &*self.shared;
        let inbox = &sh.inboxes[self.i];
        let mut q = lock(&inbox.queue);
        if q.is_empty() {
            q = (inbox.ready.wait_timeout(q, timeout))
                .unwrap_or_else(PoisonError::into_inner)
                .0;
        }
        if let Some(f) = lock(&sh.fault).clone() {
            return Err(f.into());
        }
        if q.is_empty() {
            drop(q);
            if lock(&sh.last_ack).elapsed() >= HELLO_EVERY {
                sh.ack()?;
            }
            return Ok(false);
        }
        drop(q);
        let _busy = lock(&inbox.busy);
        let Some(state) = lock(&inbox.queue).pop_front() else {
            return Ok(false); // only this thread takes: not reached
        };
        deliver(state)?;
        sh.book(self.i)?;
        Ok(true)
    }
}
