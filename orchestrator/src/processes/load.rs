//! The machine's CPU load as [`super::placement`] needs it: busy time per
//! core (`/proc/stat`) and the CPU time of the run's own processes
//! (`/proc/<pid>/stat`), in clock ticks, turned into a
//! [`Window`] per sampling period.

use super::placement::{
    Cores, FIRST_WINDOW, HYSTERESIS, Placed, Placement, State, WINDOW, Window, decide, least_busy,
    place,
};
use std::sync::atomic::{AtomicBool, Ordering};

/// Busy and total ticks of each core, by core number.
fn per_core_ticks() -> Vec<(usize, u64, u64)> {
    let Ok(stat) = std::fs::read_to_string("/proc/stat") else {
        return Vec::new();
    };
    stat.lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("cpu")?;
            let (num, fields) = rest.split_once(' ')?;
            let core = num.parse().ok()?;
            let v: Vec<u64> = fields
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            // user nice system idle iowait irq softirq steal …: busy is
            // what ran in this VM (steal — the hypervisor running someone
            // else's VM — is not a competitor we could avoid by packing).
            let at = |i: usize| v.get(i).copied().unwrap_or(0);
            let busy = at(0) + at(1) + at(2) + at(5) + at(6);
            let total: u64 = v.iter().take(8).sum();
            Some((core, busy, total))
        })
        .collect()
}

/// Time `task` spent on a CPU, ns (`/proc/.../schedstat`: exact, where
/// `/proc/<pid>/stat`'s utime and stime are cut to 10 ms ticks, an error of
/// up to a tick per process per sample).
fn task_ns(task: &std::path::Path) -> u64 {
    std::fs::read_to_string(task.join("schedstat"))
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

/// CPU time of every thread of process `pid` (`self` for this one), ns.
fn process_ns(pid: &str) -> u64 {
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return 0;
    };
    tasks.flatten().map(|t| task_ns(&t.path())).sum()
}

/// Nanoseconds per tick of `/proc/stat` (`USER_HZ`, 100 on Linux).
const NS_PER_TICK: u64 = 10_000_000;

/// One sample: per-core (busy, total) ticks and the run's own CPU time, ns.
struct Sample {
    cores: Vec<(usize, u64, u64)>,
    own: u64,
}

fn sample(pids: &[u32], allowed: &[usize]) -> Sample {
    let cores = per_core_ticks()
        .into_iter()
        .filter(|(c, _, _)| allowed.contains(c))
        .collect();
    let own = pids.iter().map(|p| process_ns(&p.to_string())).sum::<u64>() + process_ns("self");
    Sample { cores, own }
}

/// The window between two samples.
fn window(a: &Sample, b: &Sample) -> Window {
    let mut busy = 0u64;
    let mut span = 0u64;
    let mut per_core = Vec::new();
    for (&(core, b0, t0), &(_, b1, t1)) in a.cores.iter().zip(&b.cores) {
        let (db, dt) = (b1.saturating_sub(b0), t1.saturating_sub(t0));
        busy += db;
        span = span.max(dt);
        per_core.push((core, if dt == 0 { 0.0 } else { db as f64 / dt as f64 }));
    }
    let foreign = (busy * NS_PER_TICK).saturating_sub(b.own.saturating_sub(a.own));
    Window {
        foreign: if span == 0 {
            0.0
        } else {
            foreign as f64 / (span * NS_PER_TICK) as f64
        },
        per_core,
    }
}

/// Samples every [`WINDOW`] until `stop`, placing `pids` per `placement`.
pub(super) fn watch(placement: Placement, pids: &[u32], cores: &Cores, stop: &AtomicBool) {
    // The first decision takes one short window: a run should not spend
    // its first half second spread over a busy machine.
    let mut state = State {
        placed: Placed::Spread,
        streak: HYSTERESIS - 1,
    };
    let mut last = sample(pids, &cores.list);
    let mut period = FIRST_WINDOW;
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(period);
        period = WINDOW;
        let now = sample(pids, &cores.list);
        let w = window(&last, &now);
        last = now;
        let next = match placement {
            Placement::Auto => decide(state, &w),
            Placement::Pack if state.placed == Placed::Spread => State {
                placed: least_busy(&w).map_or(Placed::Spread, Placed::Packed),
                streak: 0,
            },
            Placement::Pack | Placement::Spread | Placement::Pin => state,
        };
        if next.placed != state.placed {
            tracing::info!(
                foreign_cores = w.foreign,
                placement = ?next.placed,
                "placement: other programs use {:.1} cores; nodes {}",
                w.foreign,
                match next.placed {
                    Placed::Spread if cores.pinned.is_empty() => "spread over every core".into(),
                    Placed::Spread => "each on its part's core".into(),
                    Placed::Packed(c) => format!("packed onto core {c}"),
                }
            );
            place(pids, next.placed, cores);
        }
        state = next;
    }
}
