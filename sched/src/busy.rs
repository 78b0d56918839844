//! The one definition of a busy core, for the placement (is the machine
//! busy with other programs?) and the benchmark (was it, while measuring?).
//!
//! A core is busy while it runs something of this machine: a process in
//! user mode (`user`, `nice`), the kernel on a process's behalf (`system`),
//! or an interrupt (`irq`, `softirq`). It is not busy while idle, waiting
//! for I/O (`iowait`, idle by another name), or while the hypervisor runs
//! another virtual machine (`steal`).
//!
//! Why steal is not busy: busy time is compared with the CPU time of
//! attsync's own processes to find what *other programs* used (the
//! placement's foreign load, the benchmark's background load), and a
//! process's CPU time (`/proc/<pid>/stat`, `schedstat`) never includes
//! steal. Counting steal as busy would charge the hypervisor's other guests
//! to the programs of this machine, and most of it would be stolen from
//! attsync's own nodes: the placement would pack a run because its own
//! virtual CPUs were starved, which packing cannot help (no program here is
//! the competitor), and the benchmark would wait for an "idle" machine that
//! nothing on it keeps busy.

use crate::times::CpuTimes;

impl CpuTimes {
    /// Ticks the CPU was busy (see the module's docs): `user + nice +
    /// system + irq + softirq`.
    #[must_use]
    pub fn busy(&self) -> u64 {
        self.user + self.nice + self.system + self.irq + self.softirq
    }

    /// Every tick the CPU had, busy or not: busy, `idle`, `iowait` and
    /// `steal`.
    #[must_use]
    pub fn total(&self) -> u64 {
        self.busy() + self.idle + self.iowait + self.steal
    }
}

/// Busy and total ticks of a CPU between two readings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Span {
    /// Ticks busy.
    pub busy: u64,
    /// Every tick.
    pub total: u64,
}

impl Span {
    /// From reading `earlier` to reading `later` (0 where a counter went
    /// back, as a CPU taken offline and back may make it).
    #[must_use]
    pub fn between(earlier: &CpuTimes, later: &CpuTimes) -> Self {
        Self {
            busy: later.busy().saturating_sub(earlier.busy()),
            total: later.total().saturating_sub(earlier.total()),
        }
    }

    /// The busy fraction (0 for an empty span).
    #[must_use]
    pub fn fraction(&self) -> f64 {
        if self.total == 0 {
            0.0
        } else {
            self.busy as f64 / self.total as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `user nice system idle iowait irq softirq steal`.
    fn times(v: [u64; 8]) -> CpuTimes {
        let [user, nice, system, idle, iowait, irq, softirq, steal] = v;
        CpuTimes {
            user,
            nice,
            system,
            idle,
            iowait,
            irq,
            softirq,
            steal,
        }
    }

    #[test]
    fn busy_is_what_ran_here_steal_idle_and_iowait_are_not() {
        let t = times([10, 1, 5, 100, 7, 2, 3, 50]);
        assert_eq!(t.busy(), 21);
        assert_eq!(t.total(), 178);
        let from_proc = crate::times::parse("cpu  10 1 5 100 7 2 3 50 4 0\n").all;
        assert_eq!((from_proc.busy(), from_proc.total()), (21, 178));
    }

    #[test]
    fn a_span_is_the_difference_and_its_fraction_is_busy_over_total() {
        let a = times([10, 0, 0, 10, 0, 0, 0, 0]);
        let b = times([40, 0, 0, 20, 0, 0, 0, 40]);
        let s = Span::between(&a, &b);
        assert_eq!(
            s,
            Span {
                busy: 30,
                total: 80
            }
        );
        assert!((s.fraction() - 0.375).abs() < 1e-12);
        assert_eq!(Span::between(&b, &a), Span::default());
        assert_eq!(Span::default().fraction(), 0.0);
    }
}
