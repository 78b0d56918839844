//! Short time slices for attsync's node processes.
//!
//! In lockstep every exchange hands the turn from node to node, each node
//! running a few microseconds. On a core that a CPU-bound program shares,
//! Linux's fair scheduler (EEVDF, since 6.6) lets that program run for its
//! whole slice (about 1.5–4 ms here) before a node that waits may run again,
//! and a `sched_yield` pushes the yielding node's deadline back by a whole
//! slice of its own, so the competitor is picked again and again. Since Linux
//! 6.12 a task may ask for a shorter slice (`sched_attr.sched_runtime` of a
//! `SCHED_OTHER` task, 0.1–100 ms): its share of the CPU stays the same, but
//! its deadlines come sooner, so it is picked sooner, a yield costs it less,
//! and a wake-up preempts a task with a longer slice at once (docs/waiting.md,
//! BENCHMARKS.md "Under contention").
//!
//! The orchestrator asks this for every thread of every node process
//! ([`set_slice`], beside each thread's CPU affinity), plug-ins included,
//! while it packs the run onto
//! one core because other programs keep the machine busy, and gives them
//! back the kernel's default when it spreads the run again; the policy and
//! nice value of each thread are kept. On an older kernel the request is
//! accepted and has no effect; where it is refused, the run goes on as
//! before.
//!
//! The two system calls here have no safe wrapper in `libc` or `nix`.

use std::time::Duration;
use thiserror::Error;

/// The slice attsync asks for: the shortest Linux grants (100 µs).
pub const SHORT_SLICE: Duration = Duration::from_micros(100);

/// Why a slice could not be read or set.
#[derive(Debug, Error)]
pub enum SliceError {
    /// `sched_getattr` failed (the thread is gone, or not ours).
    #[error("reading the scheduling attributes of thread {tid}: {source}")]
    Get {
        /// The thread.
        tid: u32,
        /// The system's reason.
        source: std::io::Error,
    },
    /// `sched_setattr` failed.
    #[error("setting the time slice of thread {tid}: {source}")]
    Set {
        /// The thread.
        tid: u32,
        /// The system's reason.
        source: std::io::Error,
    },
}

/// Whether this kernel honours a thread's own slice (Linux ≥ 6.12; older
/// kernels accept the request and ignore it).
#[must_use]
pub fn custom_slices() -> bool {
    let release = crate::machine::kernel_release().unwrap_or_default();
    let mut v = release.split(|c: char| !c.is_ascii_digit());
    let mut next = || v.next().and_then(|x| x.parse::<u32>().ok()).unwrap_or(0);
    (next(), next()) >= (6, 12)
}

/// `struct sched_attr` of `<linux/sched/types.h>`, version 1 (56 bytes).
#[repr(C)]
#[derive(Debug, Default, Clone, Copy)]
struct SchedAttr {
    size: u32,
    sched_policy: u32,
    sched_flags: u64,
    sched_nice: i32,
    sched_priority: u32,
    sched_runtime: u64,
    sched_deadline: u64,
    sched_period: u64,
    sched_util_min: u32,
    sched_util_max: u32,
}

/// The fair policies, whose `sched_runtime` is the slice.
const SCHED_OTHER: u32 = 0;
const SCHED_BATCH: u32 = 3;
const SCHED_IDLE: u32 = 5;
/// The one flag kept from the thread's attributes.
const SCHED_FLAG_RESET_ON_FORK: u64 = 0x01;

/// The scheduling attributes of thread `tid` (0: the calling thread).
fn get(tid: u32) -> Result<SchedAttr, SliceError> {
    let mut attr = SchedAttr::default();
    let size = std::mem::size_of::<SchedAttr>() as u32;
    // SAFETY: `attr` is a valid, writable `struct sched_attr` of `size`
    // bytes that outlives the call; the kernel writes at most `size` bytes.
    #[allow(unsafe_code)]
    let r = unsafe {
        libc::syscall(
            libc::SYS_sched_getattr,
            crate::kernel_id(tid),
            &raw mut attr,
            size,
            0 as libc::c_uint,
        )
    };
    if r != 0 {
        return Err(SliceError::Get {
            tid,
            source: std::io::Error::last_os_error(),
        });
    }
    Ok(attr)
}

