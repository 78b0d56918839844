//! Waiting strategies for a stage's inputs (see [`WaitStrategy`]).
//!
//! `Adaptive`, the default, is built for a machine that may be shared:
//! - while the cores are ours it yields between polls, for at most
//!   [`YIELD_WINDOW`] of elapsed time per wait, then blocks;
//! - a yield that comes back only after [`STOLEN`] shows that another program
//!   got the core for a time slice (a yield hands the core to whoever is
//!   runnable, and a CPU-bound competitor keeps it for its whole slice). From
//!   then on the waiter blocks at once, for [`CONTENDED_HOLD`], and then tries
//!   yielding again.
//!
//! Blocking sleeps on the node's wake event in slices of [`BLOCK_SLICE`] and
//! the caller re-polls its subscribers after every wake, timeout or not, so
//! a wake-up that never comes costs one slice, never a stall.

use iceoryx2::port::listener::Listener;
use iceoryx2::service::Service;
use msgs::config::WaitStrategy;
use std::time::{Duration, Instant};

/// Most yields of an adaptive waiter in one wait before it blocks.
pub const ADAPTIVE_YIELDS: u32 = 200;
/// Longest an adaptive waiter yields in one wait before it blocks.
pub const YIELD_WINDOW: Duration = Duration::from_millis(2);
/// A yield that takes longer than this lost the core to another program.
pub const STOLEN: Duration = Duration::from_millis(3);
/// How long an adaptive waiter blocks at once after a stolen yield.
pub const CONTENDED_HOLD: Duration = Duration::from_secs(1);
/// Longest single sleep on the wake event.
pub const BLOCK_SLICE: Duration = Duration::from_millis(1);

/// Applies a [`WaitStrategy`] between polls.
#[derive(Debug)]
pub struct Waiter {
    strategy: WaitStrategy,
    polls: u32,
    /// When the current wait episode began (adaptive only).
    began: Instant,
    /// Adaptive: block at once until then (the cores are shared).
    contended_until: Option<Instant>,
    /// Times a yield was stolen (adaptive), for the node's report.
    stolen: u64,
    /// Longest single sleep on the wake event ([`BLOCK_SLICE`]).
    slice: Duration,
}

impl Waiter {
    /// A waiter with `strategy`.
    #[must_use]
    pub fn new(strategy: WaitStrategy) -> Self {
        Self {
            strategy,
            polls: 0,
            began: Instant::now(),
            contended_until: None,
            stolen: 0,
            slice: BLOCK_SLICE,
        }
    }

    /// The same with another longest sleep on the wake event (for the
    /// benchmark's test of whether wake-ups are lost: with a long slice a lost
    /// one shows as a stall).
    #[must_use]
    pub fn with_block_slice(mut self, slice: Duration) -> Self {
        self.slice = slice;
        self
    }

    /// Starts a new wait episode (a new stage's inputs).
    pub fn begin(&mut self) {
        self.polls = 0;
        if self.strategy == WaitStrategy::Adaptive {
            self.began = Instant::now();
        }
    }

    /// Polls in the current episode.
    #[must_use]
    pub fn polls(&self) -> u32 {
        self.polls
    }

    /// How many times an adaptive waiter found its core taken by another program.
    #[must_use]
    pub fn stolen(&self) -> u64 {
        self.stolen
    }

    /// Whether peers using this strategy may sleep, so senders must notify.
    #[must_use]
    pub fn receivers_may_block(&self) -> bool {
        matches!(self.strategy, WaitStrategy::Block | WaitStrategy::Adaptive)
    }

