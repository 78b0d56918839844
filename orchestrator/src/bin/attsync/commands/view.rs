//! `attsync view`: a run directory's `view.html`, made again from its files.

use attsync::Error;
use std::path::PathBuf;

/// `attsync view DIR`.
#[derive(Debug, clap::Args)]
pub struct View {
    /// A run's results directory (it holds scenario.toml, summary.json and
    /// states.bin).
    pub dir: PathBuf,
}

/// Writes `DIR/view.html` and prints its path.
pub fn exec(a: View) -> Result<(), Error> {
    let file = attsync::view::regenerate(&a.dir)?;
    println!("view: {}", file.display());
    Ok(())
}
