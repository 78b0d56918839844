//! `attsync export DIR --parquet` (feature `parquet`, on by default): a
//! run's results as three Parquet tables that pandas, polars and DuckDB
//! read as they are, the same tables as Python's `Run.to_parquet`:
//! - `errors.parquet`: `errors.csv`'s rows and columns (`t`, `agent`,
//!   `att_err`, `angvel_err`, `obs_att_err`, `obs_angvel_err`);
//! - `states.parquet`: one row per agent per sample: `t`, `agent`,
//!   `r11`…`r33` (Rᵢ row by row), `w1`…`w3` (ωᵢ), `r_hat11`…, `w_hat1`…,
//!   `s_hat1`… (the observer's R̂ᵢ, ω̂ᵢ, σ̂ᵢ), `tau1`…`tau3` (the torque
//!   applied, N·m);
//! - `leader.parquet`: one row per sample: `t`, `r11`…`r33` (R₀), `w1`…
//!   (ω₀), `s1`… (σ₀).
//!
//! `t` is the record's step × dt (as `Run.states.t`); numbers are `DOUBLE`,
//! exact, a NaN written as null (as pandas writes it); `agent` is `INT64`.
//! Each file is written under a temporary name and renamed when complete.
//!
//! # Layout
//! - this file: [`write_parquet`] and the tables' columns;
//! - [`writer`]: one table in row groups ([`writer::Table`]).

pub mod writer;

use crate::results::layout::RunLayout;
use crate::results::states::{self, StatesError};
use std::path::{Path, PathBuf};
use writer::{Kind, Table, WriteError};

/// Why the tables were not written.
#[derive(Debug, thiserror::Error)]
pub enum TablesError {
    /// `states.bin` cannot be read (the message names the file).
    #[error(transparent)]
    States(#[from] StatesError),
    /// `errors.csv` cannot be read or holds something else.
    #[error("{}: {reason}", file.display())]
    Errors {
        /// `errors.csv`.
        file: PathBuf,
        /// What is wrong (with its line).
        reason: String,
    },
    /// A table could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// What was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    /// The three files.
    pub files: Vec<PathBuf>,
    /// Rows of `states.parquet`.
    pub state_rows: u64,
}

/// The names of a vector's or matrix's columns: `p1`…`p3`, or `p11`…`p33`.
fn names(prefix: &str, matrix: bool) -> Vec<String> {
    if matrix {
        (1..=3)
            .flat_map(|i| (1..=3).map(move |j| format!("{prefix}{i}{j}")))
            .collect()
    } else {
        (1..=3).map(|i| format!("{prefix}{i}")).collect()
    }
}

/// `t`, then `rest` as number columns (after `agent` if `agent`).
fn columns(agent: bool, rest: &[(&str, bool)]) -> Vec<(String, Kind)> {
    let mut c = vec![("t".to_string(), Kind::Number)];
    if agent {
        c.push(("agent".into(), Kind::Integer));
    }
    for (prefix, matrix) in rest {
        c.extend(
            names(prefix, *matrix)
                .into_iter()
                .map(|n| (n, Kind::Number)),
        );
    }
    c
}

/// Writes the three tables of the run in `dir` into `out` (created).
///
/// # Errors
/// See [`TablesError`]; a table not written leaves no file.
pub fn write_parquet(dir: &Path, out: &Path) -> Result<Written, TablesError> {
    std::fs::create_dir_all(out).map_err(|e| WriteError {
        file: out.to_owned(),
        source: e.into(),
    })?;
    let run = RunLayout::new(dir);
    let errors = write_errors(&run.errors_csv(), &out.join("errors.parquet"))?;
    let (states, leader, state_rows) = write_states(&run.states(), out)?;
    Ok(Written {
        files: vec![errors, states, leader],
        state_rows,
    })
}

/// `states.parquet` and `leader.parquet` from `states.bin`, one pass.
fn write_states(file: &Path, out: &Path) -> Result<(PathBuf, PathBuf, u64), TablesError> {
    let records = states::open(file)?;
    let dt = records.header.dt;
    let ids = records.header.agent_ids.clone();
    let agent_cols = [
        ("r", true),
        ("w", false),
        ("r_hat", true),
        ("w_hat", false),
        ("s_hat", false),
        ("tau", false),
    ];
    let mut agents = Table::create(
        &out.join("states.parquet"),
        "states",
        &columns(true, &agent_cols),
    )?;
    let leader_cols = [("r", true), ("w", false), ("s", false)];
    let mut leader = Table::create(
        &out.join("leader.parquet"),
        "leader",
        &columns(false, &leader_cols),
    )?;
    let mut rows = 0;
    for rec in records {
        let rec = rec?;
        let t = rec.step as f64 * dt;
        for (id, a) in ids.iter().zip(&rec.agents) {
            agents.number(0, t);
            agents.integer(1, i64::from(*id));
            let parts = [&a.r[..], &a.w, &a.r_hat, &a.w_hat, &a.s_hat, &a.tau];
            for (c, x) in parts.into_iter().flatten().enumerate() {
                agents.number(2 + c, *x);
            }
            agents.end_row()?;
            rows += 1;
        }
        leader.number(0, t);
        let l = &rec.leader;
        for (c, x) in [&l.r0[..], &l.w0, &l.s0].into_iter().flatten().enumerate() {
            leader.number(1 + c, *x);
        }
        leader.end_row()?;
    }
    Ok((agents.finish()?, leader.finish()?, rows))
}

/// `errors.parquet` from `errors.csv` (every number read back exactly: the
/// file holds each in its shortest round-trip form; an empty cell is null).
fn write_errors(file: &Path, to: &Path) -> Result<PathBuf, TablesError> {
    let bad = |reason: String| TablesError::Errors {
        file: file.to_owned(),
        reason,
    };
    let text = std::fs::read_to_string(file).map_err(|e| bad(e.to_string()))?;
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    let names: Vec<&str> = header.split(',').collect();
    if names.len() < 2 || names[..2] != ["t", "agent"] {
        return Err(bad(format!(
            "line 1: {header:?} is not errors.csv's header"
        )));
    }
    let mut cols = vec![
        ("t".to_string(), Kind::Number),
        ("agent".into(), Kind::Integer),
    ];
    cols.extend(names[2..].iter().map(|n| (n.to_string(), Kind::Number)));
    let mut table = Table::create(to, "errors", &cols)?;
    for (k, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let at = |what: String| bad(format!("line {}: {what}", k + 2));
        if cells.len() != names.len() {
            return Err(at(format!("{} cells, not {}", cells.len(), names.len())));
        }
        for (c, cell) in cells.iter().enumerate() {
            if c == 1 {
                let id = cell.parse().map_err(|_| at(format!("agent {cell:?}")))?;
                table.integer(1, id);
            } else if cell.is_empty() {
                table.number(c, f64::NAN);
            } else {
                let x = cell
                    .parse()
                    .map_err(|_| at(format!("{} {cell:?}", names[c])))?;
                table.number(c, x);
            }
        }
        table.end_row()?;
    }
    Ok(table.finish()?)
}
