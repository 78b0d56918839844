//! Who may talk to an `attsync host` daemon, and what it may start
//! (issue 33; the threat model: SECURITY.md).
//!
//! - [`Security`]: how every Zenoh session of a run across hosts is
//!   secured — mutual TLS ([`TlsFiles`]: a lab's CA, and a certificate
//!   and key per host and per user), or plain TCP only when asked for
//!   with `--insecure`.
//! - [`allow`]: the programs a daemon starts for a plug-in node, only
//!   those it was told to allow (`attsync host --allow-plugin PATH`).
//! - [`certs`]: `attsync host --gen-certs DIR`, a lab's CA and its
//!   certificates in one command.
//!
//! A leaf: it knows nothing of runs, hosts files or Zenoh sessions.

pub mod allow;
pub mod certs;

use std::path::{Path, PathBuf};
use thiserror::Error;

/// The PEM files of one party's identity under mutual TLS.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TlsFiles {
    /// The lab's CA certificate: a peer is trusted if its certificate is
    /// signed by it.
    pub ca: PathBuf,
    /// This party's certificate (signed by the CA).
    pub cert: PathBuf,
    /// This party's private key.
    pub key: PathBuf,
}

/// How the Zenoh sessions of a run across hosts are secured.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Security {
    /// Mutual TLS (1.3, QUIC's) over `quic/` endpoints: each side shows a certificate
    /// signed by the lab's CA, the dialled side's naming the address
    /// dialled; everything is encrypted.
    Tls(TlsFiles),
    /// Plain TCP over `tcp/` endpoints: nobody is authenticated and
    /// nothing is encrypted (`--insecure`, warned about).
    Insecure,
}

/// The warning `--insecure` earns, at a daemon's start and in every run.
pub const INSECURE_WARNING: &str = "INSECURE: plain TCP (--insecure): anyone who can reach a daemon's \
     port can start a run there, and every message crosses the network in clear; use quic/ \
     endpoints with --cert, --key and --ca (attsync host --gen-certs DIR; SECURITY.md)";

impl Security {
    /// The Zenoh protocol of its endpoints: `quic` or `tcp`.
    #[must_use]
    pub fn protocol(&self) -> &'static str {
        match self {
            Self::Tls(_) => "quic",
            Self::Insecure => "tcp",
        }
    }

    /// Its name in summaries: `mutual-tls` or `insecure`.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::Tls(_) => "mutual-tls",
            Self::Insecure => "insecure",
        }
    }

    /// Why `endpoint` (from `flag`) cannot carry this security, if it cannot.
    #[must_use]
    pub fn endpoint_problem(&self, endpoint: &str) -> Option<String> {
        let protocol = endpoint.split_once('/').map_or("", |(p, _)| p);
        match (self, protocol) {
            (Self::Tls(_), "quic") | (Self::Insecure, "tcp") => None,
            (_, "tls") => Some(format!(
                "`{endpoint}`: Zenoh's TLS-over-TCP link loses messages under two-way traffic \
                 (eclipse-zenoh/zenoh#2557, open in 1.10.2): write quic/… (mutual TLS over QUIC)"
            )),
            (Self::Tls(_), "tcp") => Some(format!(
                "`{endpoint}` is plain TCP: write quic/… (mutual TLS), or give --insecure to run without authentication"
            )),
            (Self::Insecure, "quic") => Some(format!(
                "`{endpoint}` is TLS (QUIC) but --insecure was given: drop --insecure and give --cert, --key and --ca"
            )),
            _ => Some(format!(
                "`{endpoint}`: only quic/ (or tcp/ with --insecure) endpoints are supported"
            )),
        }
    }
}

/// A security setting that cannot be used.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum TrustError {
    /// A file named by a flag or field cannot be used.
    #[error("{field}: {}: {reason}", path.display())]
    File {
        /// The flag or field that named it (`--cert`, `tls.key`…).
        field: String,
        /// The file.
        path: PathBuf,
        /// Why not.
        reason: String,
    },
    /// Neither TLS files nor `--insecure`, or both, or some files only.
    #[error("{0}")]
    Choice(String),
    /// A certificate could not be made (`--gen-certs`).
    #[error("--gen-certs: {0}")]
    Certs(String),
}

impl TrustError {
    /// A bad flag or file: the user's input is at fault, nothing started
    /// (exit code 2); not so if certificates could not be made.
    #[must_use]
    pub fn is_invalid(&self) -> bool {
        !matches!(self, Self::Certs(_))
    }
}

/// The names of the three files' flags or fields, for messages.
#[derive(Debug, Clone, Copy)]
pub struct FieldNames {
    /// The CA certificate's (`--ca`, `tls.ca`).
    pub ca: &'static str,
    /// The certificate's.
    pub cert: &'static str,
    /// The key's.
    pub key: &'static str,
}

