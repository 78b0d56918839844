//! The step schedule, defined once: every stage `(n, s)` of a run in order,
//! whether it is an exchange, and its time. Every loop that steps a node —
//! the in-process engine, the node runtimes, `conform` — walks it.
//!
//! A step `n` covers `[n·dt, (n+1)·dt]` and has [`STAGES`] RKMK4 stages at
//! `t = (n + c_s)·dt`, `c = [0, ½, ½, 1]` ([`stage_time_fraction`]). Stage
//! `s` of step `n` is an exchange if the coupling says so
//! ([`Coupling::exchanges_at`]).

pub use crate::integrate::stage_time_fraction;
use crate::network::Coupling;

/// Stages per step (RKMK4).
pub const STAGES: u32 = 4;

/// One stage of the schedule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    /// Step n.
    pub step: u64,
    /// Stage s, 0..[`STAGES`].
    pub stage: u32,
    /// Whether nodes publish and read states at this stage.
    pub exchange: bool,
}

impl Slot {
    /// Fraction of the step at which the stage is evaluated, `c_s`.
    #[must_use]
    pub fn time_fraction(&self) -> f64 {
        stage_time_fraction(self.stage as usize)
    }

    /// Whether this is the first stage of its step.
    #[must_use]
    pub fn starts_step(&self) -> bool {
        self.stage == 0
    }

    /// Whether this is the last stage of its step (the step is done after it).
    #[must_use]
    pub fn ends_step(&self) -> bool {
        self.stage + 1 == STAGES
    }
}

/// The stages of a run of `steps` steps under `coupling`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Schedule {
    coupling: Coupling,
    steps: u64,
}

impl Schedule {
    /// The schedule of `steps` steps with `coupling`.
    #[must_use]
    pub fn new(coupling: Coupling, steps: u64) -> Self {
        Self { coupling, steps }
    }

    /// Steps in the run.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The four stages of step `n`.
    pub fn stages(&self, n: u64) -> impl Iterator<Item = Slot> + use<> {
        let coupling = self.coupling;
        (0..STAGES).map(move |s| Slot {
            step: n,
            stage: s,
            exchange: coupling.exchanges_at(n, s as usize),
        })
    }

    /// Every stage of the run, in order.
    pub fn slots(&self) -> impl Iterator<Item = Slot> + use<> {
        let me = *self;
        (0..self.steps).flat_map(move |n| me.stages(n))
    }

    /// Every exchange of the run, in order.
    pub fn exchanges(&self) -> impl Iterator<Item = Slot> + use<> {
        self.slots().filter(|s| s.exchange)
    }

    /// The stage after `slot` in the run (`None` after the run's last).
    #[must_use]
    pub fn next(&self, slot: Slot) -> Option<Slot> {
        let (step, stage) = if slot.ends_step() {
            (slot.step + 1, 0)
        } else {
            (slot.step, slot.stage + 1)
        };
        (step < self.steps).then(|| Slot {
            step,
            stage,
            exchange: self.coupling.exchanges_at(step, stage as usize),
        })
    }

    /// The first exchange at or after step `n`, if any.
    #[must_use]
    pub fn first_exchange_from(&self, n: u64) -> Option<Slot> {
        let me = *self;
        (n..self.steps)
            .flat_map(move |k| me.stages(k))
            .find(|s| s.exchange)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuous_coupling_exchanges_at_every_stage() {
        let s = Schedule::new(Coupling::Continuous, 3);
        let all: Vec<(u64, u32)> = s.exchanges().map(|x| (x.step, x.stage)).collect();
        assert_eq!(all.len(), 12);
        assert_eq!(all[5], (1, 1));
        assert!(s.slots().filter(Slot::ends_step).all(|x| x.stage == 3));
        assert_eq!(s.slots().filter(Slot::starts_step).count(), 3);
    }

    #[test]
    fn sampled_coupling_exchanges_at_stage_zero_of_every_kth_step() {
        let s = Schedule::new(Coupling::Sampled { every: 3 }, 10);
        let all: Vec<(u64, u32)> = s.exchanges().map(|x| (x.step, x.stage)).collect();
        assert_eq!(all, vec![(0, 0), (3, 0), (6, 0), (9, 0)]);
        assert_eq!(s.slots().count(), 40);
        let first = s.first_exchange_from(4).map(|x| (x.step, x.stage));
        assert_eq!(first, Some((6, 0)));
        assert_eq!(s.first_exchange_from(10), None);
    }

    #[test]
    fn next_walks_the_slots_in_order() {
        for coupling in [Coupling::Continuous, Coupling::Sampled { every: 3 }] {
            let s = Schedule::new(coupling, 7);
            let all: Vec<Slot> = s.slots().collect();
            for (a, b) in all.iter().zip(&all[1..]) {
                assert_eq!(s.next(*a), Some(*b));
            }
            assert_eq!(s.next(all[all.len() - 1]), None);
        }
    }

    #[test]
    fn stage_times_are_the_rkmk4_nodes() {
        let s = Schedule::new(Coupling::Continuous, 1);
        let c: Vec<f64> = s.stages(0).map(|x| x.time_fraction()).collect();
        assert_eq!(c, vec![0.0, 0.5, 0.5, 1.0]);
    }
}
