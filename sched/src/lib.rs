//! Everything attsync asks of the operating system (Linux), in one place:
//! the system calls and the `/proc` reads of the orchestrator's library, its
//! benchmark and its nodes. Nothing else in them reads `/proc`.
//!
//! Each module holds one concept:
//!
//! - what `/proc` says, parsed once: [`stat`] (`/proc/<pid>/stat`),
//!   [`times`] (`/proc/stat`), [`schedstat`] (a thread's scheduler books),
//!   [`status`] (the `Key: value` files: `/proc/<pid>/status`,
//!   `/proc/meminfo`), each failing with a [`ProcError`];
//! - [`busy`]: the one definition of a busy core, for the placement and the
//!   benchmark alike;
//! - [`process`]: whether a process lives, its group, its children, its
//!   threads and command line; [`reap`]: adopting and killing orphans;
//! - [`rusage`]: the CPU time and peak memory of this process;
//! - [`affinity`]: the cores a thread may run on;
//! - [`timeslice`]: the time slice a thread asks the scheduler for;
//! - [`pdeath`]: a child that dies with its parent;
//! - [`machine`] and [`limits`]: what the machine is and what it allows.
//!
//! The crate is a leaf (`std`, `libc`, `nix`, `thiserror`): the two system
//! calls of [`timeslice`] have no safe wrapper in `libc` or `nix`; they and
//! [`pdeath`] (a hook between `fork` and `exec`, unsafe by nature) are the
//! workspace's only unsafe code.

pub mod affinity;
pub mod busy;
mod error;
pub mod limits;
pub mod machine;
pub mod pdeath;
pub mod process;
pub mod reap;
pub mod rusage;
pub mod schedstat;
pub mod stat;
pub mod status;
pub mod times;
pub mod timeslice;

pub use error::ProcError;

/// A pid or thread id as the kernel's type (one always fits: Linux caps
/// them at 2²²).
pub(crate) fn kernel_id(id: u32) -> libc::pid_t {
    libc::pid_t::try_from(id).unwrap_or(libc::pid_t::MAX)
}
