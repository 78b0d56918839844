//! `attsync export`: a run's states.bin as CSV, or as an MCAP recording.

use attsync::Error;
use std::path::{Path, PathBuf};

/// `attsync export DIR/states.bin (--csv | --mcap) [--out FILE]`.
#[derive(Debug, clap::Args)]
pub struct Export {
    /// The states.bin file of a run.
    pub states: PathBuf,
    #[command(flatten)]
    pub format: Format,
    /// Write here instead of stdout (--csv) or DIR/states.mcap (--mcap).
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
}

/// Writes the CSV or the recording.
pub fn exec(a: Export) -> Result<(), Error> {
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
