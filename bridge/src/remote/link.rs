//! A lossless, ordered, bounded byte stream between two Zenoh sessions: data
//! on a key, cumulative acknowledgements on `<key>/ack`. Zenoh carries the
//! data reliably and in order (TCP, congestion control `Block`); the credit
//! window bounds what is in flight, so a fast sender (the leader) is held
//! back across hosts as iceoryx2's subscriber buffer holds it on one, and
//! the receiver's queue never fills (a full queue would stall its session).
//!
//! Every message goes out at once (`express`: not held back to be batched;
//! lockstep waits for each one, so its latency is the run's pace).
//!
//! A real-time link ([`Flow::Freshest`]) is not lossless: like a network it
//! carries what it can, newest first — no window, and the receiver keeps
//! only its newest messages, so an age of information across hosts is the
//! network's, not a window's. (Zenoh's congestion control stays `Block`:
//! with `Drop` a quarter of the states on a 20 ms link were lost in Zenoh's
//! own queue, and the ages were older.)
//!
//! Readiness: the receiver declares its subscriber, then acknowledges
//! (count 0) every [`HELLO_EVERY`] until data flows; the sender sends nothing
//! before its first acknowledgement, so no message is put before the other
//! end listens.

use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::handlers::{FifoChannel, FifoChannelHandler, RingChannel, RingChannelHandler};
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::Sample;

/// How often an idle receiver repeats its acknowledgement (the hello).
pub const HELLO_EVERY: Duration = Duration::from_millis(100);

/// A link's window: at most `window` messages unacknowledged, acknowledged
/// every `ack_every`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// Messages in flight at most.
    pub window: u64,
    /// The receiver acknowledges after this many.
    pub ack_every: u64,
}

/// What a link does with messages it cannot carry at once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    /// Lossless and ordered: the sender holds back beyond a window.
    Window(Window),
    /// Newest first (real time): no window, the receiver keeps its newest
    /// `depth` messages.
    Freshest {
        /// Messages the receiver keeps, the oldest dropped first.
        depth: usize,
    },
}

/// Telemetry links: as deep as the orchestrator's telemetry buffer.
pub const TELEMETRY_WINDOW: Flow = Flow::Window(Window {
    window: 256,
    ack_every: 64,
});

impl Flow {
    /// At most this many messages unacknowledged.
    fn window(self) -> u64 {
        match self {
            Self::Window(w) => w.window,
            Self::Freshest { .. } => u64::MAX,
        }
    }
}

/// A link failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinkError {
    /// Zenoh refused a call.
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// No credit came back in time: the other end is gone or stalled.
    #[error("no acknowledgement for {0:.1} s")]
    Stalled(f64),
    /// The run is ending.
    #[error("stopped")]
    Stopped,
    /// What arrived is not what the link carries (not a whole number of
    /// states, a sender it does not carry, a state that cannot be read).
    #[error("received {0}")]
    Malformed(String),
}

fn zerr(e: impl std::fmt::Display) -> LinkError {
    LinkError::Zenoh(e.to_string())
}

/// A reliable publisher of `key` that sends each message at once
/// (`express`) and blocks rather than drops (`Block`).
pub(super) fn express_publisher(
    session: &zenoh::Session,
    key: String,
) -> Result<Publisher<'static>, LinkError> {
    (session.declare_publisher(key))
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(zerr)
}

/// Acknowledged count (`None` before the hello), shared with the ack callback.
type Acked = Arc<(Mutex<Option<u64>>, Condvar)>;

/// The sending end.
pub struct LinkSender {
    publisher: Publisher<'static>,
    acked: Acked,
    _acks: Subscriber<()>,
    sent: u64,
    flow: Flow,
}

impl LinkSender {
    /// Declares the publisher of `key` and the subscriber of its acks.
    pub fn open(session: &zenoh::Session, key: &str, flow: Flow) -> Result<Self, LinkError> {
        let publisher = express_publisher(session, key.to_string())?;
        let acked: Acked = Arc::new((Mutex::new(None), Condvar::new()));
        let a = acked.clone();
        let acks = session
            .declare_subscriber(super::keys::ack(key))
            .callback(move |s: Sample| {
                let Ok(b) = <[u8; 8]>::try_from(s.payload().to_bytes().as_ref()) else {
                    return;
                };
                let n = u64::from_le_bytes(b);
                let (m, cv) = &*a;
                let mut g = m.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                *g = Some(g.map_or(n, |old| old.max(n)));
                cv.notify_all();
            })
            .wait()
            .map_err(zerr)?;
        Ok(Self {
            publisher,
            acked,
            _acks: acks,
            sent: 0,
            flow,
        })
    }

