//! Small helpers of `attsync-bench run`: medians, background CPU load, and
//! the machine description. See `main.rs` for how to run the benchmark.

/// Median (mean of the two middle values for an even count); `None` if empty.
#[must_use]
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    })
}

/// Median of integers (lower middle for an even count).
#[must_use]
pub fn median_u64(values: &[u64]) -> Option<u64> {
    let mut v = values.to_vec();
    v.sort_unstable();
    v.get(v.len().saturating_sub(1) / 2).copied()
}

/// Clock ticks per second of `/proc` CPU times.
const TICKS: f64 = attsync_sched::times::USER_HZ as f64;

/// Ticks every core was busy (the workspace's one definition of busy:
/// [`attsync_sched::busy`]).
fn machine_busy_ticks() -> Option<u64> {
    Some(attsync_sched::times::read_now().ok()?.all.busy())
}

/// CPU time this process has used so far (user + system, every thread,
/// finished ones included), s; `/proc` resolution (10 ms).
#[must_use]
pub fn cpu_seconds() -> Option<f64> {
    attsync_sched::rusage::cpu_time().map(|t| t.as_secs_f64())
}

/// Measures how busy the machine was with *other* work during a
/// measurement: machine CPU time minus this process's and its waited-for
/// descendants' CPU time, per wall second (in cores).
#[derive(Debug, Clone, Copy)]
pub struct CpuMeter {
    busy: Option<u64>,
    mine: Option<u64>,
    t0: std::time::Instant,
}

impl CpuMeter {
    /// Starts measuring.
    #[must_use]
    pub fn start() -> Self {
        Self {
            busy: machine_busy_ticks(),
            mine: attsync_sched::rusage::cpu_ticks_with_children(),
            t0: std::time::Instant::now(),
        }
    }

    /// Cores' worth of CPU used by other processes since [`CpuMeter::start`]
    /// (call after the children have been waited for).
    #[must_use]
    pub fn foreign_cores(&self) -> Option<f64> {
        let busy = machine_busy_ticks()?.checked_sub(self.busy?)?;
        let mine = attsync_sched::rusage::cpu_ticks_with_children()?.checked_sub(self.mine?)?;
        let wall = self.t0.elapsed().as_secs_f64();
        (wall > 0.0).then(|| (busy as f64 - mine as f64).max(0.0) / TICKS / wall)
    }
}

/// Waits until the machine has been idle (other processes using under
/// `threshold` cores over half a second) or `max` has passed; returns whether
/// it was idle. Call it between measurements, when no child is running.
#[must_use]
pub fn wait_idle(threshold: f64, max: std::time::Duration) -> bool {
    let t0 = std::time::Instant::now();
    loop {
        let m = CpuMeter::start();
        std::thread::sleep(std::time::Duration::from_millis(500));
        match m.foreign_cores() {
            Some(c) if c < threshold => return true,
            None => return true,
            Some(_) if t0.elapsed() >= max => return false,
            Some(_) => {}
        }
    }
}

/// `nproc`, CPU model, RAM.
#[must_use]
pub fn machine() -> String {
    use attsync_sched::machine;
    let cpus = std::thread::available_parallelism().map_or(0, std::num::NonZero::get);
    let model = machine::cpu_model().unwrap_or_else(|| "unknown CPU".into());
    let ram = machine::mem_total().unwrap_or(0);
    format!(
        "{cpus} CPUs (nproc), {model}, {:.1} GiB RAM",
        ram as f64 / 1024.0 / 1024.0 / 1024.0
    )
}

/// The 1-, 5- and 15-minute load averages.
#[must_use]
pub fn loadavg() -> String {
    attsync_sched::machine::load_averages().unwrap_or_else(|| "?".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        assert_eq!(median_u64(&[9, 1, 5]), Some(5));
        assert_eq!(median_u64(&[4, 1, 2, 3]), Some(2));
        assert_eq!(median_u64(&[]), None);
    }

    #[test]
    fn cpu_seconds_grow_with_work() {
        let t0 = cpu_seconds();
        assert!(
            t0.is_some() || !cfg!(target_os = "linux"),
            "no CPU time on Linux"
        );
        let Some(t0) = t0 else { return };
        let mut x = 0u64;
        while cpu_seconds().is_some_and(|t| t < t0 + 0.02) {
            x = x.wrapping_add(1);
        }
        assert!(x > 0 && cpu_seconds().is_some_and(|t| t >= t0 + 0.02));
    }

    #[test]
    fn cpu_meter_reads_proc() {
        assert!(CpuMeter::start().foreign_cores().is_some() || !cfg!(target_os = "linux"));
    }
}
