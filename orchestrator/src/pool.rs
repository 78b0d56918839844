//! The one work pool: jobs `0..n` on a few threads, started in index order,
//! their results by index. Used by `sweep` (one run per value) and `mc`
//! (one trial per index).

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// What a job asks of the pool after it ran.
pub enum Flow<T> {
    /// Its result; the pool goes on.
    Next(T),
    /// Its result, if any; no job starts after it on any worker.
    Stop(Option<T>),
}

/// Runs `job(k)` for `k` in `0..n` on up to `workers` threads (at least
/// one). A job starts only while `stop()` is false and no job has returned
/// [`Flow::Stop`]. Returns each job's result at its index (`None`: not run,
/// or stopped without one).
pub fn run<T: Send>(
    n: usize,
    workers: usize,
    stop: impl Fn() -> bool + Sync,
    job: impl Fn(usize) -> Flow<T> + Sync,
) -> Vec<Option<T>> {
    let next = AtomicUsize::new(0);
    let halted = AtomicBool::new(false);
    let out: Mutex<Vec<Option<T>>> = Mutex::new((0..n).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..workers.clamp(1, n.max(1)) {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= n || stop() || halted.load(Ordering::Relaxed) {
                        return;
                    }
                    let result = match job(k) {
                        Flow::Next(r) => Some(r),
                        Flow::Stop(r) => {
                            halted.store(true, Ordering::Relaxed);
                            r
                        }
                    };
                    out.lock().expect("no job panics holding the lock")[k] = result;
                }
            });
        }
    });
    out.into_inner().expect("no job panics holding the lock")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_job_runs_once_and_results_keep_their_index() {
        let r = run(50, 3, || false, |k| Flow::Next(k * k));
        assert_eq!(r, (0..50).map(|k| Some(k * k)).collect::<Vec<_>>());
        assert!(run(0, 4, || false, Flow::Next).is_empty());
    }

    #[test]
    fn a_stop_ends_the_pool_and_stop_holds_back_every_job() {
        let r = run(
            100,
            1,
            || false,
            |k| match k {
                3 => Flow::Stop(Some(k)),
                _ => Flow::Next(k),
            },
        );
        assert_eq!(r[..4], [Some(0), Some(1), Some(2), Some(3)]);
        assert!(r[4..].iter().all(Option::is_none));
        assert!(run(5, 2, || true, Flow::Next).iter().all(Option::is_none));
    }
}
