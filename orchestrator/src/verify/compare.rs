//! The first difference between a recorded run and its re-run: `states.bin`
//! sample by sample (streamed, a record at a time: [`crate::results::states::open`]), values
//! compared bit for bit (`f64::to_bits`: `-0.0 ≠ 0.0`, a NaN equals the
//! same NaN), and `errors.csv` row by row.
//!
//! Fields are named as in Rust, 0-based: the leader's `R0[i][j]`,
//! `omega0[i]`, `sigma0[i]`; an agent's `R[i][j]`, `omega[i]`,
//! `R_hat[i][j]`, `omega_hat[i]`, `sigma_hat[i]`, `tau[i]` (matrices
//! row-major, as in `states.bin`).
//!
//! A recorded file of an older layout (version 1, without torques) is
//! compared in the values it holds: if they are all equal, there is no
//! difference (its bytes cannot equal a re-run's).

use super::VerifyError;
use crate::results::fmt_time;
use crate::results::layout::node_name;
use crate::results::states::{self, AgentRecord, Header, LeaderRecord, Records};
use std::fmt;
use std::fs::File;
use std::io::{self, BufReader, Read};
use std::path::Path;

/// The first difference of two `states.bin`.
#[derive(Debug, Clone, PartialEq)]
pub enum StatesDifference {
    /// The recorded file cannot be read (truncated, bad magic, …).
    Unreadable(String),
    /// A header field differs (both values, `{:?}`).
    Header {
        /// The field (`scenario`, `dt`, `sample_every`, `agent_ids`, `has_observer`).
        field: &'static str,
        /// In the recorded file.
        recorded: String,
        /// In the re-run's.
        rerun: String,
    },
    /// The `index`-th record has another step number.
    Step {
        /// Record index, 0-based.
        index: usize,
        /// Recorded step.
        recorded: u64,
        /// Re-run step.
        rerun: u64,
    },
    /// The first value that differs.
    Sample {
        /// Sample time, s (as in `errors.csv`).
        t: String,
        /// Step of the sample.
        step: u64,
        /// `leader` or `agent-<id>`.
        node: String,
        /// The field and element (`R_hat[1][2]`, `omega[0]`, …).
        field: String,
        /// The recorded value.
        recorded: f64,
        /// The re-run's value.
        rerun: f64,
    },
    /// Equal samples as far as both go, but not as many.
    Samples {
        /// Samples recorded.
        recorded: usize,
        /// Samples of the re-run.
        rerun: usize,
    },
    /// Equal samples, other bytes (the encoding is fixed, so only a change
    /// of the file outside any value).
    Bytes {
        /// The first differing byte.
        offset: u64,
    },
}

impl fmt::Display for StatesDifference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Unreadable(why) => write!(f, "the recorded file cannot be read: {why}"),
            Self::Header {
                field,
                recorded,
                rerun,
            } => {
                write!(
                    f,
                    "header field {field}: recorded {recorded}, re-run {rerun}"
                )
            }
            Self::Step {
                index,
                recorded,
                rerun,
            } => write!(
                f,
                "sample {index} is of step {recorded} recorded, of step {rerun} in the re-run"
            ),
            Self::Sample {
                t,
                step,
                node,
                field,
                recorded,
                rerun,
            } => write!(
                f,
                "first differing sample: t = {t} s (step {step}), {node}, {field}: \
                 recorded {recorded:?}, re-run {rerun:?}"
            ),
            Self::Samples { recorded, rerun } => write!(
                f,
                "{recorded} samples recorded, {rerun} in the re-run (equal as far as both go)"
            ),
            Self::Bytes { offset } => {
                write!(f, "equal samples but the bytes differ from offset {offset}")
            }
        }
    }
}

