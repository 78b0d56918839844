//! The machine a run ran on, as `manifest.json` records it: OS,
//! architecture, CPU model, cores and kernel release. Anything that cannot
//! be read is `unknown`: it describes the run, it never stops it.

use serde::{Deserialize, Serialize};

/// What is written for a value that cannot be read.
pub const UNKNOWN: &str = "unknown";

/// The machine of a run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Platform {
    /// Operating system (`std::env::consts::OS`: `linux`, …).
    pub os: String,
    /// CPU architecture (`std::env::consts::ARCH`: `x86_64`, `aarch64`, …).
    pub arch: String,
    /// The CPU model ([`attsync_sched::machine::cpu_model`]), or `unknown`.
    pub cpu_model: String,
    /// Cores this process may run on (its affinity mask; 0 if unknown).
    pub cores: usize,
    /// Kernel release (`/proc/sys/kernel/osrelease`, as `uname -r`), or `unknown`.
    pub kernel: String,
}

impl Platform {
    /// This machine.
    #[must_use]
    pub fn read() -> Self {
        use attsync_sched::machine;
        Self {
            os: std::env::consts::OS.into(),
            arch: std::env::consts::ARCH.into(),
            cpu_model: machine::cpu_model().unwrap_or_else(|| UNKNOWN.into()),
            cores: std::thread::available_parallelism().map_or(0, std::num::NonZero::get),
            kernel: machine::kernel_release().unwrap_or_else(|| UNKNOWN.into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_platform_is_read() {
        let p = Platform::read();
        assert_eq!(
            (p.os.as_str(), p.arch.as_str()),
            (std::env::consts::OS, std::env::consts::ARCH)
        );
    }
}
