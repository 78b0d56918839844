//! A barrier that spins briefly, then blocks.
//!
//! The parallel engine meets at a barrier once per exchange and twice per
//! step. `std::sync::Barrier` takes its mutex on every wait (about a
//! microsecond each on this machine); here an arrival is one atomic add
//! and a waiter spins for up to [`SPINS`] polls of the generation, then
//! yields its core up to [`YIELDS`] times (a late thread may be waiting for
//! it), then sleeps on a condition variable (so a machine shared with other
//! work is not burnt by idle spinning).

use std::sync::atomic::{AtomicUsize, Ordering::SeqCst};
use std::sync::{Condvar, Mutex, PoisonError};

/// Polls of the generation before a waiter yields (about a µs).
pub const SPINS: u32 = 1_000;

/// Yields before a waiter sleeps.
pub const YIELDS: u32 = 16;

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
        for _ in 0..YIELDS {
            if self.generation.load(SeqCst) != generation {
                return;
            }
            std::thread::yield_now();
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
