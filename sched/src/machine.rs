//! What the machine is: kernel, CPU model, memory, load. What cannot be
//! read is `None`: these describe a run, they never stop one.

use crate::status::{meminfo, number};

/// The text of `path`, trimmed, if it can be read and is not empty.
fn text(path: &str) -> Option<String> {
    let t = std::fs::read_to_string(path).ok()?;
    let t = t.trim();
    (!t.is_empty()).then(|| t.to_owned())
}

/// The kernel release (`/proc/sys/kernel/osrelease`, as `uname -r`).
#[must_use]
pub fn kernel_release() -> Option<String> {
    text("/proc/sys/kernel/osrelease")
}

/// The CPU model (`/proc/cpuinfo`, see [`cpu_model_in`]).
#[must_use]
pub fn cpu_model() -> Option<String> {
    cpu_model_in(&std::fs::read_to_string("/proc/cpuinfo").ok()?)
}

/// The CPU model in the text of `/proc/cpuinfo`: the first `model name`
/// (x86), else `Hardware`, `cpu model` or `uarch` (ARM, MIPS, RISC-V).
#[must_use]
pub fn cpu_model_in(cpuinfo: &str) -> Option<String> {
    ["model name", "Hardware", "cpu model", "uarch"]
        .iter()
        .find_map(|key| {
            cpuinfo.lines().find_map(|line| {
                let (k, v) = line.split_once(':')?;
                (k.trim() == *key && !v.trim().is_empty()).then(|| v.trim().to_owned())
            })
        })
}

/// The machine's memory (`MemTotal`), bytes.
#[must_use]
pub fn mem_total() -> Option<u64> {
    Some(number(&meminfo().ok()?, "MemTotal")? * 1024)
}

/// The memory available to new work without swapping (`MemAvailable`), bytes.
#[must_use]
pub fn mem_available() -> Option<u64> {
    Some(number(&meminfo().ok()?, "MemAvailable")? * 1024)
}

/// The 1-, 5- and 15-minute load averages, as `/proc/loadavg` writes them
/// (`0.52 0.58 0.59`).
#[must_use]
pub fn load_averages() -> Option<String> {
    let t = text("/proc/loadavg")?;
    Some(t.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

/// Tasks (threads) on the machine now (`/proc/loadavg`'s `running/total`).
#[must_use]
pub fn tasks() -> Option<u64> {
    let t = text("/proc/loadavg")?;
    t.split_whitespace().nth(3)?.split('/').nth(1)?.parse().ok()
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
            cpu_model_in(x86).as_deref(),
            Some("Intel(R) Xeon(R) CPU @ 2.00GHz")
        );
        assert_eq!(
            cpu_model_in("processor : 0\nHardware : BCM2835\n").as_deref(),
            Some("BCM2835")
        );
        assert_eq!(cpu_model_in("processor : 0\nmodel : 85\n"), None);
    }

    #[test]
    fn this_machine_is_read() {
        assert!(kernel_release().is_some_and(|k| k.starts_with(|c: char| c.is_ascii_digit())));
        assert!(mem_available().is_some_and(|m| m > 0 && Some(m) <= mem_total()));
        assert_eq!(load_averages().map(|l| l.split(' ').count()), Some(3));
        assert!(tasks().is_some_and(|t| t >= 1));
    }
}
