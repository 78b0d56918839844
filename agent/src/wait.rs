//! Waiting strategies for a stage's inputs (see [`WaitStrategy`]).

use iceoryx2::port::listener::Listener;
use iceoryx2::service::Service;
use msgs::config::WaitStrategy;
use std::time::{Duration, Instant};

/// Yields before an adaptive waiter starts to block.
const ADAPTIVE_YIELDS: u32 = 200;
/// Longest single sleep on the wake event: a lost wake-up costs at most this.
const BLOCK_SLICE: Duration = Duration::from_millis(1);

/// Applies a [`WaitStrategy`] between polls.
#[derive(Debug)]
pub struct Waiter {
    strategy: WaitStrategy,
    polls: u32,
}

impl Waiter {
    /// A waiter with `strategy`.
    #[must_use]
    pub fn new(strategy: WaitStrategy) -> Self {
        Self { strategy, polls: 0 }
    }

    /// Starts a new wait episode (a new stage's inputs).
    pub fn begin(&mut self) {
        self.polls = 0;
    }

    /// Polls in the current episode.
    #[must_use]
    pub fn polls(&self) -> u32 {
        self.polls
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
            WaitStrategy::Block => block(listener),
            WaitStrategy::Adaptive => {
                if self.polls <= ADAPTIVE_YIELDS {
                    std::thread::yield_now();
                } else {
                    block(listener);
                }
            }
        }
        // Checking the clock costs ~20 ns; spinning checks it every 64 polls.
        (self.strategy != WaitStrategy::Spin || self.polls % 64 == 0) && Instant::now() > deadline
    }
}

fn block<S: Service>(listener: &Listener<S>) {
    let _ = listener.timed_wait(|_| {}, BLOCK_SLICE);
}
