//! `states.bin`: the full state trajectory of a run, leader and every agent
//! at every output sample, as a bincode stream.
//!
//! # Layout (version 2)
//! bincode 2, fixed-width little-endian integers
//! (`config::standard().with_fixed_int_encoding()`): `u32`/`u64` are 4/8
//! bytes LE, `f64` 8 bytes LE, `bool` 1 byte, a `Vec`/`String` is a `u64`
//! length then its elements, fixed-size arrays have no length.
//! ```text
//! Header  { magic: [u8; 8] = "ATTSYNCS", version: u32 = 2, scenario: String,
//!           dt: f64, sample_every: u64, agent_ids: Vec<u32>, has_observer: bool }
//! Record* { step: u64, leader: Leader, agents: [Agent; agent_ids.len()] (as a Vec) }
//! Leader  { r0: [f64; 9], w0: [f64; 3], s0: [f64; 3] }
//! Agent   { r: [f64; 9], w: [f64; 3], r_hat: [f64; 9], w_hat: [f64; 3], s_hat: [f64; 3],
//!           tau: [f64; 3] }
//! ```
//! Matrices are row-major, attitudes map body to inertial, rates are in the
//! body frame (rad/s, rad/s²); t = step · dt. `tau` is the torque τᵢ the
//! body received at stage 0 of the record's step (t = step · dt, from the
//! record's state; after the actuator's limits), N·m, body frame. No torque
//! is applied after the last step, so the run's last record (step = the
//! run's steps) has `tau` = NaN; so has an agent that did not report it (a
//! plug-in that does not send telemetry kind 7, PROTOCOL.md § 5). Records
//! follow until the end of the file. Both engines write identical files.
//!
//! Version 1 is version 2 without `tau` (27 `f64` per agent, not 30): it is
//! still read, its records with `tau` = NaN, so that older results stay
//! readable (`verify`, `export`, `view`, `mc --trial`).

use attitude::engine::{NO_TORQUE, Snapshot};
use attitude::network::{AgentState, Network};
use attitude::reference::LeaderState;
use msgs::{from_rows, to_rows};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::{self, BufReader, BufWriter, Read, Write};
use std::path::Path;

/// File magic.
pub const MAGIC: [u8; 8] = *b"ATTSYNCS";
/// Layout version (the one written; [`OLDEST_VERSION`] up to it are read).
pub const VERSION: u32 = 2;

/// The oldest layout version read: version 1 has no torques.
pub const OLDEST_VERSION: u32 = 1;

/// `f64` words of the leader in a record.
const LEADER_WORDS: u64 = 9 + 3 + 3;

/// `f64` words of an agent in a record of layout `version` (version 1 has
/// no `tau`).
fn agent_words(version: u32) -> u64 {
    let state = 9 + 3 + 9 + 3 + 3;
    if version == 1 { state } else { state + 3 }
}

fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_fixed_int_encoding()
}

/// The most bytes a header may take: 64 MiB (a name and 16 million agent
/// ids). A length field claiming more is refused before anything is
/// allocated for it (bincode sizes a string's buffer from its length).
pub const MAX_HEADER_BYTES: usize = 64 << 20;

/// [`config`], refusing a header over [`MAX_HEADER_BYTES`].
fn header_config() -> impl bincode::config::Config {
    (bincode::config::standard().with_fixed_int_encoding()).with_limit::<MAX_HEADER_BYTES>()
}

/// The first value of the stream.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// [`MAGIC`].
    pub magic: [u8; 8],
    /// [`VERSION`].
    pub version: u32,
    /// Scenario name.
    pub scenario: String,
    /// Integrator step, s.
    pub dt: f64,
    /// Steps between records.
    pub sample_every: u64,
    /// Agent ids, in record order.
    pub agent_ids: Vec<u32>,
    /// Whether the observer fields are meaningful.
    pub has_observer: bool,
}

/// The leader in a record.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LeaderRecord {
    /// `R₀`, row-major.
    pub r0: [f64; 9],
    /// `ω₀`.
    pub w0: [f64; 3],
    /// `σ₀`.
    pub s0: [f64; 3],
}

