//! Rule `version`: the candidate must refuse a configuration of another
//! protocol version (exit non-zero, promptly).

use super::candidate::{Candidate, EXIT_TIMEOUT, candidate_config, success};
use super::rules::{Report, RuleId};
use super::{ConformError, ConformOptions};
use crate::launch::namespace::{self, Namespace};
use crate::launch::supervise::describe;
use attitude::network::Network;
use msgs::PROTOCOL_VERSION;

/// Starts agent `index` of `net` with a config of another version and
/// records rule `version`.
pub(super) fn version_probe(
    net: &Network,
    index: usize,
    opts: &ConformOptions,
    report: &mut Report,
) -> Result<(), ConformError> {
    let ns = Namespace::create().map_err(|source| ConformError::Io {
        path: namespace::base_dir(),
        source,
    })?;
    let mut cfg = candidate_config(net, index, ns.run(), ns.dir(), opts);
    cfg.protocol_version = PROTOCOL_VERSION + 100;
    let file = ns.dir().join("candidate-bad-version.json");
    cfg.write(&file)?;
    let mut cand = Candidate::start(opts, &file, false)?;
    match cand.wait_exit(EXIT_TIMEOUT) {
        Some(st) if !success(&st) => report.pass(RuleId::Version),
        Some(st) => report.fail(
            RuleId::Version,
            format!(
                "given protocol_version {} it ended with {} instead of refusing",
                cfg.protocol_version,
                describe(&st)
            ),
        ),
        None => {
            cand.kill();
            report.fail(
                RuleId::Version,
                format!(
                    "given protocol_version {} it was still running after {} s",
                    cfg.protocol_version,
                    EXIT_TIMEOUT.as_secs()
                ),
            );
        }
    }
    cand.kill_group();
    Ok(())
}
