//! Waiting strategies for a stage's inputs (see [`WaitStrategy`]).
//!
//! `Adaptive`, the default, is built for a machine that may be shared:
//! - while the cores are ours it yields between polls, for at most
//!   [`YIELD_WINDOW`] of elapsed time per wait, then blocks;
//! - a yield that comes back only after [`STOLEN`] shows that another program
//!   got the core for a time slice (a yield hands the core to whoever is
//!   runnable, and a CPU-bound competitor keeps it for its whole slice). From
//!   then on the waiter blocks at once, for a hold, and then tries yielding
//!   again. The first hold is [`HOLD_MIN`]; a probe that is stolen again
//!   doubles it, up to [`HOLD_MAX`]; a clean probe resets it. A lone hiccup
//!   of an idle machine (a vCPU descheduled by the hypervisor for a few ms)
//!   thus costs 20 ms of blocking, not a second, while a lasting competitor
//!   is probed only about once a second.
//! - where the orchestrator places the run ([`Contention::Placement`]) it
//!   moves the nodes off cores that competitors use, and the waiter starts
//!   a hold only after [`PLACED_STREAK`] stolen yields in a row: with more
//!   of the run's own processes than cores a yield comes back late on an
//!   idle machine too (100 nodes on 2 cores: 10–40 per node per second, one
//!   at a time), and blocking after each made such runs 2–5× slower than
//!   plain yielding (BENCHMARKS.md, session 6); but a competitor the
//!   placement could not move (the run packed onto a core that a CPU-bound
//!   program keeps) takes every yield, and yielding on to it made the paper
//!   run 3–25× slower than its idle time (session 16).
//!
//! Blocking sleeps on the node's wake event in slices of [`BLOCK_SLICE`] and
//! the caller re-polls its subscribers after every wake, timeout or not, so
//! a wake-up that never comes costs one slice, never a stall.

use iceoryx2::port::listener::Listener;
use iceoryx2::service::Service;
use msgs::config::{Contention, WaitStrategy};
use std::time::{Duration, Instant};

/// Most yields of an adaptive waiter in one wait before it blocks.
pub const ADAPTIVE_YIELDS: u32 = 200;
/// Longest an adaptive waiter yields in one wait before it blocks.
pub const YIELD_WINDOW: Duration = Duration::from_millis(2);
/// A yield that takes longer than this lost the core to another program.
pub const STOLEN: Duration = Duration::from_millis(3);
/// How long an adaptive waiter blocks at once after a first stolen yield.
pub const HOLD_MIN: Duration = Duration::from_millis(20);
/// The longest hold: after stolen probes in a row the hold doubles up to this.
pub const HOLD_MAX: Duration = Duration::from_secs(1);
/// Longest single sleep on the wake event.
pub const BLOCK_SLICE: Duration = Duration::from_millis(1);
/// Stolen yields in a row that start a hold where the orchestrator places
/// the run ([`Contention::Placement`]); one does elsewhere.
pub const PLACED_STREAK: u32 = 3;