/// An agent in a record.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AgentRecord {
    /// `Rᵢ`, row-major.
    pub r: [f64; 9],
    /// `ωᵢ`.
    pub w: [f64; 3],
    /// `R̂ᵢ`, row-major.
    pub r_hat: [f64; 9],
    /// `ω̂ᵢ`.
    pub w_hat: [f64; 3],
    /// `σ̂ᵢ`.
    pub s_hat: [f64; 3],
    /// `τᵢ` at stage 0 of the record's step, N·m, body frame; NaN at the
    /// run's last step (none is applied after it) or where not reported.
    pub tau: [f64; 3],
}

/// An agent in a record of layout version 1 (no torque).
#[derive(Debug, Clone, Copy, Deserialize)]
struct AgentRecordV1 {
    r: [f64; 9],
    w: [f64; 3],
    r_hat: [f64; 9],
    w_hat: [f64; 3],
    s_hat: [f64; 3],
}

/// A record of layout version 1.
#[derive(Debug, Clone, Deserialize)]
struct RecordV1 {
    step: u64,
    leader: LeaderRecord,
    agents: Vec<AgentRecordV1>,
}

impl From<RecordV1> for Record {
    /// The record with its torques NaN (version 1 has none).
    fn from(v: RecordV1) -> Self {
        let agent = |a: AgentRecordV1| AgentRecord {
            r: a.r,
            w: a.w,
            r_hat: a.r_hat,
            w_hat: a.w_hat,
            s_hat: a.s_hat,
            tau: NO_TORQUE.into(),
        };
        Self {
            step: v.step,
            leader: v.leader,
            agents: v.agents.into_iter().map(agent).collect(),
        }
    }
}

/// One sample of the whole network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Step index.
    pub step: u64,
    /// The leader.
    pub leader: LeaderRecord,
    /// The agents, in header order.
    pub agents: Vec<AgentRecord>,
}

// NOTE: the row-major conversion is msgs' (`msgs::to_rows`, the one every
// payload uses), so a matrix is laid out the same way on the wire and here.
impl LeaderRecord {
    fn of(l: &LeaderState) -> Self {
        Self {
            r0: to_rows(&l.r0),
            w0: l.w0.into(),
            s0: l.s0.into(),
        }
    }
}

impl AgentRecord {
    /// The record of state `x` and torque `tau` (`None`: NaN).
    fn of(x: &AgentState, tau: Option<&Vector3<f64>>) -> Self {
        Self {
            r: to_rows(&x.r),
            w: x.w.into(),
            r_hat: to_rows(&x.r_hat),
            w_hat: x.w_hat.into(),
            s_hat: x.s_hat.into(),
            tau: (*tau.unwrap_or(&NO_TORQUE)).into(),
        }
    }

    /// The torque `τᵢ`.
    #[must_use]
    pub fn torque(&self) -> Vector3<f64> {
        self.tau.into()
    }
}

impl Record {
    /// Every agent's torque, in header order (for a [`Snapshot`]).
    #[must_use]
    pub fn torques(&self) -> Vec<Vector3<f64>> {
        self.agents.iter().map(AgentRecord::torque).collect()
    }
}

/// Writes `states.bin` record by record, the last one held back until the
/// next comes or the file is finished, so that a run extended past its
/// horizon can complete that record's torques ([`StatesWriter::amend_torques`]).
#[derive(Debug)]
pub struct StatesWriter {
    w: BufWriter<File>,
    /// The last record, not written yet.
    held: Option<Record>,
}

/// An encoding error as the I/O error it is (a full disk says
/// "No space left on device", not bincode's debug struct).
fn enc(e: bincode::error::EncodeError) -> io::Error {
    match e {
        bincode::error::EncodeError::Io { inner, .. } => inner,
        e => io::Error::other(e.to_string()),
    }
}

