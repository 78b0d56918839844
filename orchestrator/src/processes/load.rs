//! The machine's CPU load as [`super::placement`] needs it: the busy time
//! of each core ([`attsync_sched::busy`], the workspace's one definition)
//! and the CPU time of the run's own processes ([`attsync_sched::schedstat`]:
//! exact, where `/proc`'s per-process times are cut to clock ticks), turned
//! into a [`Window`] per sampling period.

use super::placement::{
    Cores, FIRST_WINDOW, HYSTERESIS, Placed, Placement, State, WINDOW, Window, decide, least_busy,
    place,
};
use attsync_sched::busy::Span;
use attsync_sched::schedstat::on_cpu_ns;
use attsync_sched::times::{CpuTimes, TICK};
use std::sync::atomic::{AtomicBool, Ordering};

/// Nanoseconds per clock tick of the cores' times.
const NS_PER_TICK: u64 = TICK.as_nanos() as u64;

/// One sample: each allowed core's times and the run's own CPU time, ns.
struct Sample {
    cores: Vec<(usize, CpuTimes)>,
    own: u64,
}

fn sample(pids: &[u32], allowed: &[usize]) -> Sample {
    let times = attsync_sched::times::read_now().unwrap_or_default();
    let cores = (times.cores.into_iter())
        .filter(|(c, _)| allowed.contains(c))
        .collect();
    let own = pids.iter().map(|&p| on_cpu_ns(p)).sum::<u64>() + on_cpu_ns(std::process::id());
    Sample { cores, own }
}

/// The window between two samples.
fn window(a: &Sample, b: &Sample) -> Window {
    let mut busy = 0u64;
    let mut span = 0u64;
    let mut per_core = Vec::new();
    for ((core, t0), (_, t1)) in a.cores.iter().zip(&b.cores) {
        let s = Span::between(t0, t1);
        busy += s.busy;
        span = span.max(s.total);
        per_core.push((*core, s.fraction()));
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