/// The first difference between the recorded `states.bin` and the re-run's.
/// Both files are streamed: memory does not grow with the run's length.
///
/// # Errors
/// The re-run's own file cannot be read ([`VerifyError::Read`]).
pub fn states(recorded: &Path, rerun: &Path) -> Result<Option<StatesDifference>, VerifyError> {
    let ours = File::open(rerun).map_err(|e| VerifyError::Read(read_error(rerun, &e)))?;
    let theirs = match File::open(recorded) {
        Ok(f) => f,
        Err(e) => return Ok(Some(StatesDifference::Unreadable(read_error(recorded, &e)))),
    };
    let offset = match first_difference(theirs, ours) {
        Ok(None) => return Ok(None),
        Ok(Some(offset)) => offset,
        Err((Side::Recorded, e)) => {
            return Ok(Some(StatesDifference::Unreadable(read_error(recorded, &e))));
        }
        Err((Side::Rerun, e)) => return Err(VerifyError::Read(read_error(rerun, &e))),
    };
    let mut a = match states::open(recorded) {
        Ok(x) => x,
        Err(why) => return Ok(Some(StatesDifference::Unreadable(why.to_string()))),
    };
    let mut b = states::open(rerun).map_err(|e| VerifyError::Read(e.to_string()))?;
    if let Some(d) = header(&a.header, &b.header) {
        return Ok(Some(d));
    }
    let older = a.header.version < b.header.version;
    Ok(match records(&mut a, &mut b, !older)? {
        Some(d) => Some(d),
        None if older => None,
        None => Some(StatesDifference::Bytes { offset }),
    })
}

/// `FILE: error`.
fn read_error(file: &Path, e: &io::Error) -> String {
    format!("{}: {e}", file.display())
}

/// Which file a read error came from.
#[derive(Debug, Clone, Copy)]
enum Side {
    Recorded,
    Rerun,
}

/// The offset of the first byte where `a` and `b` differ (the shorter one's
/// length if one is a prefix of the other), `None` if they are equal.
fn first_difference(a: impl Read, b: impl Read) -> Result<Option<u64>, (Side, io::Error)> {
    let (mut a, mut b) = (BufReader::new(a), BufReader::new(b));
    let (mut x, mut y) = (vec![0; 1 << 16], vec![0; 1 << 16]);
    let mut at = 0u64;
    loop {
        let n = fill(&mut a, &mut x).map_err(|e| (Side::Recorded, e))?;
        let m = fill(&mut b, &mut y).map_err(|e| (Side::Rerun, e))?;
        if let Some(k) = x[..n.min(m)].iter().zip(&y[..m]).position(|(p, q)| p != q) {
            return Ok(Some(at + k as u64));
        }
        if n != m {
            return Ok(Some(at + n.min(m) as u64));
        }
        if n == 0 {
            return Ok(None);
        }
        at += n as u64;
    }
}