/// Applies a [`WaitStrategy`] between polls.
#[derive(Debug)]
pub struct Waiter {
    strategy: WaitStrategy,
    polls: u32,
    /// When the current wait episode began (adaptive only).
    began: Instant,
    /// Adaptive: block at once until then (the cores are shared).
    contended_until: Option<Instant>,
    /// The current hold: [`HOLD_MIN`] doubled per stolen probe in a row.
    hold: Duration,
    /// Whether the next yield is the probe that ends a hold.
    probing: bool,
    /// Times a yield was stolen (adaptive), for the node's report.
    stolen: u64,
    /// Stolen yields since the last clean one.
    in_a_row: u32,
    /// Stolen yields in a row that start a hold (1, or [`PLACED_STREAK`]).
    streak: u32,
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
            hold: HOLD_MIN,
            probing: false,
            stolen: 0,
            in_a_row: 0,
            streak: 1,
            slice: BLOCK_SLICE,
        }
    }

    /// The same for a node whose competitors are handled by `contention`:
    /// with [`Contention::Placement`] only [`PLACED_STREAK`] stolen yields
    /// in a row start a hold.
    #[must_use]
    pub fn with_contention(mut self, contention: Contention) -> Self {
        self.streak = match contention {
            Contention::Waiter => 1,
            Contention::Placement => PLACED_STREAK,
        };
        self
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
            self.probing = true;
        }
        if self.polls > ADAPTIVE_YIELDS || now.duration_since(self.began) > YIELD_WINDOW {
            Step::Block
        } else {
            Step::Yield
        }
    }

    /// Records a yield from `before` to `after`: if it took longer than
    /// [`STOLEN`] and is the streak's last in a row, block at once for the
    /// hold (doubled if this yield was the probe ending the previous hold); a
    /// clean yield ends the streak, a clean probe resets the hold.
    fn after_yield(&mut self, before: Instant, after: Instant) {
        let probe = std::mem::take(&mut self.probing);
        if after.duration_since(before) > STOLEN {
            self.stolen += 1;
            self.in_a_row = self.in_a_row.saturating_add(1);
            if self.in_a_row < self.streak {
                return;
            }
            self.hold = if probe {
                (self.hold * 2).min(HOLD_MAX)
            } else {
                HOLD_MIN
            };
            self.contended_until = Some(after + self.hold);
        } else {
            self.in_a_row = 0;
            if probe {
                self.hold = HOLD_MIN;
            }
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
        assert_eq!(w.adaptive_step(back + HOLD_MIN / 2), Step::Block);
        // After the hold a new episode yields again (a probe).
        let later = back + HOLD_MIN + Duration::from_millis(1);
        w.began = later;
        assert_eq!(w.adaptive_step(later), Step::Yield);
    }

    /// Ends the current hold at `at` with a probe that takes `took`; returns
    /// the hold that follows (zero: none).
    fn probe(w: &mut Waiter, at: Instant, took: Duration) -> Duration {
        let until = w.contended_until.expect("in a hold");
        assert!(at >= until);
        w.began = at;
        assert_eq!(w.adaptive_step(at), Step::Yield);
        w.after_yield(at, at + took);
        w.contended_until
            .map_or(Duration::ZERO, |u| u.duration_since(at + took))
    }

    #[test]
    fn stolen_probes_in_a_row_double_the_hold_up_to_the_max_and_a_clean_one_resets_it() {
        let t0 = Instant::now();
        let mut w = adaptive(t0);
        let stolen = STOLEN * 2;
        w.after_yield(t0, t0 + stolen);
        let mut at = t0 + stolen;
        let mut expected = HOLD_MIN;
        for _ in 0..10 {
            at += expected;
            expected = (expected * 2).min(HOLD_MAX);
            assert_eq!(probe(&mut w, at, stolen), expected);
            at += stolen;
        }
        assert_eq!(expected, HOLD_MAX);
        // A clean probe: no hold, and the next stolen yield starts again at the minimum.
        at += expected;
        assert_eq!(probe(&mut w, at, Duration::from_micros(10)), Duration::ZERO);
        w.after_yield(at, at + stolen);
        assert_eq!(w.contended_until, Some(at + stolen + HOLD_MIN));
    }

    #[test]
    fn where_the_orchestrator_places_the_run_lone_stolen_yields_are_counted_but_never_block() {
        let t0 = Instant::now();
        let mut w = adaptive(t0).with_contention(Contention::Placement);
        let mut at = t0;
        // Stolen yields with clean ones between them: the run's own processes.
        for _ in 0..10 {
            w.after_yield(at, at + STOLEN * 2);
            at += STOLEN * 2;
            w.after_yield(at, at + Duration::from_micros(5));
            at += Duration::from_micros(5);
        }
        assert_eq!(w.stolen(), 10);
        assert_eq!(w.contended_until, None);
        w.began = at;
        assert_eq!(w.adaptive_step(at), Step::Yield);
        // The window still ends a long wait in blocking.
        assert_eq!(w.adaptive_step(at + YIELD_WINDOW * 2), Step::Block);
    }

    #[test]
    fn where_the_orchestrator_places_the_run_stolen_yields_in_a_row_start_a_hold() {
        let t0 = Instant::now();
        let mut w = adaptive(t0).with_contention(Contention::Placement);
        let mut at = t0;
        for k in 1..=PLACED_STREAK {
            w.after_yield(at, at + STOLEN * 2);
            at += STOLEN * 2;
            assert_eq!(w.contended_until.is_some(), k == PLACED_STREAK, "after {k}");
        }
        w.began = at;
        assert_eq!(w.adaptive_step(at), Step::Block);
        // The probe after the hold is stolen again: the hold doubles at once.
        at += HOLD_MIN + Duration::from_millis(1);
        assert_eq!(probe(&mut w, at, STOLEN * 2), HOLD_MIN * 2);
    }
}