impl StatesWriter {
    /// Creates `file` and writes the header.
    pub fn create(file: &Path, scenario: &str, net: &Network) -> io::Result<Self> {
        let mut w = BufWriter::new(File::create(file)?);
        let header = Header {
            magic: MAGIC,
            version: VERSION,
            scenario: scenario.to_string(),
            dt: net.dt,
            sample_every: net.sample_every,
            agent_ids: net.agents.iter().map(|a| a.model.id).collect(),
            has_observer: net
                .agents
                .first()
                .is_some_and(|a| a.model.scheme.has_observer()),
        };
        bincode::serde::encode_into_std_write(&header, &mut w, config()).map_err(enc)?;
        Ok(Self { w, held: None })
    }

    /// Appends one snapshot (written once the next one comes, or at
    /// [`StatesWriter::finish`]).
    pub fn write(&mut self, snap: &Snapshot<'_>) -> io::Result<()> {
        let agents = snap.agents.iter().enumerate();
        let rec = Record {
            step: snap.step,
            leader: LeaderRecord::of(snap.leader),
            agents: agents
                .map(|(k, x)| AgentRecord::of(x, snap.torques.get(k)))
                .collect(),
        };
        self.flush_held()?;
        self.held = Some(rec);
        Ok(())
    }

    /// Sets the torques of the last record, if it is of step `step`; whether
    /// it was. What a run extended past its horizon does: its former last
    /// record had none (`attitude::engine::InProcess::begin_step`).
    pub fn amend_torques(&mut self, step: u64, torques: &[Vector3<f64>]) -> bool {
        let Some(rec) = self.held.as_mut().filter(|r| r.step == step) else {
            return false;
        };
        for (k, a) in rec.agents.iter_mut().enumerate() {
            a.tau = (*torques.get(k).unwrap_or(&NO_TORQUE)).into();
        }
        true
    }

    /// Writes the record held back, if any.
    fn flush_held(&mut self) -> io::Result<()> {
        if let Some(rec) = self.held.take() {
            bincode::serde::encode_into_std_write(&rec, &mut self.w, config()).map_err(enc)?;
        }
        Ok(())
    }

    /// Writes the last record and flushes the file.
    pub fn finish(mut self) -> io::Result<()> {
        self.flush_held()?;
        self.w.flush()
    }
}

/// An open `states.bin`: its header, then its records one at a time
/// (the file's length is checked against whole records first).
#[derive(Debug)]
pub struct Records {
    /// The header.
    pub header: Header,
    file: std::path::PathBuf,
    r: BufReader<File>,
    left: u64,
    /// One record's bytes, read whole before it is decoded.
    buf: Vec<u8>,
}

/// Opens `file`, reads and checks its header and that its records are whole.
///
/// # Errors
/// [`StatesError`] naming `file`.
pub fn open(file: &Path) -> Result<Records, StatesError> {
    let what = |problem: StatesProblem| StatesError {
        file: file.to_owned(),
        problem,
    };
    let len = std::fs::metadata(file).map_err(|e| what(e.into()))?.len();
    let mut r = BufReader::new(File::open(file).map_err(|e| what(e.into()))?);
    let header: Header = bincode::serde::decode_from_std_read(&mut r, header_config())
        .map_err(|e| what(e.into()))?;
    if header.magic != MAGIC {
        return Err(what(StatesProblem::BadMagic));
    }
    if !(OLDEST_VERSION..=VERSION).contains(&header.version) {
        return Err(what(StatesProblem::Version(header.version)));
    }
    let header_len = bincode::serde::encode_to_vec(&header, config())
        .map_err(|e| what(e.into()))?
        .len() as u64;
    let agents = header.agent_ids.len() as u64;
    let record_len = 8 + 8 + (LEADER_WORDS + agents * agent_words(header.version)) * 8;
    let body = len.saturating_sub(header_len);
    if body % record_len != 0 {
        return Err(what(StatesProblem::Truncated { body, record_len }));
    }
    Ok(Records {
        header,
        file: file.to_owned(),
        r,
        left: body / record_len,
        buf: vec![0; record_len as usize],
    })
}