/// Reads into `buf` until it is full or the stream ends; the bytes read.
fn fill(r: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// The first header field that differs.
fn header(a: &Header, b: &Header) -> Option<StatesDifference> {
    let field = |field, recorded: String, rerun: String| {
        (recorded != rerun).then_some(StatesDifference::Header {
            field,
            recorded,
            rerun,
        })
    };
    field(
        "scenario",
        format!("{:?}", a.scenario),
        format!("{:?}", b.scenario),
    )
    .or_else(|| field("dt", format!("{:?}", a.dt), format!("{:?}", b.dt)))
    .or_else(|| {
        let (x, y) = (a.sample_every, b.sample_every);
        field("sample_every", x.to_string(), y.to_string())
    })
    .or_else(|| {
        let (x, y) = (&a.agent_ids, &b.agent_ids);
        field("agent_ids", format!("{x:?}"), format!("{y:?}"))
    })
    .or_else(|| {
        let (x, y) = (a.has_observer, b.has_observer);
        field("has_observer", x.to_string(), y.to_string())
    })
}

/// The first record that differs (the headers are equal), read a record at
/// a time, torques compared if `torques`; a recorded record that cannot be
/// read is itself the difference.
fn records(
    a: &mut Records,
    b: &mut Records,
    torques: bool,
) -> Result<Option<StatesDifference>, VerifyError> {
    let (ra, rb) = (a.remaining(), b.remaining());
    let h = a.header.clone();
    for (index, (x, y)) in a.by_ref().zip(b.by_ref()).enumerate() {
        let x = match x {
            Ok(x) => x,
            Err(why) => return Ok(Some(StatesDifference::Unreadable(why.to_string()))),
        };
        let y = y.map_err(|e| VerifyError::Read(e.to_string()))?;
        if x.step != y.step {
            let (recorded, rerun) = (x.step, y.step);
            return Ok(Some(StatesDifference::Step {
                index,
                recorded,
                rerun,
            }));
        }
        let at = |node: String, (field, recorded, rerun): Diff| StatesDifference::Sample {
            t: fmt_time(x.step, h.dt),
            step: x.step,
            node,
            field,
            recorded,
            rerun,
        };
        if let Some(d) = leader(&x.leader, &y.leader) {
            return Ok(Some(at(node_name(0), d)));
        }
        let agents = h.agent_ids.iter().zip(x.agents.iter().zip(&y.agents));
        for (&id, (p, q)) in agents {
            if let Some(d) = agent(p, q, torques) {
                return Ok(Some(at(node_name(id), d)));
            }
        }
    }
    Ok((ra != rb).then_some(StatesDifference::Samples {
        recorded: ra as usize,
        rerun: rb as usize,
    }))
}

/// A differing value: (field name, recorded, re-run).
type Diff = (String, f64, f64);

/// The first element of `a` and `b` whose bits differ, named `name[k]`
/// (`rows`: a row-major 3×3 matrix, named `name[i][j]`).
fn first(name: &str, rows: bool, a: &[f64], b: &[f64]) -> Option<Diff> {
    let k = a
        .iter()
        .zip(b)
        .position(|(x, y)| x.to_bits() != y.to_bits())?;
    let field = if rows {
        format!("{name}[{}][{}]", k / 3, k % 3)
    } else {
        format!("{name}[{k}]")
    };
    Some((field, a[k], b[k]))
}

/// The leader's first differing value.
fn leader(a: &LeaderRecord, b: &LeaderRecord) -> Option<Diff> {
    first("R0", true, &a.r0, &b.r0)
        .or_else(|| first("omega0", false, &a.w0, &b.w0))
        .or_else(|| first("sigma0", false, &a.s0, &b.s0))
}

/// An agent's first differing value (its torque only if `torques`).
fn agent(a: &AgentRecord, b: &AgentRecord, torques: bool) -> Option<Diff> {
    first("R", true, &a.r, &b.r)
        .or_else(|| first("omega", false, &a.w, &b.w))
        .or_else(|| first("R_hat", true, &a.r_hat, &b.r_hat))
        .or_else(|| first("omega_hat", false, &a.w_hat, &b.w_hat))
        .or_else(|| first("sigma_hat", false, &a.s_hat, &b.s_hat))
        .or_else(|| torques.then(|| first("tau", false, &a.tau, &b.tau))?)
}

/// The first difference of two `errors.csv`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RowDifference {
    /// The recorded file cannot be read.
    Unreadable(String),
    /// The first line that differs (`None`: that file has ended).
    Row {
        /// Line number, 1-based (line 1 is the header).
        line: usize,
        /// The recorded line.
        recorded: Option<String>,
        /// The re-run's line.
        rerun: Option<String>,
    },
}

impl fmt::Display for RowDifference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let show = |l: &Option<String>| {
            l.as_ref()
                .map_or("<end of file>".into(), |l| format!("{l:?}"))
        };
        match self {
            Self::Unreadable(why) => write!(f, "the recorded file cannot be read: {why}"),
            Self::Row {
                line,
                recorded,
                rerun,
            } => write!(
                f,
                "first differing row at line {line}: recorded {}, re-run {}",
                show(recorded),
                show(rerun)
            ),
        }
    }
}

