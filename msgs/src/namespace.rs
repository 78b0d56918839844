//! Per-run iceoryx2 isolation: every file a run creates carries the prefix
//! `as<run>_` (in /dev/shm and elsewhere) and lives under the root path
//! `<base>/<run>/`, so two runs, or parallel tests, never meet, and a run's
//! leftovers can be removed by name.

use crate::iox::{IoxError, iox};
use iceoryx2::config::Config;
use iceoryx2::prelude::{FileName, Path, SemanticString};

/// The iceoryx2 file prefix of run `run`.
#[must_use]
pub fn prefix(run: &str) -> String {
    format!("as{run}_")
}

/// The iceoryx2 configuration of a run: prefix [`prefix`], root path `root`
/// (a directory that belongs to the run, with a trailing `/`), and no scan
/// for dead nodes when a node is created or dropped or a service opened.
///
/// NOTE: each scan reads every node's files in the namespace, so with the
/// defaults a run's start-up and shutdown cost O(n²) file opens (≈ 750 per
/// node at 100 nodes). A run's namespace is private to it and removed
/// whole at its end, and a node that dies ends the run, so there is never
/// a dead node's leftover for the scan to clean.
pub fn config(run: &str, root: &std::path::Path) -> Result<Config, IoxError> {
    let mut cfg = Config::default();
    cfg.global.node.cleanup_dead_nodes_on_creation = false;
    cfg.global.node.cleanup_dead_nodes_on_destruction = false;
    cfg.global.service.cleanup_dead_nodes_on_open = false;
    cfg.global.prefix =
        FileName::new(prefix(run).as_bytes()).map_err(iox("file prefix from the run id"))?;
    let mut root = root.to_string_lossy().into_owned();
    if !root.ends_with('/') {
        root.push('/');
    }
    cfg.global
        .set_root_path(&Path::new(root.as_bytes()).map_err(iox("root path"))?);
    Ok(cfg)
}
