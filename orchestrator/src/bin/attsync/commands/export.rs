//! `attsync export`: a run's states.bin as CSV.

use attsync::Error;
use std::path::PathBuf;

/// `attsync export DIR/states.bin --csv [--out FILE]`.
#[derive(Debug, clap::Args)]
pub struct Export {
    /// The states.bin file of a run.
    pub states: PathBuf,
    /// Write CSV (long form: one row per node per sample; node 0 is the leader).
    #[arg(long, required = true)]
    pub csv: bool,
    /// Write here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Writes the CSV.
pub fn exec(a: Export) -> Result<(), Error> {
    let mut text = Vec::new();
    attsync::results::states::export_csv(&a.states, &mut text).map_err(Error::Export)?;
    super::write_output(a.out.as_deref(), &text)
}
