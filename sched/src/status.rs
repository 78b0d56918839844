//! The `Key: value` files of `/proc`: `/proc/<pid>/status` and
//! `/proc/meminfo`, one reader for both.

use crate::error::{ProcError, dir, read};

/// The value of line `key` in `text` (`key:` then the value, trimmed).
#[must_use]
pub fn field<'a>(text: &'a str, key: &str) -> Option<&'a str> {
    text.lines()
        .find_map(|l| l.strip_prefix(key)?.strip_prefix(':'))
        .map(str::trim)
}

/// The first number of line `key` in `text` (`VmHWM:  2048 kB` → 2048,
/// `Uid:  1000 1000 …` → 1000).
#[must_use]
pub fn number(text: &str, key: &str) -> Option<u64> {
    field(text, key)?.split_whitespace().next()?.parse().ok()
}

/// The text of `/proc/<pid>/status` of process `pid`.
pub fn of(pid: u32) -> Result<String, ProcError> {
    read(dir(pid).join("status"))
}

/// The text of `/proc/meminfo`.
pub fn meminfo() -> Result<String, ProcError> {
    read("/proc/meminfo")
}

#[cfg(test)]
mod tests {
    use super::*;

    const STATUS: &str = "Name:\tmy (evil) prog\nState:\tS (sleeping)\n\
        Uid:\t1000\t1000\t1000\t1000\nVmHWM:\t    2048 kB\nThreads:\t3\n\
        Cpus_allowed_list:\t0-1\n";

    #[test]
    fn fields_and_their_first_numbers_are_read() {
        assert_eq!(field(STATUS, "Name"), Some("my (evil) prog"));
        assert_eq!(field(STATUS, "Cpus_allowed_list"), Some("0-1"));
        assert_eq!(number(STATUS, "VmHWM"), Some(2048));
        assert_eq!(number(STATUS, "Uid"), Some(1000));
        assert_eq!(number(STATUS, "Threads"), Some(3));
        assert_eq!(number(STATUS, "VmRSS"), None);
        assert_eq!(
            number("MemAvailable:   123 kB\n", "MemAvailable"),
            Some(123)
        );
    }

    #[test]
    fn this_processs_status_and_the_meminfo_are_read() {
        let me = of(std::process::id()).expect("own status");
        assert!(number(&me, "Threads").is_some_and(|t| t >= 1));
        assert!(number(&meminfo().expect("meminfo"), "MemTotal").is_some());
    }
}
