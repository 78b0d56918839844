//! What this process has used: CPU time and peak memory.

use std::time::Duration;

/// The CPU time of `ticks` clock ticks.
fn ticks(ticks: u64) -> Duration {
    crate::times::TICK * u32::try_from(ticks).unwrap_or(u32::MAX)
}

/// CPU time this process has used so far (user + system, every thread,
/// finished ones included), to a clock tick (10 ms).
#[must_use]
pub fn cpu_time() -> Option<Duration> {
    let s = crate::stat::own().ok()?;
    Some(ticks(s.utime + s.stime))
}

/// [`cpu_time`] and that of the children this process has waited for, in
/// clock ticks.
#[must_use]
pub fn cpu_ticks_with_children() -> Option<u64> {
    let s = crate::stat::own().ok()?;
    Some(s.utime + s.stime + s.cutime + s.cstime)
}

/// Peak resident set size of this process (`VmHWM`), kB; 0 if unknown.
#[must_use]
pub fn peak_rss_kb() -> u64 {
    let status = crate::status::of(std::process::id()).unwrap_or_default();
    crate::status::number(&status, "VmHWM").unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_time_grows_with_work_and_memory_is_known() {
        let t0 = cpu_time().expect("own CPU time");
        let mut x = 0u64;
        while cpu_time().is_some_and(|t| t < t0 + Duration::from_millis(20)) {
            x = std::hint::black_box(x.wrapping_add(1));
        }
        assert!(x > 0);
        assert!(cpu_ticks_with_children().is_some_and(|t| t >= 2));
        assert!(peak_rss_kb() > 0);
    }
}