    /// Whether the receiver has said hello.
    #[must_use]
    pub fn connected(&self) -> bool {
        self.acked.0.lock().is_ok_and(|g| g.is_some())
    }

    /// Whether a message may be sent now: the receiver said hello and the
    /// window has room.
    #[must_use]
    pub fn has_credit(&self) -> bool {
        let g = self
            .acked
            .0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        g.is_some_and(|a| self.sent - a < self.flow.window())
    }

    /// Sends `bytes` now (call after [`Self::has_credit`]).
    pub fn send_now(&mut self, bytes: Vec<u8>) -> Result<(), LinkError> {
        self.publisher.put(bytes).wait().map_err(zerr)?;
        self.sent += 1;
        Ok(())
    }

    /// Sends `bytes` once the window has room; waits at most `timeout`,
    /// giving up early when `stop()` says so.
    pub fn send(
        &mut self,
        bytes: Vec<u8>,
        timeout: Duration,
        stop: &dyn Fn() -> bool,
    ) -> Result<(), LinkError> {
        let deadline = Instant::now() + timeout;
        let (m, cv) = &*self.acked;
        let mut g = m.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        while g.is_none_or(|a| self.sent - a >= self.flow.window()) {
            if stop() {
                return Err(LinkError::Stopped);
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(LinkError::Stalled(timeout.as_secs_f64()));
            }
            let slice = left.min(Duration::from_millis(20));
            g = cv
                .wait_timeout(g, slice)
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .0;
        }
        drop(g);
        self.send_now(bytes)
    }
}

/// A receiver's queue: a FIFO that holds a whole window (lossless), or a
/// ring that drops its oldest (newest first).
enum Inbox {
    Fifo(Subscriber<FifoChannelHandler<Sample>>),
    Ring(Subscriber<RingChannelHandler<Sample>>),
}

impl Inbox {
    fn declare(session: &zenoh::Session, key: &str, flow: Flow) -> Result<Self, LinkError> {
        let sub = session.declare_subscriber(key.to_string());
        Ok(match flow {
            Flow::Window(w) => {
                let capacity = usize::try_from(w.window).unwrap_or(usize::MAX) + 16;
                Self::Fifo(sub.with(FifoChannel::new(capacity)).wait().map_err(zerr)?)
            }
            Flow::Freshest { depth } => {
                Self::Ring(sub.with(RingChannel::new(depth)).wait().map_err(zerr)?)
            }
        })
    }

    fn recv_timeout(&self, timeout: Duration) -> Result<Option<Sample>, LinkError> {
        match self {
            Self::Fifo(s) => s.recv_timeout(timeout).map_err(zerr),
            Self::Ring(s) => s.recv_timeout(timeout).map_err(zerr),
        }
    }
}

/// The receiving end.
pub struct LinkReceiver {
    data: Inbox,
    acks: Publisher<'static>,
    delivered: u64,
    last_ack: Instant,
    flow: Flow,
}

impl LinkReceiver {
    /// Declares the subscriber of `key` (its queue as `flow` says) and the
    /// publisher of its acks, and says hello.
    pub fn open(session: &zenoh::Session, key: &str, flow: Flow) -> Result<Self, LinkError> {
        let data = Inbox::declare(session, key, flow)?;
        let acks = express_publisher(session, super::keys::ack(key))?;
        let r = Self {
            data,
            acks,
            delivered: 0,
            last_ack: Instant::now(),
            flow,
        };
        r.ack()?;
        Ok(r)
    }

    fn ack(&self) -> Result<(), LinkError> {
        (self.acks)
            .put(self.delivered.to_le_bytes().to_vec())
            .wait()
            .map_err(zerr)
    }

    /// The next message, waiting at most `timeout`; an idle receiver
    /// repeats its acknowledgement every [`HELLO_EVERY`].
    pub fn recv(&mut self, timeout: Duration) -> Result<Option<Vec<u8>>, LinkError> {
        let got = self.data.recv_timeout(timeout)?;
        if got.is_none() && self.last_ack.elapsed() >= HELLO_EVERY {
            self.last_ack = Instant::now();
            self.ack()?;
        }
        Ok(got.map(|s| s.payload().to_bytes().into_owned()))
    }

    /// Books one message as delivered (acknowledged every `ack_every` of
    /// a window; a newest-first link needs no acknowledgement).
    pub fn delivered(&mut self) -> Result<(), LinkError> {
        self.delivered += 1;
        let Flow::Window(w) = self.flow else {
            return Ok(());
        };
        if self.delivered % w.ack_every == 0 {
            self.last_ack = Instant::now();
            self.ack()?;
        }
        Ok(())
    }
}