    /// Waits a little (per the strategy). Returns `true` if `deadline` has
    /// passed. The caller polls its subscribers after every call.
    pub fn wait<S: Service>(&mut self, listener: &Listener<S>, deadline: Instant) -> bool {
        self.polls = self.polls.wrapping_add(1);
        match self.strategy {
            WaitStrategy::Spin => std::hint::spin_loop(),
            WaitStrategy::Yield => std::thread::yield_now(),
            WaitStrategy::Block => block(listener, self.slice),
            WaitStrategy::Adaptive => self.adapt(listener),
        }
        // Checking the clock costs ~20 ns; spinning checks it every 64 polls.
        (self.strategy != WaitStrategy::Spin || self.polls % 64 == 0) && Instant::now() > deadline
    }

    /// One adaptive wait: yield while the core is ours and the wait is short,
    /// else block.
    fn adapt<S: Service>(&mut self, listener: &Listener<S>) {
        let now = Instant::now();
        match self.adaptive_step(now) {
            Step::Block => block(listener, self.slice),
            Step::Yield => {
                std::thread::yield_now();
                self.after_yield(now, Instant::now());
            }
        }
    }

    /// What an adaptive wait does at `now`.
    fn adaptive_step(&mut self, now: Instant) -> Step {
        if let Some(until) = self.contended_until {
            if now < until {
                return Step::Block;
            }
            self.contended_until = None;
        }
        if self.polls > ADAPTIVE_YIELDS || now.duration_since(self.began) > YIELD_WINDOW {
            Step::Block
        } else {
            Step::Yield
        }
    }

    /// Records a yield from `before` to `after`: if it took longer than
    /// [`STOLEN`], block at once for [`CONTENDED_HOLD`].
    fn after_yield(&mut self, before: Instant, after: Instant) {
        if after.duration_since(before) > STOLEN {
            self.stolen += 1;
            self.contended_until = Some(after + CONTENDED_HOLD);
        }
    }
}

/// What one adaptive wait does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    Yield,
    Block,
}

fn block<S: Service>(listener: &Listener<S>, slice: Duration) {
    let _ = listener.timed_wait(|_| {}, slice);
}

/// What a publisher does while a receiver's buffer is full: sleep briefly
/// rather than yield, so that a sender far ahead (the leader, which has no
/// inputs) leaves the core to the nodes it waits for — a yield would hand it
/// to any competitor for a whole time slice and keep the sender runnable.
pub fn backpressure_pause() {
    std::thread::sleep(BACKPRESSURE_SLEEP);
}

/// The pause of [`backpressure_pause`].
pub const BACKPRESSURE_SLEEP: Duration = Duration::from_micros(50);

#[cfg(test)]
mod tests {
    use super::*;

    fn adaptive(at: Instant) -> Waiter {
        let mut w = Waiter::new(WaitStrategy::Adaptive);
        w.began = at;
        w
    }

    #[test]
    fn adaptive_yields_within_its_window_then_blocks() {
        let t0 = Instant::now();
        let mut w = adaptive(t0);
        assert_eq!(w.adaptive_step(t0), Step::Yield);
        assert_eq!(w.adaptive_step(t0 + YIELD_WINDOW / 2), Step::Yield);
        assert_eq!(w.adaptive_step(t0 + YIELD_WINDOW * 2), Step::Block);
    }

    #[test]
    fn a_stolen_yield_makes_it_block_for_the_hold_then_yield_again() {
        let t0 = Instant::now();
        let mut w = adaptive(t0);
        // A quick yield (another node ran for a few µs) changes nothing.
        w.after_yield(t0, t0 + Duration::from_micros(20));
        assert_eq!((w.stolen(), w.adaptive_step(t0)), (0, Step::Yield));
        // A competitor kept the core for a time slice.
        let back = t0 + STOLEN * 2;
        w.after_yield(t0, back);
        assert_eq!(w.stolen(), 1);
        w.began = back;
        assert_eq!(w.adaptive_step(back), Step::Block);
        assert_eq!(w.adaptive_step(back + CONTENDED_HOLD / 2), Step::Block);
        // After the hold a new episode yields again (a probe).
        let later = back + CONTENDED_HOLD + Duration::from_millis(1);
        w.began = later;
        assert_eq!(w.adaptive_step(later), Step::Yield);
    }
}
