//! Where a measurement's threads spent their time, from the scheduler's own
//! books ([`attsync_sched::schedstat`]: nanoseconds on a CPU, and
//! nanoseconds runnable but waiting for one), without `perf`.
//!
//! The engine's worker threads live only while [`attitude::engine::InProcess::run`]
//! runs, so a [`Watch`] samples every task of the process every
//! [`PERIOD`] from a thread of its own and keeps each task's last figures;
//! a task that ends between two samples loses at most one period.
//! On a machine shared with other work the wait column says how much of
//! the wall time the threads were ready to run and got no core.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering::Relaxed};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

/// How often the watch samples the tasks.
pub const PERIOD: Duration = Duration::from_millis(10);

/// What the tasks of the process did during a measurement.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Books {
    /// Tasks (threads) seen running, the watch's own excluded.
    pub tasks: usize,
    /// Time on a CPU, summed over the tasks, s.
    pub on_cpu: f64,
    /// Time runnable but waiting for a CPU, summed over the tasks, s.
    pub waiting: f64,
}

/// Per task id: (ns on a CPU, ns waiting), at the first and the last sample.
type Seen = HashMap<u32, ((u64, u64), (u64, u64))>;

/// A running watch over the process's tasks (see the module's docs).
#[derive(Debug)]
pub struct Watch {
    stop: Arc<AtomicBool>,
    seen: Arc<Mutex<Seen>>,
    thread: Option<JoinHandle<u32>>,
}

impl Watch {
    /// Starts sampling (one sample at once, then every [`PERIOD`]).
    #[must_use]
    pub fn start() -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let seen = Arc::new(Mutex::new(Seen::new()));
        sample(&seen, true);
        let thread = {
            let (stop, seen) = (Arc::clone(&stop), Arc::clone(&seen));
            std::thread::spawn(move || {
                while !stop.load(Relaxed) {
                    std::thread::sleep(PERIOD);
                    sample(&seen, false);
                }
                own_tid()
            })
        };
        Self {
            stop,
            seen,
            thread: Some(thread),
        }
    }

    /// Takes a last sample and returns the books since [`Watch::start`]
    /// (all zero where `/proc` does not tell).
    #[must_use]
    pub fn stop(mut self) -> Books {
        sample(&self.seen, false);
        self.stop.store(true, Relaxed);
        let me = self.thread.take().and_then(|t| t.join().ok());
        let seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
        let mut books = Books::default();
        for (tid, ((run0, wait0), (run1, wait1))) in seen.iter() {
            if Some(*tid) == me || run1 == run0 {
                continue;
            }
            books.tasks += 1;
            books.on_cpu += (run1 - run0) as f64 * 1e-9;
            books.waiting += (wait1 - wait0) as f64 * 1e-9;
        }
        books
    }
}

/// Reads every task's schedstat into `seen`: the last figures replaced;
/// a task's first figures are what it had at the watch's start, or zero
/// for a task started since (so its whole life is booked).
fn sample(seen: &Mutex<Seen>, at_start: bool) {
    let now = attsync_sched::schedstat::of_threads(std::process::id());
    let mut seen = seen.lock().unwrap_or_else(|e| e.into_inner());
    for (tid, s) in now {
        let figures = (s.on_cpu_ns, s.waiting_ns);
        seen.entry(tid)
            .and_modify(|(_, last)| *last = figures)
            .or_insert((if at_start { figures } else { (0, 0) }, figures));
    }
}

/// The calling thread's task id (0 if unknown).
fn own_tid() -> u32 {
    attsync_sched::process::current_thread().unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_busy_thread_is_booked() {
        let watch = Watch::start();
        let worker = std::thread::spawn(|| {
            let t0 = std::time::Instant::now();
            let mut x = 0u64;
            while t0.elapsed() < Duration::from_millis(60) {
                x = std::hint::black_box(x.wrapping_add(1));
            }
            x
        });
        assert!(worker.join().expect("joins") > 0);
        let books = watch.stop();
        if cfg!(target_os = "linux") {
            assert!(books.tasks >= 1, "{books:?}");
            assert!(books.on_cpu > 0.0 && books.waiting >= 0.0, "{books:?}");
        }
    }
}
