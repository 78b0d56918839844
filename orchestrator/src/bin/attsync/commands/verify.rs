//! `attsync verify`: a run's files against its manifest, and a re-run of
//! its scenario against its results.

use super::WaitArg;
use attsync::Error;
use attsync::interrupt::Interrupt;
use attsync::run::Engine;
use attsync::verify::{self, VerifyOptions};
use std::io::IsTerminal;
use std::path::PathBuf;

/// `attsync verify DIR [--engine E] [--wait W] [--quiet]`.
#[derive(Debug, clap::Args)]
pub struct Verify {
    /// A run's results directory (holding manifest.json).
    pub dir: PathBuf,
    /// Re-run with this engine [default: the recorded one] (the engines
    /// are bit-identical, so a processes run can be verified in-process).
    #[arg(long, value_enum)]
    pub engine: Option<Engine>,
    /// How the re-run's node processes wait [default: the recorded strategy, else adaptive].
    #[arg(long, value_enum)]
    pub wait: Option<WaitArg>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Prints the report; a run that does not reproduce is an error (exit 1).
pub fn exec(a: Verify, interrupt: &Interrupt) -> Result<(), Error> {
    let opts = VerifyOptions {
        engine: a.engine,
        wait: a.wait.map(Into::into),
        progress: !a.quiet && std::io::stderr().is_terminal(),
    };
    let report = verify::verify(&a.dir, &opts, interrupt)?;
    print!("{report}");
    if report.is_identical() {
        Ok(())
    } else {
        Err(Error::NotIdentical)
    }
}