/// The time slice of thread `tid` (0: the calling thread): the one it asked
/// for, else the kernel's default (Linux ≥ 6.12 reports both; older kernels
/// report none), or `None` under a policy that has no slice.
pub fn slice_of(tid: u32) -> Result<Option<Duration>, SliceError> {
    let attr = get(tid)?;
    let fair = matches!(attr.sched_policy, SCHED_OTHER | SCHED_BATCH | SCHED_IDLE);
    Ok((fair && attr.sched_runtime > 0).then(|| Duration::from_nanos(attr.sched_runtime)))
}

/// Asks for time slices of `slice` for thread `tid` (0: the calling
/// thread), or for the kernel's default if `None`, keeping its policy and
/// nice value. A thread under a real-time policy is left alone. Threads it
/// creates later inherit the slice.
pub fn set_slice(tid: u32, slice: Option<Duration>) -> Result<(), SliceError> {
    let mut attr = get(tid)?;
    if !matches!(attr.sched_policy, SCHED_OTHER | SCHED_BATCH | SCHED_IDLE) {
        return Ok(());
    }
    attr.size = std::mem::size_of::<SchedAttr>() as u32;
    attr.sched_flags &= SCHED_FLAG_RESET_ON_FORK;
    attr.sched_runtime = slice.map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX));
    attr.sched_priority = 0;
    attr.sched_deadline = 0;
    attr.sched_period = 0;
    // SAFETY: `attr` is a valid, initialised `struct sched_attr` whose
    // `size` field is its size; the kernel only reads it.
    #[allow(unsafe_code)]
    let r = unsafe {
        libc::syscall(
            libc::SYS_sched_setattr,
            crate::kernel_id(tid),
            &raw const attr,
            0 as libc::c_uint,
        )
    };
    if r != 0 {
        return Err(SliceError::Set {
            tid,
            source: std::io::Error::last_os_error(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `f` on a fresh thread (so the test's own thread keeps its slice).
    fn on_a_thread<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
        std::thread::spawn(f).join().expect("thread")
    }

    /// Whether this kernel has custom slices; where it should, a thread
    /// must keep the slice it asks for.
    fn kernel_has_custom_slices() -> bool {
        let has = custom_slices();
        if !has {
            eprintln!("this kernel (before Linux 6.12) has no custom slices: nothing to check");
        }
        has
    }

    #[test]
    fn a_thread_gets_the_slice_it_asks_for_keeps_its_nice_value_and_can_go_back() {
        if !kernel_has_custom_slices() {
            return;
        }
        let (nice_before, slice, nice_after, default) = on_a_thread(|| {
            let nice_before = get(0).expect("get").sched_nice;
            let default_before = slice_of(0).expect("slice");
            set_slice(0, Some(Duration::from_micros(300))).expect("set");
            let slice = slice_of(0).expect("slice");
            let nice_after = get(0).expect("get").sched_nice;
            set_slice(0, None).expect("back to the default");
            let default_after = slice_of(0).expect("slice");
            (
                nice_before,
                slice,
                nice_after,
                (default_before, default_after),
            )
        });
        assert_eq!(slice, Some(Duration::from_micros(300)));
        assert_eq!(nice_after, nice_before);
        let (before, after) = default;
        assert_ne!(before, Some(Duration::from_micros(300)));
        assert_eq!(after, before, "back to the kernel's default");
    }

    #[test]
    fn another_processs_thread_gets_the_slice_and_new_threads_inherit_it() {
        if !kernel_has_custom_slices() {
            return;
        }
        let mut child = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .expect("sleep");
        let tid = child.id();
        let set = set_slice(tid, Some(SHORT_SLICE));
        let slice = slice_of(tid);
        let _ = child.kill();
        let _ = child.wait();
        set.expect("set");
        assert_eq!(slice.expect("slice"), Some(SHORT_SLICE));
        // Threads inherit it.
        let inherited = on_a_thread(|| {
            set_slice(0, Some(SHORT_SLICE)).expect("set");
            on_a_thread(|| slice_of(0).expect("slice"))
        });
        assert_eq!(inherited, Some(SHORT_SLICE));
    }

    #[test]
    fn a_thread_that_is_gone_is_named_with_the_systems_reason() {
        let mut child = std::process::Command::new("true").spawn().expect("true");
        let tid = child.id();
        child.wait().expect("wait");
        match set_slice(tid, Some(SHORT_SLICE)) {
            Err(SliceError::Get { tid: t, source }) => {
                assert_eq!((t, source.raw_os_error()), (tid, Some(libc::ESRCH)));
            }
            other => panic!("expected ESRCH from sched_getattr, got {other:?}"),
        }
    }
}
