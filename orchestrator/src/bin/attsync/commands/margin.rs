//! `attsync margin`: the linearisation's delay margin and rightmost root.

use super::ScenarioArgs;
use attsync::Error;
use attsync::scenario::StiffnessCheck;
use std::path::PathBuf;

/// `attsync margin SCENARIO [--set K=V]… [--json FILE]`.
#[derive(Debug, clap::Args)]
pub struct MarginCmd {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Also write the result as JSON (`margin`, `omega`, `rightmost`) to FILE
    /// (`-`: stdout only, nothing else printed).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// Prints the margin (and writes `--json`); a scenario that cannot be
/// linearised is exit 2, nothing written.
pub fn exec(a: MarginCmd) -> Result<(), Error> {
    let loaded = a.scenario.load(StiffnessCheck::Warn)?;
    let report = attsync::margin::margin(&loaded)?;
    let json = serde_json::to_string_pretty(&report.json()).expect("json") + "\n";
    match a.json.as_deref() {
        Some(p) if p.as_os_str() == "-" => return super::write_output(None, json.as_bytes()),
        Some(p) => super::write_output(Some(p), json.as_bytes())?,
        None => {}
    }
    print!("{}", report.text());
    Ok(())
}