impl Records {
    /// The next record: its bytes read whole (the size every record has),
    /// then decoded; lengths inside that disagree with the header are refused.
    fn record(&mut self) -> Result<Record, StatesProblem> {
        self.r.read_exact(&mut self.buf)?;
        let (rec, used) = self.decode()?;
        let agents = self.header.agent_ids.len();
        if used != self.buf.len() || rec.agents.len() != agents {
            return Err(StatesProblem::Agents {
                step: rec.step,
                agents: rec.agents.len(),
                header: agents,
            });
        }
        Ok(rec)
    }

    /// The record in `buf`, decoded by its layout version, and the bytes used.
    fn decode(&self) -> Result<(Record, usize), bincode::error::DecodeError> {
        let buf = &self.buf;
        if self.header.version == 1 {
            let (v1, used): (RecordV1, usize) = bincode::serde::decode_from_slice(buf, config())?;
            return Ok((v1.into(), used));
        }
        bincode::serde::decode_from_slice(buf, config())
    }

    /// How many records are left to read.
    #[must_use]
    pub fn remaining(&self) -> u64 {
        self.left
    }
}

impl Iterator for Records {
    type Item = Result<Record, StatesError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.left == 0 {
            return None;
        }
        self.left -= 1;
        Some(self.record().map_err(|problem| StatesError {
            file: self.file.clone(),
            problem,
        }))
    }
}

/// Reads a whole `states.bin`.
///
/// # Errors
/// [`StatesError`] naming `file`.
pub fn read(file: &Path) -> Result<(Header, Vec<Record>), StatesError> {
    let mut records = open(file)?;
    let mut all = Vec::with_capacity(records.remaining() as usize);
    for rec in &mut records {
        all.push(rec?);
    }
    Ok((records.header, all))
}

impl LeaderRecord {
    /// The leader's state, as the model holds it (matrices from rows).
    #[must_use]
    pub fn state(&self) -> LeaderState {
        LeaderState {
            r0: from_rows(&self.r0),
            w0: self.w0.into(),
            s0: self.s0.into(),
        }
    }
}

impl AgentRecord {
    /// The agent's state, as the model holds it (matrices from rows).
    #[must_use]
    pub fn state(&self) -> AgentState {
        AgentState {
            r: from_rows(&self.r),
            w: self.w.into(),
            r_hat: from_rows(&self.r_hat),
            w_hat: self.w_hat.into(),
            s_hat: self.s_hat.into(),
        }
    }
}

/// The columns of [`export_csv`]: `t,node,r11..r33,w1..w3,r_hat11..r_hat33,
/// w_hat1..w_hat3,s_hat1..s_hat3,tau1..tau3`.
#[must_use]
pub fn csv_columns() -> Vec<String> {
    let matrix = |name: &str| -> Vec<String> {
        let cells = (1..=3).flat_map(|i| (1..=3).map(move |j| (i, j)));
        cells.map(|(i, j)| format!("{name}{i}{j}")).collect()
    };
    let vector = |name: &str| -> Vec<String> { (1..=3).map(|i| format!("{name}{i}")).collect() };
    let mut cols = vec!["t".to_string(), "node".into()];
    cols.extend(matrix("r"));
    cols.extend(vector("w"));
    cols.extend(matrix("r_hat"));
    cols.extend(vector("w_hat"));
    cols.extend(vector("s_hat"));
    cols.extend(vector("tau"));
    cols
}

