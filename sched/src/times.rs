//! The one parser of `/proc/stat`'s CPU lines: where every CPU's time went
//! since boot, in clock ticks (`cpu  user nice system idle iowait irq
//! softirq steal guest guest_nice`, then one `cpuN` line per core).

use crate::error::{ProcError, read};
use std::time::Duration;

/// Clock ticks per second of the CPU times of `/proc` (`USER_HZ`: 100 on
/// every Linux architecture attsync runs on).
pub const USER_HZ: u64 = 100;

/// One clock tick of `/proc`'s CPU times.
pub const TICK: Duration = Duration::from_nanos(1_000_000_000 / USER_HZ);

/// Where one CPU's (or every CPU's) time went, clock ticks. `guest` and
/// `guest_nice` are left out: the kernel counts them in `user` and `nice`
/// already.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CpuTimes {
    /// Running processes in user mode.
    pub user: u64,
    /// Running niced processes in user mode.
    pub nice: u64,
    /// Running the kernel for processes.
    pub system: u64,
    /// Nothing to run.
    pub idle: u64,
    /// Nothing to run while waiting for I/O.
    pub iowait: u64,
    /// Serving interrupts.
    pub irq: u64,
    /// Serving deferred interrupt work.
    pub softirq: u64,
    /// Wanting to run while the hypervisor ran another virtual machine.
    pub steal: u64,
}

/// `/proc/stat`'s CPU lines.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Times {
    /// Every CPU together (the `cpu` line).
    pub all: CpuTimes,
    /// Each online core, by number (the `cpuN` lines).
    pub cores: Vec<(usize, CpuTimes)>,
}

/// The times of one CPU line's numbers (missing ones 0: older kernels
/// write fewer).
fn cpu_times(numbers: &str) -> CpuTimes {
    let v: Vec<u64> = numbers
        .split_whitespace()
        .map_while(|x| x.parse().ok())
        .collect();
    let at = |i: usize| v.get(i).copied().unwrap_or(0);
    CpuTimes {
        user: at(0),
        nice: at(1),
        system: at(2),
        idle: at(3),
        iowait: at(4),
        irq: at(5),
        softirq: at(6),
        steal: at(7),
    }
}

/// Parses the text of `/proc/stat` (its other lines are ignored).
#[must_use]
pub fn parse(text: &str) -> Times {
    let mut times = Times::default();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("cpu") else {
            continue;
        };
        let (num, numbers) = rest.split_once(' ').unwrap_or((rest, ""));
        if num.is_empty() {
            times.all = cpu_times(numbers);
        } else if let Ok(core) = num.parse() {
            times.cores.push((core, cpu_times(numbers)));
        }
    }
    times
}

/// `/proc/stat` now.
pub fn read_now() -> Result<Times, ProcError> {
    read("/proc/stat").map(|t| parse(&t))
}

#[cfg(test)]
mod tests {
    use super::*;

    const STAT: &str = "cpu  100 2 30 400 5 6 7 8 9 10\n\
        cpu0 60 1 20 150 3 4 5 6 9 10\n\
        cpu1 40 1 10 250 2 2 2 2 0 0\n\
        intr 12345 1 2\nctxt 999\nbtime 1700000000\nprocesses 4242\n";

    #[test]
    fn every_cpu_and_each_core_are_read_guest_time_left_out() {
        let t = parse(STAT);
        assert_eq!(
            t.all,
            CpuTimes {
                user: 100,
                nice: 2,
                system: 30,
                idle: 400,
                iowait: 5,
                irq: 6,
                softirq: 7,
                steal: 8,
            }
        );
        assert_eq!(t.cores.len(), 2);
        assert_eq!((t.cores[1].0, t.cores[1].1.idle), (1, 250));
    }

    #[test]
    fn an_old_kernels_short_line_reads_zero_for_the_rest() {
        let t = parse("cpu  1 2 3 4\ncpu3 1 2 3 4\n");
        assert_eq!((t.all.idle, t.all.steal), (4, 0));
        assert_eq!(t.cores[0].0, 3);
        assert!(!read_now().expect("/proc/stat").cores.is_empty());
    }
}