/// The command-line flags' names.
pub const FLAGS: FieldNames = FieldNames {
    ca: "--ca",
    cert: "--cert",
    key: "--key",
};

/// The security chosen by `--ca`/`--cert`/`--key` (all three, checked)
/// or `insecure` (alone); anything else is an error saying what to give.
pub fn choose(
    ca: Option<PathBuf>,
    cert: Option<PathBuf>,
    key: Option<PathBuf>,
    insecure: bool,
    names: FieldNames,
) -> Result<Security, TrustError> {
    let given = [ca.is_some(), cert.is_some(), key.is_some()];
    match (ca, cert, key, insecure) {
        (None, None, None, true) => Ok(Security::Insecure),
        (Some(ca), Some(cert), Some(key), false) => {
            let files = TlsFiles { ca, cert, key };
            files.check(names)?;
            Ok(Security::Tls(files))
        }
        (_, _, _, true) => Err(TrustError::Choice(format!(
            "--insecure and TLS files ({}, {}, {}) exclude each other",
            names.ca, names.cert, names.key
        ))),
        _ if given.iter().any(|g| *g) => Err(TrustError::Choice(format!(
            "mutual TLS needs all three of {}, {} and {}",
            names.ca, names.cert, names.key
        ))),
        _ => Err(TrustError::Choice(format!(
            "no security given: give {}, {} and {} (mutual TLS; attsync host --gen-certs DIR makes them), \
             or --insecure for plain TCP without authentication",
            names.ca, names.cert, names.key
        ))),
    }
}

/// PEM markers a certificate file and a key file must hold.
const CERT_MARK: &str = "-----BEGIN CERTIFICATE-----";
/// (A PKCS#8, PKCS#1 or SEC1 key: `… PRIVATE KEY-----`.)
const KEY_MARK: &str = "PRIVATE KEY-----";

impl TlsFiles {
    /// Checks that each file reads and holds PEM of its kind.
    pub fn check(&self, names: FieldNames) -> Result<(), TrustError> {
        pem_file(names.ca, &self.ca, CERT_MARK, "a PEM certificate")?;
        pem_file(names.cert, &self.cert, CERT_MARK, "a PEM certificate")?;
        pem_file(names.key, &self.key, KEY_MARK, "a PEM private key")
    }
}

/// Longest PEM file read, bytes (a certificate chain is a few KiB).
const MAX_PEM_BYTES: u64 = 1 << 20;

/// Checks that `path` (named by `field`) reads, is small and holds `mark`.
fn pem_file(field: &str, path: &Path, mark: &str, what: &str) -> Result<(), TrustError> {
    let bad = |reason: String| TrustError::File {
        field: field.to_string(),
        path: path.to_owned(),
        reason,
    };
    let meta = std::fs::metadata(path).map_err(|e| bad(e.to_string()))?;
    if !meta.is_file() || meta.len() > MAX_PEM_BYTES {
        return Err(bad(format!("not {what} (not a file of at most 1 MiB)")));
    }
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    if !text.contains(mark) {
        return Err(bad(format!("not {what} (no `{mark}`)")));
    }
    path.to_str()
        .map(|_| ())
        .ok_or_else(|| bad("the path is not UTF-8 (Zenoh takes paths as text)".into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_choice_is_explicit() {
        assert_eq!(
            choose(None, None, None, true, FLAGS),
            Ok(Security::Insecure)
        );
        let e = choose(None, None, None, false, FLAGS).unwrap_err();
        assert!(e.to_string().contains("--insecure"), "{e}");
        let e = choose(Some("a".into()), None, None, false, FLAGS).unwrap_err();
        assert!(e.to_string().contains("all three"), "{e}");
        let e = choose(Some("a".into()), None, None, true, FLAGS).unwrap_err();
        assert!(e.to_string().contains("exclude"), "{e}");
        let e = choose(
            Some("/nonexistent/ca.pem".into()),
            Some("c".into()),
            Some("k".into()),
            false,
            FLAGS,
        )
        .unwrap_err();
        assert!(
            e.to_string().starts_with("--ca: /nonexistent/ca.pem: "),
            "{e}"
        );
    }

    #[test]
    fn endpoints_match_the_security() {
        let tls = Security::Tls(TlsFiles {
            ca: "a".into(),
            cert: "b".into(),
            key: "c".into(),
        });
        assert_eq!(tls.endpoint_problem("quic/127.0.0.1:1"), None);
        assert!(tls.endpoint_problem("tcp/127.0.0.1:1").is_some());
        let e = tls.endpoint_problem("tls/127.0.0.1:1").unwrap();
        assert!(e.contains("zenoh#2557"), "{e}");
        assert_eq!(Security::Insecure.endpoint_problem("tcp/127.0.0.1:1"), None);
        assert!(
            Security::Insecure
                .endpoint_problem("quic/127.0.0.1:1")
                .is_some()
        );
        assert!(tls.endpoint_problem("udp/127.0.0.1:1").is_some());
    }
}
