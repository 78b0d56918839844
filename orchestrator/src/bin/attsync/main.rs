//! `attsync`: run networks of rigid bodies synchronising their attitudes.
//!
//! The binary only parses the command line and calls the library, one file
//! per subcommand in `commands/`; the exit code comes from the error
//! ([`attsync::Error::exit_code`]): 0 success, 2 invalid scenario, `--set`
//! or option, 1 any other error, 128 + N interrupted by signal N; `verify`:
//! 0 bit-identical, 1 different, 2 a run that cannot be verified.

mod commands;

use clap::Parser;
use std::process::ExitCode;

/// Leader-follower attitude synchronisation on SO(3), one process per rigid body.
#[derive(Debug, Parser)]
#[command(name = "attsync", version, about)]
struct Cli {
    #[command(subcommand)]
    command: commands::Command,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    init_tracing();
    match commands::exec(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if e.is_scenario() {
                eprintln!("{e}");
            } else {
                eprintln!("error: {e}");
            }
            ExitCode::from(e.exit_code())
        }
    }
}

/// Logs to stderr at the level of `ATTSYNC_LOG` (default `warn`, Zenoh's
/// own `error`: its warnings are about its configuration, which attsync
/// sets; `debug` shows the phases of a run), as ARCHITECTURE.md's logging
/// policy says.
fn init_tracing() {
    let filter = tracing_subscriber::EnvFilter::try_from_env("ATTSYNC_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn,zenoh=error"));
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(false)
        .init();
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_command_line_is_well_formed() {
        use clap::CommandFactory;
        super::Cli::command().debug_assert();
    }
}
