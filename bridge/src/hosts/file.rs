//! The hosts file's format ([`HostsFile`], [`Host`]) and the rules a file
//! must keep on its own ([`check`]): a safe, unique name per host, a TCP
//! endpoint, the leader on at most one host, no agent placed twice (nor
//! agent 0, the leader's node id), no host with nothing on it.

use super::endpoint;
use scenario::Issue;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::collections::hash_map::Entry;

/// Longest host name, in characters (it goes into paths and key expressions).
pub const MAX_NAME_CHARS: usize = 64;

/// The whole file: `[[host]]` tables, and how the links are secured
/// (`[tls]`, or `insecure = true`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HostsFile {
    /// Plain TCP without authentication (`tcp/` endpoints; warned about).
    #[serde(default)]
    pub insecure: bool,
    /// The orchestrator's identity under mutual TLS (`quic/` endpoints).
    #[serde(default)]
    pub tls: Option<TlsTable>,
    /// The hosts, in file order.
    #[serde(default)]
    pub host: Vec<Host>,
}

/// `[tls]`: the user's files, relative to the hosts file's directory.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TlsTable {
    /// The lab's CA certificate (PEM).
    pub ca: std::path::PathBuf,
    /// The user's certificate (PEM, signed by the CA).
    pub cert: std::path::PathBuf,
    /// The user's private key (PEM).
    pub key: std::path::PathBuf,
}

/// One machine and the nodes it runs.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Host {
    /// Its name (`[A-Za-z0-9_-]+`, at most [`MAX_NAME_CHARS`], unique in the file).
    pub name: String,
    /// Where its daemon listens, `quic/<ip-or-name>:<port>` (Zenoh's
    /// syntax; `tcp/…` when insecure).
    pub endpoint: String,
    /// Ids of the scenario's agents it runs (1-based, as in `[[agent]] id`).
    #[serde(default)]
    pub agents: Vec<u32>,
    /// Whether it runs the leader (node 0).
    #[serde(default)]
    pub leader: bool,
}

/// Every rule `hosts` breaks, in file order (empty: the file is sound).
#[must_use]
pub fn check(hosts: &[Host]) -> Vec<Issue> {
    let mut issues = Vec::new();
    if hosts.is_empty() {
        issues.push(issue(
            "host",
            "the file places nothing: add [[host]] tables".into(),
        ));
    }
    let mut names: HashMap<&str, usize> = HashMap::new();
    let mut placed: HashMap<u32, (usize, usize)> = HashMap::new();
    let mut leader: Option<usize> = None;
    for (h, host) in hosts.iter().enumerate() {
        name(h, host, &mut names, &mut issues);
        if let Some(reason) = endpoint::problem(&host.endpoint) {
            issues.push(issue(&format!("host[{h}].endpoint"), reason));
        }
        if host.leader {
            match leader {
                Some(first) => issues.push(issue(
                    &format!("host[{h}].leader"),
                    format!("the leader is already on host[{first}] (at most one host has leader = true)"),
                )),
                None => leader = Some(h),
            }
        }
        agents(h, host, &mut placed, &mut issues);
        if host.agents.is_empty() && !host.leader {
            issues.push(issue(
                &format!("host[{h}]"),
                format!(
                    "host `{}` runs nothing: give it agents or leader = true, or remove it",
                    host.name
                ),
            ));
        }
    }
    issues
}

/// Checks host `h`'s name: a safe token, not used by an earlier host.
fn name<'a>(
    h: usize,
    host: &'a Host,
    names: &mut HashMap<&'a str, usize>,
    issues: &mut Vec<Issue>,
) {
    let field = format!("host[{h}].name");
    let n = host.name.as_str();
    let safe = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
    if n.is_empty() {
        issues.push(issue(&field, "is empty".into()));
    } else if !n.chars().all(safe) || n.chars().count() > MAX_NAME_CHARS {
        issues.push(issue(
            &field,
            format!("`{n}` is not a name of 1 to {MAX_NAME_CHARS} letters, digits, `_` or `-` (it is used in paths and Zenoh key expressions)"),
        ));
    } else if let Entry::Occupied(first) = names.entry(n) {
        let first = *first.get();
        issues.push(issue(
            &field,
            format!("`{n}` is already the name of host[{first}]"),
        ));
    } else {
        names.insert(n, h);
    }
}

/// Checks host `h`'s agents: not the leader's id 0, none placed before.
fn agents(
    h: usize,
    host: &Host,
    placed: &mut HashMap<u32, (usize, usize)>,
    issues: &mut Vec<Issue>,
) {
    for (k, &id) in host.agents.iter().enumerate() {
        let field = format!("host[{h}].agents[{k}]");
        if id == 0 {
            issues.push(issue(
                &field,
                "0 is the leader's node, not an agent: write leader = true".into(),
            ));
            continue;
        }
        match placed.entry(id) {
            Entry::Vacant(v) => {
                v.insert((h, k));
            }
            Entry::Occupied(o) => {
                let (fh, fk) = *o.get();
                issues.push(issue(
                    &field,
                    format!("agent {id} is already placed at host[{fh}].agents[{fk}] (an agent runs on one host)"),
                ));
            }
        }
    }
}

fn issue(field: &str, reason: String) -> Issue {
    Issue {
        field: field.to_owned(),
        reason,
    }
}
