//! `attsync export`: a run's states.bin as CSV, as an MCAP recording, or
//! the run's tables as Parquet.

use attsync::Error;
use std::path::{Path, PathBuf};

/// `attsync export DIR[/states.bin] (--csv | --mcap | --parquet) [--out PATH]`.
#[derive(Debug, clap::Args)]
pub struct Export {
    /// A run's results directory, or its states.bin.
    pub states: PathBuf,
    #[command(flatten)]
    pub format: Format,
    /// Write here instead of stdout (--csv), DIR/states.mcap (--mcap) or
    /// into DIR (--parquet: a directory).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// The output format: exactly one.
#[derive(Debug, clap::Args)]
#[group(required = true, multiple = false)]
pub struct Format {
    /// Write CSV (long form: one row per node per sample; node 0 is the leader).
    #[arg(long)]
    pub csv: bool,
    /// Write an MCAP recording (Foxglove's FrameTransforms on /tf, errors on
    /// /errors/agent-<id>, Protobuf, simulated time) for Foxglove, Lichtblick
    /// and Rerun; default --out DIR/states.mcap.
    #[arg(long)]
    pub mcap: bool,
    /// Write errors.parquet, states.parquet (one row per agent per sample,
    /// torques included) and leader.parquet: tables pandas, polars and
    /// DuckDB read as they are; default --out DIR.
    #[arg(long)]
    pub parquet: bool,
}

/// Writes the CSV, the recording or the tables.
pub fn exec(mut a: Export) -> Result<(), Error> {
    if a.states.is_dir() {
        a.states = a.states.join(attsync::results::layout::STATES);
    }
    if a.format.parquet {
        if !a.states.is_file() {
            return Err(Error::Export(format!(
                "{}: no states.bin there (give a run's results directory or its states.bin)",
                a.states.display()
            )));
        }
        let dir = a.states.parent().unwrap_or(Path::new("")).to_owned();
        return parquet(&dir, a.out.as_deref().unwrap_or(&dir));
    }
    if a.format.mcap {
        let out = a.out.unwrap_or_else(|| default_mcap(&a.states));
        return mcap(&a.states, &out);
    }
    let mut text = Vec::new();
    attsync::results::states::export_csv(&a.states, &mut text)
        .map_err(|e| Error::Export(e.to_string()))?;
    super::write_output(a.out.as_deref(), &text)
}

/// `states.mcap` beside `states`.
fn default_mcap(states: &Path) -> PathBuf {
    let dir = states.parent().unwrap_or(Path::new(""));
    dir.join(attsync::results::layout::STATES_MCAP)
}

/// Writes the recording of `states` to `out` and says what it holds.
#[cfg(feature = "mcap")]
fn mcap(states: &Path, out: &Path) -> Result<(), Error> {
    let s = attsync::export::write_mcap(states, out).map_err(|e| Error::Export(e.to_string()))?;
    println!(
        "wrote {}: {} samples, {} channels, {} messages",
        out.display(),
        s.samples,
        s.channels,
        s.messages
    );
    Ok(())
}

/// Without the `mcap` feature there is no recording.
#[cfg(not(feature = "mcap"))]
fn mcap(_: &Path, out: &Path) -> Result<(), Error> {
    Err(Error::Export(format!(
        "{}: this attsync was built without the cargo feature `mcap`",
        out.display()
    )))
}

/// Writes the run's tables in `dir` into `out` and says what it wrote.
#[cfg(feature = "parquet")]
fn parquet(dir: &Path, out: &Path) -> Result<(), Error> {
    let w = attsync::tables::write_parquet(dir, out).map_err(|e| Error::Export(e.to_string()))?;
    for f in &w.files {
        println!("wrote {}", f.display());
    }
    println!("{} rows of agent states", w.state_rows);
    Ok(())
}

/// Without the `parquet` feature there are no tables.
#[cfg(not(feature = "parquet"))]
fn parquet(_: &Path, out: &Path) -> Result<(), Error> {
    Err(Error::Export(format!(
        "{}: this attsync was built without the cargo feature `parquet`",
        out.display()
    )))
}
