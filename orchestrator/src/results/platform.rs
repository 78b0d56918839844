//! The machine a run ran on, as `manifest.json` records it: OS,
//! architecture, CPU model, cores and kernel release. Anything that cannot
//! be read is `unknown`: it describes the run, it never stops it.

use serde::{Deserialize, Serialize};
use std::path::Path;

/// What is written for a value that cannot be read.
pub const UNKNOWN: &str = "unknown";

/// The machine of a run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Platform {
    /// Operating system (`std::env::consts::OS`: `linux`, …).
    pub os: String,
    /// CPU architecture (`std::env::consts::ARCH`: `x86_64`, `aarch64`, …).
    pub arch: String,
    /// The CPU model from `/proc/cpuinfo`, or `unknown`.
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
        let text = |p: &str| std::fs::read_to_string(Path::new(p)).ok();
        Self {
            os: std::env::consts::OS.into(),
            arch: std::env::consts::ARCH.into(),
            cpu_model: text("/proc/cpuinfo")
                .and_then(|t| cpu_model(&t))
                .unwrap_or_else(|| UNKNOWN.into()),
            cores: std::thread::available_parallelism().map_or(0, std::num::NonZero::get),
            kernel: text("/proc/sys/kernel/osrelease")
                .map(|k| k.trim().to_owned())
                .filter(|k| !k.is_empty())
                .unwrap_or_else(|| UNKNOWN.into()),
        }
    }
}

/// The CPU model in the text of `/proc/cpuinfo`: the first `model name`
/// (x86), else `Hardware`, `cpu model` or `uarch` (ARM, MIPS, RISC-V).
fn cpu_model(cpuinfo: &str) -> Option<String> {
    ["model name", "Hardware", "cpu model", "uarch"]
        .iter()
        .find_map(|key| {
            cpuinfo.lines().find_map(|line| {
                let (k, v) = line.split_once(':')?;
                (k.trim() == *key && !v.trim().is_empty()).then(|| v.trim().to_owned())
            })
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cpu_model_is_the_first_model_name() {
        let x86 = "processor\t: 0\nvendor_id\t: GenuineIntel\nmodel\t\t: 85\n\
                   model name\t: Intel(R) Xeon(R) CPU @ 2.00GHz\nprocessor\t: 1\n\
                   model name\t: Intel(R) Xeon(R) CPU @ 2.00GHz\n";
        assert_eq!(
            cpu_model(x86).as_deref(),
            Some("Intel(R) Xeon(R) CPU @ 2.00GHz")
        );
        assert_eq!(
            cpu_model("processor : 0\nHardware : BCM2835\n").as_deref(),
            Some("BCM2835")
        );
        assert_eq!(cpu_model("processor : 0\nmodel : 85\n"), None);
        let p = Platform::read();
        assert_eq!(
            (p.os.as_str(), p.arch.as_str()),
            (std::env::consts::OS, std::env::consts::ARCH)
        );
    }
}
