//! The cores a thread may run on (its CPU affinity), as lists of core
//! numbers.

use nix::sched::{CpuSet, sched_getaffinity, sched_setaffinity};
use nix::unistd::Pid;
use thiserror::Error;

/// Why an affinity could not be read or set.
#[derive(Debug, Error)]
pub enum AffinityError {
    /// `sched_getaffinity` or `sched_setaffinity` failed (the thread is
    /// gone, or not ours).
    #[error("the CPU affinity of thread {tid}: {source}")]
    Call {
        /// The thread (0: the calling one).
        tid: u32,
        /// The system's reason.
        source: nix::Error,
    },
    /// A core number past what the kernel's CPU set holds.
    #[error("core {core} is not a core of this machine")]
    NoSuchCore {
        /// The core.
        core: usize,
    },
}

/// Thread `tid` as `nix` names it.
fn pid(tid: u32) -> Pid {
    Pid::from_raw(crate::kernel_id(tid))
}

/// The cores thread `tid` may run on (0: the calling thread), ascending.
pub fn of(tid: u32) -> Result<Vec<usize>, AffinityError> {
    let set = sched_getaffinity(pid(tid)).map_err(|source| AffinityError::Call { tid, source })?;
    Ok((0..CpuSet::count())
        .filter(|&c| set.is_set(c).unwrap_or(false))
        .collect())
}

/// The cores this thread may run on (where it cannot be read: none).
#[must_use]
pub fn own() -> Vec<usize> {
    of(0).unwrap_or_default()
}

/// Lets thread `tid` (0: the calling thread) run on `cores` only; threads
/// it starts later inherit them.
pub fn set(tid: u32, cores: &[usize]) -> Result<(), AffinityError> {
    let mut set = CpuSet::new();
    for &core in cores {
        set.set(core)
            .map_err(|_| AffinityError::NoSuchCore { core })?;
    }
    sched_setaffinity(pid(tid), &set).map_err(|source| AffinityError::Call { tid, source })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thread_moved_to_one_core_runs_there_and_can_go_back() {
        let all = own();
        assert!(!all.is_empty());
        let (one, back) = std::thread::spawn(move || {
            set(0, &all[..1]).expect("one core");
            let one = own();
            set(0, &all).expect("every core");
            (one, own())
        })
        .join()
        .expect("thread");
        assert_eq!(one, own()[..1]);
        assert_eq!(back, own());
        assert!(matches!(
            set(0, &[usize::MAX]),
            Err(AffinityError::NoSuchCore { .. })
        ));
    }
}
