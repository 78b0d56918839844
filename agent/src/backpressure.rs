//! What a lockstep publisher does while a receiver's buffer is full.
//!
//! It sleeps rather than yields, so that a sender far ahead (the leader,
//! which has no inputs) leaves the core to the nodes it waits for — a yield
//! would hand it to any competitor for a whole time slice and keep the
//! sender runnable. How long it sleeps adapts ([`Pacer`]): a receiver takes
//! one message per exchange, so a fixed short pause woke the leader every
//! few exchanges to publish a few messages, and each wake-up (a timer, two
//! context switches) cost CPU that the nodes on the critical path needed
//! (BENCHMARKS.md, session 7). The pacer instead aims to refill about half
//! of the receiver's buffer per wake-up, which leaves the other half as
//! slack, so a receiver never waits for the paced sender as long as its
//! pace changes by less than 2× between two wake-ups.

use iceoryx2::port::{BackpressureAction, BackpressureInfo};
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::time::Duration;

/// Shortest pause (and the first).
pub const PAUSE_MIN: Duration = Duration::from_micros(50);
/// Longest pause: a paced sender still checks its receivers 1 000 times a second.
pub const PAUSE_MAX: Duration = Duration::from_millis(1);

/// The adaptive pause of one publisher; clones share it (the publisher's
/// backpressure handler and the code that sends).
#[derive(Debug, Clone)]
pub struct Pacer(Arc<State>);

#[derive(Debug)]
struct State {
    /// The receivers' buffer, messages.
    buffer: u32,
    /// Messages sent since the last pause.
    sent: AtomicU32,
    /// The current pause, ns.
    pause_ns: AtomicU64,
}

impl Pacer {
    /// A pacer for receivers that buffer `buffer` messages.
    #[must_use]
    pub fn new(buffer: usize) -> Self {
        Self(Arc::new(State {
            buffer: u32::try_from(buffer).unwrap_or(u32::MAX),
            sent: AtomicU32::new(0),
            pause_ns: AtomicU64::new(nanos(PAUSE_MIN)),
        }))
    }

    /// Records a message delivered to every receiver.
    pub fn sent(&self) {
        self.0.sent.fetch_add(1, Ordering::Relaxed);
    }

    /// A receiver's buffer is full: the pause to sleep now (adapted to the
    /// messages sent since the last one).
    pub fn pause(&self) -> Duration {
        let s = &self.0;
        let sent = s.sent.swap(0, Ordering::Relaxed);
        let now = Duration::from_nanos(s.pause_ns.load(Ordering::Relaxed));
        let next = next_pause(now, sent, s.buffer);
        s.pause_ns.store(nanos(next), Ordering::Relaxed);
        next
    }
}

fn nanos(d: Duration) -> u64 {
    u64::try_from(d.as_nanos()).unwrap_or(u64::MAX)
}

/// The pause after `pause` once `sent` messages went out between two full
/// buffers of `buffer` messages: doubled if they refilled less than a
/// quarter of it (the sender woke too often), halved if more than three
/// quarters (the receiver nearly ran dry), within [`PAUSE_MIN`, `PAUSE_MAX`].
#[must_use]
pub fn next_pause(pause: Duration, sent: u32, buffer: u32) -> Duration {
    let (low, high) = (buffer / 4, buffer - buffer / 4);
    if sent < low {
        (pause * 2).min(PAUSE_MAX)
    } else if sent > high {
        (pause / 2).max(PAUSE_MIN)
    } else {
        pause
    }
}

/// A backpressure handler: sleep for the pacer's pause and retry until
/// `timeout`, then give up on that receiver and fail the send (so nothing
/// hangs). It also gives up at once when the node's parent (the
/// orchestrator: [`msgs::parent::watched`] when the handler is made) is
/// gone: a dead receiver's buffer stays full, and a sender waiting on it
/// must still exit within a second of the orchestrator's death (PROTOCOL.md
/// § 6: a node exits if its parent process changes).
pub fn retry_until(
    timeout: Duration,
    pacer: Pacer,
) -> impl Fn(&BackpressureInfo) -> BackpressureAction + Send + 'static {
    retry_until_parent(timeout, pacer, msgs::parent::watched().ok())
}

/// [`retry_until`] for a node whose parent is `parent` (`None`: already
/// orphaned).
fn retry_until_parent(
    timeout: Duration,
    pacer: Pacer,
    parent: Option<u32>,
) -> impl Fn(&BackpressureInfo) -> BackpressureAction + Send + 'static {
    move |info| {
        let orphaned = || parent != Some(std::os::unix::process::parent_id());
        if info.elapsed_time > timeout || orphaned() {
            BackpressureAction::DiscardDataAndFail
        } else {
            std::thread::sleep(pacer.pause());
            BackpressureAction::Retry
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn full(elapsed: Duration) -> BackpressureInfo {
        BackpressureInfo {
            service_id: 0,
            sender_port_id: 0,
            receiver_port_id: 0,
            retries: 1,
            elapsed_time: elapsed,
        }
    }

    #[test]
    fn a_full_receiver_is_retried_until_the_timeout_or_the_parents_death() {
        let parent = std::os::unix::process::parent_id();
        let timeout = Duration::from_secs(10);
        let ours = retry_until_parent(timeout, Pacer::new(64), Some(parent));
        assert!(matches!(
            ours(&full(Duration::ZERO)),
            BackpressureAction::Retry
        ));
        let late = full(timeout + Duration::from_millis(1));
        assert!(matches!(
            ours(&late),
            BackpressureAction::DiscardDataAndFail
        ));
        // A parent that is not ours any more: the orchestrator died.
        let gone = retry_until_parent(timeout, Pacer::new(64), Some(parent.wrapping_add(1)));
        let now = gone(&full(Duration::ZERO));
        assert!(matches!(now, BackpressureAction::DiscardDataAndFail));
        // Orphaned before the handler was made.
        let gone = retry_until_parent(timeout, Pacer::new(64), None);
        let now = gone(&full(Duration::ZERO));
        assert!(matches!(now, BackpressureAction::DiscardDataAndFail));
    }

    #[test]
    fn a_sender_that_refills_little_per_wake_up_sleeps_longer_up_to_the_max() {
        let mut p = PAUSE_MIN;
        for _ in 0..20 {
            p = next_pause(p, 3, 64);
        }
        assert_eq!(p, PAUSE_MAX);
        assert_eq!(next_pause(PAUSE_MIN, 0, 64), PAUSE_MIN * 2);
    }

    #[test]
    fn a_receiver_nearly_drained_halves_the_pause_down_to_the_min() {
        assert_eq!(next_pause(PAUSE_MAX, 60, 64), PAUSE_MAX / 2);
        assert_eq!(next_pause(PAUSE_MIN, 64, 64), PAUSE_MIN);
    }

    #[test]
    fn about_half_a_buffer_per_wake_up_keeps_the_pause() {
        for sent in [16, 32, 48] {
            assert_eq!(next_pause(PAUSE_MIN * 4, sent, 64), PAUSE_MIN * 4);
        }
    }

    #[test]
    fn the_pacer_counts_sends_between_pauses() {
        let p = Pacer::new(64);
        let sender = p.clone();
        for _ in 0..3 {
            sender.sent();
        }
        assert_eq!(p.pause(), PAUSE_MIN * 2);
        // A retry of the same send (nothing went out) doubles again.
        assert_eq!(p.pause(), PAUSE_MIN * 4);
        for _ in 0..32 {
            sender.sent();
        }
        assert_eq!(p.pause(), PAUSE_MIN * 4);
    }
}
