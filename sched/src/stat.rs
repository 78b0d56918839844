//! The one parser of `/proc/<pid>/stat`: `pid (comm) state ppid pgrp …`.
//!
//! The command name (`comm`) is whatever the process calls itself, spaces
//! and parentheses included, so the fields are counted from the *last* `)`.

use crate::error::{ProcError, dir, read};

/// The fields of `/proc/<pid>/stat` that attsync uses (times in clock
/// ticks, [`crate::times::USER_HZ`] per second).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stat {
    /// The command name, without its parentheses.
    pub comm: String,
    /// The state letter: `R` running, `S` sleeping, `Z` zombie, `X` dead, ….
    pub state: char,
    /// The parent's pid (0 for the first process).
    pub ppid: u32,
    /// The process group.
    pub pgrp: u32,
    /// CPU time in user mode, every thread, finished ones included.
    pub utime: u64,
    /// CPU time in the kernel, every thread, finished ones included.
    pub stime: u64,
    /// User time of the children this process has waited for.
    pub cutime: u64,
    /// Kernel time of the children this process has waited for.
    pub cstime: u64,
}

impl Stat {
    /// Whether the process is gone all the same: a zombie (dead, not yet
    /// reaped by its parent) or dead.
    #[must_use]
    pub fn is_dead(&self) -> bool {
        matches!(self.state, 'Z' | 'X')
    }
}

/// Parses the text of a `/proc/<pid>/stat`; `Err` names the first field
/// that is missing or not a number.
pub fn parse(text: &str) -> Result<Stat, &'static str> {
    let open = text.find('(').ok_or("comm")?;
    let close = text.rfind(')').ok_or("comm")?;
    let comm = text.get(open + 1..close).ok_or("comm")?.to_owned();
    // Fields 3, 4, … of proc(5): state, ppid, pgrp, …
    let fields: Vec<&str> = text[close + 1..].split_whitespace().collect();
    let number = |k: usize, name: &'static str| {
        fields
            .get(k)
            .and_then(|f| f.parse::<u64>().ok())
            .ok_or(name)
    };
    let state = fields
        .first()
        .and_then(|s| s.chars().next())
        .ok_or("state")?;
    let id = |k, name| number(k, name).and_then(|v| u32::try_from(v).map_err(|_| name));
    Ok(Stat {
        comm,
        state,
        ppid: id(1, "ppid")?,
        pgrp: id(2, "pgrp")?,
        utime: number(11, "utime")?,
        stime: number(12, "stime")?,
        cutime: number(13, "cutime")?,
        cstime: number(14, "cstime")?,
    })
}

/// `/proc/<pid>/stat` of process `pid`.
pub fn read_pid(pid: u32) -> Result<Stat, ProcError> {
    let path = dir(pid).join("stat");
    let text = read(&path)?;
    parse(&text).map_err(|field| ProcError::Malformed { path, field })
}

/// `/proc/<pid>/stat` of this process.
pub fn own() -> Result<Stat, ProcError> {
    read_pid(std::process::id())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A real line (a `sleep` under a shell), its command name made hostile.
    const HOSTILE: &str = "4242 (my (evil) ) prog) S 4000 4242 4000 34816 4242 4194304 \
        120 0 0 0 7 3 11 5 20 0 1 0 123456 8597504 200 18446744073709551615 1 1 0 0 \
        0 0 0 0 0 0 0 0 17 1 0 0 0 0 0\n";

    #[test]
    fn a_command_name_with_spaces_and_parentheses_is_read_whole() {
        let s = parse(HOSTILE).expect("parses");
        assert_eq!(s.comm, "my (evil) ) prog");
        assert_eq!((s.state, s.ppid, s.pgrp), ('S', 4000, 4242));
        assert_eq!((s.utime, s.stime, s.cutime, s.cstime), (7, 3, 11, 5));
        assert!(!s.is_dead());
    }

    #[test]
    fn a_zombie_is_dead_and_a_short_line_names_its_missing_field() {
        let zombie = "77 (sh) Z 1 77 77 0 -1 4228108 0 0 0 0 0 0 0 0 20 0 1 0 9 0 0";
        assert!(parse(zombie).expect("parses").is_dead());
        assert_eq!(parse("77 (sh) R 1 77 77 0 -1 4228108"), Err("utime"));
        assert_eq!(parse("77 (sh) R x"), Err("ppid"));
        assert_eq!(parse("no parentheses"), Err("comm"));
    }

    #[test]
    fn stat_is_parsed_past_the_command_name() {
        let me = own().expect("own stat");
        let pgrp = nix::unistd::getpgrp().as_raw();
        assert_eq!(me.ppid, std::os::unix::process::parent_id());
        assert_eq!(i32::try_from(me.pgrp), Ok(pgrp));
        assert!(!me.is_dead());
    }
}
