//! A node's log: its stdout and stderr, piped through the orchestrator into
//! `logs/<node>.log` and cut at [`LOG_CAP`] (past it one [`CUT_LINE`] is
//! written and the rest drained, so the node never blocks on a full pipe);
//! [`tail`] reads only the end of a log, [`last_bytes`] its end as bytes
//! (what a host daemon sends back of a remote node's log).

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use tokio::io::AsyncReadExt;
use tokio::process::{ChildStderr, ChildStdout};

/// Most bytes of a node's output kept in its log.
pub const LOG_CAP: u64 = 16 << 20;
/// The line that ends a log cut at [`LOG_CAP`].
pub const CUT_LINE: &str = "[attsync: log cut at 16 MiB; further output discarded]";
/// How much of the end of a log [`tail`] and [`last_bytes`] read.
pub const TAIL_BYTES: u64 = 64 << 10;

/// A log file that takes at most `cap` bytes of output.
#[derive(Debug)]
struct CappedLog {
    file: File,
    written: u64,
    cap: u64,
    cut: bool,
    /// The log's path, named when it cannot be written.
    path: PathBuf,
}

impl CappedLog {
    fn write(&mut self, data: &[u8]) {
        if self.cut {
            return;
        }
        let room = usize::try_from(self.cap - self.written).unwrap_or(usize::MAX);
        let keep = &data[..data.len().min(room)];
        // A log that cannot be written (a full disk) is not a reason to stop
        // the node: say so once, naming the file and the node, and drain the rest.
        if let Err(e) = self.file.write_all(keep) {
            tracing::warn!("{}", unwritable(&self.path, &e));
            self.cut = true;
            return;
        }
        self.written += keep.len() as u64;
        if keep.len() < data.len() {
            let _ = writeln!(self.file, "\n{CUT_LINE}");
            self.cut = true;
        }
    }
}

/// What is said when the log at `path` cannot be written: the file, the
/// node (named by the file) and the OS error.
#[must_use]
pub fn unwritable(path: &Path, e: &std::io::Error) -> String {
    let node = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    format!(
        "writing {}: {e}: the log of {node} stops here (its further output is discarded; the node runs on)",
        path.display()
    )
}

/// Copies `out` and `err` into `log` (the file at `path`; at most `cap`
/// bytes, then [`CUT_LINE`]) until both are closed, draining whatever comes
/// after the cap or after a write error.
pub async fn copy_capped(
    mut out: Option<ChildStdout>,
    mut err: Option<ChildStderr>,
    log: File,
    path: PathBuf,
    cap: u64,
) {
    let mut log = CappedLog {
        file: log,
        written: 0,
        cap,
        cut: false,
        path,
    };
    let (mut bo, mut be) = (vec![0u8; 16 << 10], vec![0u8; 16 << 10]);
    while out.is_some() || err.is_some() {
        tokio::select! {
            r = async { out.as_mut().expect("open").read(&mut bo).await }, if out.is_some() => {
                match r {
                    Ok(n) if n > 0 => log.write(&bo[..n]),
                    _ => out = None,
                }
            }
            r = async { err.as_mut().expect("open").read(&mut be).await }, if err.is_some() => {
                match r {
                    Ok(n) if n > 0 => log.write(&be[..n]),
                    _ => err = None,
                }
            }
        }
    }
}

/// The last `n` lines of a log file, read from at most its last 64 KiB and
/// decoded lossily (empty if unreadable).
#[must_use]
pub fn tail(log: &Path, n: usize) -> String {
    let (bytes, _) = last_bytes(log);
    let text = String::from_utf8_lossy(&bytes);
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// The end of a log file: at most its last [`TAIL_BYTES`], from the first
/// line that starts within them (the whole file if it is no longer), and
/// how many bytes before that were left out (nothing if unreadable).
#[must_use]
pub fn last_bytes(log: &Path) -> (Vec<u8>, u64) {
    let Ok(mut file) = File::open(log) else {
        return (Vec::new(), 0);
    };
    let len = file.metadata().map_or(0, |m| m.len());
    let start = len.saturating_sub(TAIL_BYTES);
    let mut bytes = Vec::new();
    if file.seek(SeekFrom::Start(start)).is_err() || file.read_to_end(&mut bytes).is_err() {
        return (Vec::new(), 0);
    }
    if start == 0 {
        return (bytes, 0);
    }
    // Cut in the middle of a line: start at the next one.
    let skip = bytes.iter().position(|&b| b == b'\n').map_or(0, |i| i + 1);
    (bytes.split_off(skip), start + skip as u64)
}

/// The line that heads a log of which only the end is kept (`cut` bytes
/// before it left out, on `host`).
#[must_use]
pub fn cut_note(host: &str, cut: u64) -> String {
    format!(
        "[attsync: the first {cut} bytes of this log were cut on host {host}; only its last {} KiB came back]",
        TAIL_BYTES >> 10
    )
}

/// `<name>.log`, the log of node `name` (`leader`, `agent-3`).
#[must_use]
pub fn node_log_file(name: &str) -> String {
    format!("{name}.log")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_is_cut_once_at_the_cap() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.log");
        let mut log = CappedLog {
            file: File::create(&path).unwrap(),
            written: 0,
            cap: 10,
            cut: false,
            path: path.clone(),
        };
        log.write(b"12345678");
        log.write(b"abcdef");
        log.write(b"more");
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, format!("12345678ab\n{CUT_LINE}\n"));
        assert_eq!(tail(&path, 1), CUT_LINE);
    }

    #[test]
    fn a_log_on_a_full_disk_is_named_with_its_node_and_drained() {
        let mut log = CappedLog {
            file: File::options().write(true).open("/dev/full").unwrap(),
            written: 0,
            cap: 1 << 20,
            cut: false,
            path: "/r/logs/agent-7.log".into(),
        };
        log.write(b"hello\n");
        assert!(log.cut, "a failed write stops the log");
        log.write(b"more");
        let e = std::io::Error::from_raw_os_error(28);
        let text = unwritable(&log.path, &e);
        assert!(
            text.starts_with("writing /r/logs/agent-7.log: No space left"),
            "{text}"
        );
        assert!(text.contains("the log of agent-7 stops here"), "{text}");
    }

    #[test]
    fn tail_reads_the_end_lossily() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.log");
        let mut data = b"head\n".repeat(40_000);
        data.extend_from_slice(b"bad \xff\xfe bytes\nlast\n");
        std::fs::write(&path, data).unwrap();
        assert_eq!(tail(&path, 2), "bad \u{fffd}\u{fffd} bytes\nlast");
        assert!(tail(&path, 100_000).lines().count() < 14_000);
    }

    #[test]
    fn last_bytes_start_at_a_line_and_count_what_was_cut() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.log");
        std::fs::write(&path, b"short\nlog\n").unwrap();
        assert_eq!(last_bytes(&path), (b"short\nlog\n".to_vec(), 0));
        let line = b"0123456789abcde\n"; // 16 bytes
        let data = line.repeat(10_000);
        std::fs::write(&path, &data).unwrap();
        let (end, cut) = last_bytes(&path);
        assert_eq!(end.len() as u64 + cut, data.len() as u64);
        assert!(
            end.len() as u64 <= TAIL_BYTES && end.starts_with(line),
            "{cut}"
        );
        assert_eq!(cut % 16, 0);
        assert!(last_bytes(&dir.path().join("none")).0.is_empty());
    }
}