/// The first row of the recorded `errors.csv` that differs from the re-run's.
///
/// # Errors
/// The re-run's own file cannot be read ([`VerifyError::Read`]).
pub fn errors_csv(recorded: &Path, rerun: &Path) -> Result<Option<RowDifference>, VerifyError> {
    let ours =
        std::fs::read(rerun).map_err(|e| VerifyError::Read(format!("{}: {e}", rerun.display())))?;
    let theirs = match std::fs::read(recorded) {
        Ok(b) if b == ours => return Ok(None),
        Ok(b) => b,
        Err(e) => {
            return Ok(Some(RowDifference::Unreadable(format!(
                "{}: {e}",
                recorded.display()
            ))));
        }
    };
    let (a, b) = (
        String::from_utf8_lossy(&theirs),
        String::from_utf8_lossy(&ours),
    );
    let (mut la, mut lb) = (a.split_inclusive('\n'), b.split_inclusive('\n'));
    for line in 1.. {
        match (la.next(), lb.next()) {
            (Some(x), Some(y)) if x == y => {}
            (None, None) => break,
            (x, y) => {
                let trim = |l: Option<&str>| l.map(|l| l.trim_end_matches('\n').to_owned());
                let (recorded, rerun) = (trim(x), trim(y));
                return Ok(Some(RowDifference::Row {
                    line,
                    recorded,
                    rerun,
                }));
            }
        }
    }
    // Equal lines, other bytes: only invalid UTF-8 can do that.
    Ok(Some(RowDifference::Row {
        line: 1,
        recorded: Some("<not UTF-8>".into()),
        rerun: None,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_differing_byte_is_found_across_buffer_boundaries() {
        let a: Vec<u8> = (0..200_000u32).map(|i| (i % 251) as u8).collect();
        let at = |x: &[u8], y: &[u8]| first_difference(x, y).unwrap();
        assert_eq!(at(&a, &a), None);
        for k in [0, 1, 65_535, 65_536, 65_537, 199_999] {
            let mut b = a.clone();
            b[k] ^= 1;
            assert_eq!(at(&a, &b), Some(k as u64), "byte {k}");
        }
        assert_eq!(at(&a, &a[..70_000]), Some(70_000), "a prefix");
        assert_eq!(at(&a[..1], &a), Some(1));
        assert_eq!(at(&[], &[]), None);
    }

    #[test]
    fn fields_are_named_by_row_and_column() {
        let a = [0.0; 9];
        let mut b = a;
        b[5] = 1e-300;
        assert_eq!(
            first("R_hat", true, &a, &b),
            Some(("R_hat[1][2]".into(), 0.0, 1e-300))
        );
        assert_eq!(
            first("omega", false, &a[..3], &[0.0, 0.0, -0.0]),
            Some(("omega[2]".into(), 0.0, -0.0))
        );
        assert_eq!(first("omega", false, &[f64::NAN], &[f64::NAN]), None);
    }

    #[test]
    fn csv_rows_are_compared_line_by_line() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        std::fs::write(&a, "h\n1\n2\n").expect("write");
        std::fs::write(&b, "h\n1\n2\n").expect("write");
        assert_eq!(errors_csv(&a, &b).expect("read"), None);
        std::fs::write(&b, "h\n1\n3\n").expect("write");
        let d = errors_csv(&a, &b).expect("read").expect("differs");
        assert_eq!(
            d.to_string(),
            r#"first differing row at line 3: recorded "2", re-run "3""#
        );
        std::fs::write(&b, "h\n1\n").expect("write");
        let d = errors_csv(&a, &b).expect("read").expect("differs");
        assert_eq!(
            d.to_string(),
            r#"first differing row at line 3: recorded "2", re-run <end of file>"#
        );
    }
}
