//! What `attsync host` says on its stdout ([`DaemonEvent`], one line
//! each): that it listens (its name, endpoints and version), and each run
//! it starts or refuses. The daemon's library calls a [`Report`]; the
//! command prints.

use std::fmt;
use std::sync::Arc;

/// One thing a daemon reports.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DaemonEvent {
    /// Its Zenoh session is open and its queryables declared.
    Listening {
        /// The host's name.
        name: String,
        /// The endpoints it listens on.
        listen: Vec<String>,
        /// The endpoints it dials.
        connect: Vec<String>,
    },
    /// It started a run's nodes.
    Started {
        /// The run's id.
        run: String,
        /// The nodes it started (their names).
        nodes: Vec<String>,
        /// The hosts it dialled for the run.
        dialled: Vec<String>,
    },
    /// It refused a run, or could not start it (nothing runs).
    Refused {
        /// The run's id.
        run: String,
        /// Why.
        why: String,
    },
}

impl fmt::Display for DaemonEvent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Listening {
                name,
                listen,
                connect,
            } => {
                let version = env!("CARGO_PKG_VERSION");
                write!(
                    f,
                    "attsync host {name} {version}: listening on {}",
                    listen.join(", ")
                )?;
                if !connect.is_empty() {
                    write!(f, "; dialling {}", connect.join(", "))?;
                }
                Ok(())
            }
            Self::Started {
                run,
                nodes,
                dialled,
            } => {
                write!(
                    f,
                    "run {run}: started {} nodes ({})",
                    nodes.len(),
                    nodes.join(", ")
                )?;
                if !dialled.is_empty() {
                    write!(f, "; dialled host {}", dialled.join(", host "))?;
                }
                Ok(())
            }
            Self::Refused { run, why } => write!(f, "run {run}: refused: {why}"),
        }
    }
}

/// Where a daemon's events go (`attsync host` prints each on a line).
pub type Report = Arc<dyn Fn(DaemonEvent) + Send + Sync>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_event_is_one_line_that_names_what_it_is_about() {
        let listening = DaemonEvent::Listening {
            name: "a".into(),
            listen: vec!["tls/127.0.0.1:7447".into()],
            connect: Vec::new(),
        };
        let text = listening.to_string();
        assert!(
            text.starts_with("attsync host a ")
                && text.ends_with("listening on tls/127.0.0.1:7447")
        );
        let started = DaemonEvent::Started {
            run: "r1".into(),
            nodes: vec!["agent-1".into(), "leader".into()],
            dialled: Vec::new(),
        };
        assert_eq!(
            started.to_string(),
            "run r1: started 2 nodes (agent-1, leader)"
        );
        let meshed = DaemonEvent::Started {
            run: "r2".into(),
            nodes: vec!["agent-4".into()],
            dialled: vec!["a".into(), "b".into()],
        };
        assert_eq!(
            meshed.to_string(),
            "run r2: started 1 nodes (agent-4); dialled host a, host b"
        );
        for e in [listening, started] {
            assert!(!e.to_string().contains('\n'));
        }
    }
}