/// Converts `states.bin` to CSV, long form: one row per node per record,
/// node 0 the leader (`r` = R₀, `w` = ω₀, `s_hat` = σ₀, observer and torque
/// columns empty); an agent's `tau1..tau3` are its torque at stage 0 of the
/// record's step (`NaN` at the last step, and in files of layout version 1).
///
/// # Errors
/// [`CsvError`]: the file cannot be read, or the CSV written.
pub fn export_csv(file: &Path, out: &mut dyn Write) -> Result<(), CsvError> {
    let (h, records) = read(file)?;
    let io = CsvError::Write;
    writeln!(out, "{}", csv_columns().join(",")).map_err(io)?;
    let join = |v: &[f64]| v.iter().map(|&x| shortest(x)).collect::<Vec<_>>().join(",");
    for rec in &records {
        let t = super::fmt_time(rec.step, h.dt);
        writeln!(
            out,
            "{t},0,{},{},{},{},{},{}",
            join(&rec.leader.r0),
            join(&rec.leader.w0),
            [""; 9].join(","),
            [""; 3].join(","),
            join(&rec.leader.s0),
            [""; 3].join(",")
        )
        .map_err(io)?;
        for (id, a) in h.agent_ids.iter().zip(&rec.agents) {
            writeln!(
                out,
                "{t},{id},{},{},{},{},{},{}",
                join(&a.r),
                join(&a.w),
                join(&a.r_hat),
                join(&a.w_hat),
                join(&a.s_hat),
                join(&a.tau)
            )
            .map_err(io)?;
        }
    }
    Ok(())
}

/// `x` in the shorter of its two shortest round-trip forms, plain
/// (`0.25`, `-3`) or exponent (`1.5e-79`, `2.5e21`): either reads back as
/// exactly `x`; plain wins a tie.
#[must_use]
pub fn shortest(x: f64) -> String {
    let plain = x.to_string();
    let exp = format!("{x:e}");
    if exp.len() < plain.len() { exp } else { plain }
}

/// Why a `states.bin` cannot be read.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", file.display())]
pub struct StatesError {
    /// The file.
    pub file: std::path::PathBuf,
    /// What is wrong.
    pub problem: StatesProblem,
}

/// What is wrong with a `states.bin` ([`StatesError`]).
#[derive(Debug, thiserror::Error)]
pub enum StatesProblem {
    /// It cannot be read.
    #[error(transparent)]
    Io(#[from] io::Error),
    /// Its header or a record does not decode.
    #[error(transparent)]
    Decode(#[from] bincode::error::DecodeError),
    /// Its header does not encode back (to measure it).
    #[error(transparent)]
    Encode(#[from] bincode::error::EncodeError),
    /// It does not begin with [`MAGIC`].
    #[error("not an attsync states file (bad magic)")]
    BadMagic,
    /// Its layout version is not one this attsync reads.
    #[error("states layout version {0} (this attsync reads {OLDEST_VERSION} to {VERSION})")]
    Version(u32),
    /// Its records are not whole.
    #[error("truncated: {body} bytes of records is not a multiple of the record size {record_len}")]
    Truncated {
        /// Bytes after the header.
        body: u64,
        /// The size of one record.
        record_len: u64,
    },
    /// A record holds another number of agents than the header.
    #[error("record of step {step} holds {agents} agents, the header {header}")]
    Agents {
        /// The record's step.
        step: u64,
        /// Its agents.
        agents: usize,
        /// The header's.
        header: usize,
    },
}

/// Why `states.bin` could not be exported to CSV ([`export_csv`]).
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// The states file cannot be read.
    #[error(transparent)]
    States(#[from] StatesError),
    /// The CSV could not be written.
    #[error("writing CSV: {0}")]
    Write(io::Error),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_short_and_read_back_exactly() {
        for (x, text) in [
            (1.5e-79, "1.5e-79"),
            (0.25, "0.25"),
            (-3.0, "-3"),
            (2.5e21, "2.5e21"),
            (0.1 + 0.2, "0.30000000000000004"),
            (f64::NAN, "NaN"),
        ] {
            assert_eq!(shortest(x), text);
            let back: f64 = shortest(x).parse().unwrap();
            assert!(back == x || (x.is_nan() && back.is_nan()));
        }
    }

    #[test]
    fn a_full_disk_while_encoding_is_said_as_the_os_error() {
        let full = bincode::error::EncodeError::Io {
            inner: io::Error::from_raw_os_error(28),
            index: 7,
        };
        let e = enc(full);
        assert_eq!(e.kind(), io::ErrorKind::StorageFull);
        assert_eq!(e.to_string(), "No space left on device (os error 28)");
    }
}
