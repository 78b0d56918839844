//! A barrier that spins briefly, then blocks.
//!
//! The parallel engine meets at a barrier once per exchange and twice per
//! step. `std::sync::Barrier` takes its mutex on every wait (about a
//! microsecond each on this machine); here an arrival is one atomic add
//! and a waiter polls the generation up to [`SPINS`] times (a late thread
//! is usually a few µs behind: the shares are equal), then
//! sleeps on a condition variable (so a machine shared with other work is
//! not burnt by idle spinning).
//!
//! # NOTE
//! There is no phase of `yield_now` between the two: on a machine whose
//! cores are all taken, one yield hands the core away for a whole time
//! slice (5–15 ms measured here, with 15–20 runnable processes on 2
//! cores), long after the barrier opened, where a sleeper on the condition
//! variable is woken as soon as the last thread arrives. On an idle
//! machine a yield returns at once, like a poll.

use std::sync::atomic::{AtomicUsize, Ordering::SeqCst};
use std::sync::{Condvar, Mutex, PoisonError};

/// Polls of the generation before a waiter sleeps: ~50 µs on this machine
/// (a poll with its `pause` is ~25 ns on AMD Zen 4), a few times the
/// imbalance between equal shares and more than a wake-up from the
/// condition variable costs (tens of µs on a VM). Counted, not timed: the
/// model crate reads no clock.
pub const SPINS: u32 = 2_000;

/// A reusable barrier for a fixed number of threads.
#[derive(Debug)]
pub struct SpinBarrier {
    n: usize,
    arrived: AtomicUsize,
    generation: AtomicUsize,
    sleepers: AtomicUsize,
    lock: Mutex<()>,
    wake: Condvar,
}

impl SpinBarrier {
    /// A barrier for `n` ≥ 1 threads.
    #[must_use]
    pub fn new(n: usize) -> Self {
        assert!(n >= 1, "a barrier needs at least one thread");
        Self {
            n,
            arrived: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            sleepers: AtomicUsize::new(0),
            lock: Mutex::new(()),
            wake: Condvar::new(),
        }
    }

    /// Waits until all `n` threads have called `wait` in this generation.
    /// Everything a thread wrote before its `wait` is visible to every
    /// thread after theirs.
    pub fn wait(&self) {
        let generation = self.generation.load(SeqCst);
        if self.arrived.fetch_add(1, SeqCst) + 1 == self.n {
            self.arrived.store(0, SeqCst);
            self.generation.store(generation.wrapping_add(1), SeqCst);
            if self.sleepers.load(SeqCst) > 0 {
                let _held = self.lock.lock().unwrap_or_else(PoisonError::into_inner);
                self.wake.notify_all();
            }
            return;
        }
        for _ in 0..SPINS {
            if self.generation.load(SeqCst) != generation {
                return;
            }
            std::hint::spin_loop();
        }
        let mut held = self.lock.lock().unwrap_or_else(PoisonError::into_inner);
        self.sleepers.fetch_add(1, SeqCst);
        while self.generation.load(SeqCst) == generation {
            held = self.wake.wait(held).unwrap_or_else(PoisonError::into_inner);
        }
        self.sleepers.fetch_sub(1, SeqCst);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU64;

    #[test]
    fn no_thread_passes_before_all_arrived() {
        const THREADS: usize = 3;
        const ROUNDS: u64 = 2_000;
        let barrier = SpinBarrier::new(THREADS);
        let counter = AtomicU64::new(0);
        std::thread::scope(|s| {
            for _ in 0..THREADS {
                s.spawn(|| {
                    for round in 0..ROUNDS {
                        counter.fetch_add(1, SeqCst);
                        barrier.wait();
                        // Every thread added its 1 of this round, none of the next.
                        assert_eq!(counter.load(SeqCst), (round + 1) * THREADS as u64);
                        barrier.wait();
                    }
                });
            }
        });
        assert_eq!(counter.load(SeqCst), ROUNDS * THREADS as u64);
    }
}
