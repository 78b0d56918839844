//! Placement files (`HOSTS.toml`, issue 12): which machine runs which node
//! of a scenario, and the links between machines that this makes.
//!
//! ```toml
//! [tls]                            # mutual TLS (SECURITY.md); or `insecure = true`
//! ca = "certs/ca.pem"              # paths relative to this file
//! cert = "certs/alice.pem"
//! key = "certs/alice.key"
//!
//! [[host]]
//! name = "lab-a"                   # [A-Za-z0-9_-]+, unique
//! endpoint = "quic/10.0.0.2:7447"  # where its `attsync host` daemon listens
//! agents = [1, 3, 5]               # agent ids of the scenario (default: none)
//! leader = true                    # on at most one host (default: false)
//! ```
//! Nodes on no host run on the orchestrator's machine ("local").
//!
//! [`load`] reads a file (within [`MAX_FILE_BYTES`]) and checks it on its
//! own: TOML, the format ([`mod@file`]), names, endpoints (`endpoint`), the
//! leader, agents placed twice, empty hosts. [`Placement::of`] then checks
//! it against a scenario's network (every agent exists) and works out the
//! cut edges. Each stage reports every problem at once ([`HostsError`]).
//! [`Hosts::secure`] settles how the links are secured (the file's `[tls]`
//! or `insecure`, unless the command line says otherwise) and that every
//! endpoint fits it.
//!
//! # Layout
//! - [`mod@file`] — the format as serde types, and the rules a file must keep;
//! - `endpoint` — the shape of a TCP endpoint in Zenoh's syntax;
//! - [`placement`] — [`Placement`]: nodes per host, local nodes, [`CutEdge`]s;
//! - [`report`] — the text `attsync check --hosts` prints;
//! - `error` — [`HostsError`].

mod endpoint;
mod error;
pub mod file;
pub mod placement;
pub mod report;
mod security;

pub use error::HostsError;
pub use file::Host;
pub use placement::{CutEdge, Placement};

use scenario::input::{self, Limit};
use std::path::{Path, PathBuf};

/// The largest hosts file accepted: 64 MiB (room for millions of agent ids).
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// The size limit of a hosts file.
const LIMIT: Limit = Limit {
    bytes: MAX_FILE_BYTES,
    what: "a hosts file",
};

/// A hosts file, loaded and checked on its own.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Hosts {
    /// The file it came from (named in every message).
    pub path: PathBuf,
    /// Its `[[host]]` tables, in file order (a host's index is its place here).
    pub hosts: Vec<Host>,
    /// How the links are secured: the file's (`[tls]`, `insecure`) until
    /// [`Hosts::secure`] settles it; `None`, neither said.
    pub security: Option<crate::trust::Security>,
}

/// Reads (at most [`MAX_FILE_BYTES`]) and checks the hosts file `path`:
/// its TOML and format, then the rules of [`file::check`], each stage
/// reporting every problem at once.
pub fn load(path: &Path) -> Result<Hosts, HostsError> {
    let text =
        input::read_limited(path, LIMIT).map_err(|error| HostsError::Io(path.to_owned(), error))?;
    load_str(path, &text)
}

/// As [`load`], from text already read (`path` is used in messages).
pub fn load_str(path: &Path, text: &str) -> Result<Hosts, HostsError> {
    let parsed: file::HostsFile = scenario::parse::typed(text)
        .map_err(|issues| HostsError::Invalid(path.to_owned(), issues))?;
    let mut issues = file::check(&parsed.host);
    let security = security::of_file(path, &parsed, &mut issues);
    if !issues.is_empty() {
        return Err(HostsError::Invalid(path.to_owned(), issues));
    }
    Ok(Hosts {
        path: path.to_owned(),
        hosts: parsed.host,
        security,
    })
}
