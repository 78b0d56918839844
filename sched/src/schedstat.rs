//! A thread's books in the scheduler (`/proc/<pid>/task/<tid>/schedstat`:
//! nanoseconds on a CPU, nanoseconds runnable but waiting for one, time
//! slices run): exact, where `/proc/<pid>/stat`'s CPU times are cut to
//! clock ticks (10 ms, an error of up to a tick per process per reading).

use crate::error::{ProcError, dir, read};

/// One thread's figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SchedStat {
    /// Time on a CPU, ns.
    pub on_cpu_ns: u64,
    /// Time runnable but waiting for a CPU, ns.
    pub waiting_ns: u64,
}

/// Parses the text of a `schedstat` file; `Err` names the missing field.
pub fn parse(text: &str) -> Result<SchedStat, &'static str> {
    let mut f = text.split_whitespace().map(|x| x.parse::<u64>().ok());
    Ok(SchedStat {
        on_cpu_ns: f.next().flatten().ok_or("time on a CPU")?,
        waiting_ns: f.next().flatten().ok_or("time waiting")?,
    })
}

/// The figures of thread `tid` of process `pid`.
pub fn of_thread(pid: u32, tid: u32) -> Result<SchedStat, ProcError> {
    let path = dir(pid).join(format!("task/{tid}/schedstat"));
    let text = read(&path)?;
    parse(&text).map_err(|field| ProcError::Malformed { path, field })
}

/// The figures of every thread of process `pid` now, by thread id (the
/// threads that end while they are read left out).
#[must_use]
pub fn of_threads(pid: u32) -> Vec<(u32, SchedStat)> {
    crate::process::threads(pid)
        .into_iter()
        .filter_map(|tid| Some((tid, of_thread(pid, tid).ok()?)))
        .collect()
}

/// Time every live thread of process `pid` has spent on a CPU, ns (0 if
/// the process is gone).
#[must_use]
pub fn on_cpu_ns(pid: u32) -> u64 {
    of_threads(pid).iter().map(|(_, s)| s.on_cpu_ns).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_times_are_read_and_a_short_file_is_named() {
        let s = parse("123456789 4200 17\n").expect("parses");
        assert_eq!((s.on_cpu_ns, s.waiting_ns), (123_456_789, 4200));
        assert_eq!(parse("12"), Err("time waiting"));
        assert_eq!(parse(""), Err("time on a CPU"));
    }

    #[test]
    fn this_process_has_spent_time_on_a_cpu() {
        assert!(on_cpu_ns(std::process::id()) > 0);
        let me = crate::process::current_thread().expect("own thread id");
        assert!(of_thread(std::process::id(), me).is_ok());
    }
}
