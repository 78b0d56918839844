//! `attsync host --gen-certs DIR --for NAME[=ADDR,…]…`: a lab's CA and a
//! certificate per host and per user, so that mutual TLS is set up in a
//! minute. ECDSA P-256 keys; every certificate serves both ends of a link
//! (a daemon listens and dials; an orchestrator dials).
//!
//! `DIR/ca.pem` and `DIR/ca.key` are made once and reused, so hosts and
//! users can be added later; `DIR/NAME.pem` and `DIR/NAME.key` per
//! subject, never overwritten. Keys are written with mode 0600. Copy
//! `ca.pem` to every machine, and each `NAME.pem`/`NAME.key` only to its
//! own; keep `ca.key` off the network.

use super::TrustError;
use rcgen::{
    BasicConstraints, CertificateParams, DnType, ExtendedKeyUsagePurpose, IsCa, Issuer, KeyPair,
    KeyUsagePurpose,
};
use std::io::Write;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The CA's common name.
const CA_NAME: &str = "attsync lab CA";
/// How long a certificate is valid: from 1 January of this year, for
/// this many years.
const VALID_YEARS: i32 = 5;

/// Someone to issue a certificate for: a host (with the addresses others
/// dial it at) or a user (no address).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Subject {
    /// Its name (the files' stem and the certificate's common name).
    pub name: String,
    /// IP addresses or DNS names it is dialled at (`quic/<address>:port`).
    pub addresses: Vec<String>,
}

/// A `--for` that is not `NAME` or `NAME=ADDR[,ADDR…]` (the name given).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{0}` is not a name (letters, digits, `-`, `_`): write NAME or NAME=ADDR[,ADDR…]")]
pub struct BadSubject(pub String);

impl FromStr for Subject {
    type Err = BadSubject;

    /// `NAME` or `NAME=ADDR[,ADDR…]`.
    fn from_str(s: &str) -> Result<Self, BadSubject> {
        let (name, addrs) = s.split_once('=').unwrap_or((s, ""));
        let ok = !name.is_empty()
            && (name.chars()).all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
        if !ok {
            return Err(BadSubject(name.to_string()));
        }
        let addresses = (addrs.split(',').filter(|a| !a.is_empty()))
            .map(str::to_string)
            .collect();
        Ok(Self {
            name: name.to_string(),
            addresses,
        })
    }
}

/// What `--gen-certs` made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Issued {
    /// The CA was made now (else an existing one was used).
    pub new_ca: bool,
    /// The certificate and key files written, in order.
    pub files: Vec<PathBuf>,
}

/// Makes (or reuses) the CA in `dir`, then a certificate and key per subject.
pub fn generate(dir: &Path, subjects: &[Subject]) -> Result<Issued, TrustError> {
    let io = |p: &Path, e: std::io::Error| TrustError::File {
        field: "--gen-certs".into(),
        path: p.to_owned(),
        reason: e.to_string(),
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    for s in subjects {
        let cert = dir.join(format!("{}.pem", s.name));
        if cert.exists() || s.name == "ca" {
            return Err(TrustError::Certs(format!(
                "{}: exists (remove it, and its key, to issue it again)",
                cert.display()
            )));
        }
    }
    let (ca_key, new_ca) = ca(dir)?;
    let issuer = Issuer::new(ca_params()?, &ca_key);
    let mut files = Vec::new();
    for s in subjects {
        let key = KeyPair::generate().map_err(certs_error)?;
        let cert = leaf_params(s)?
            .signed_by(&key, &issuer)
            .map_err(certs_error)?;
        let (c, k) = (
            dir.join(format!("{}.pem", s.name)),
            dir.join(format!("{}.key", s.name)),
        );
        write_new(&c, &cert.pem(), 0o644).map_err(|e| io(&c, e))?;
        write_new(&k, &key.serialize_pem(), 0o600).map_err(|e| io(&k, e))?;
        files.extend([c, k]);
    }
    Ok(Issued { new_ca, files })
}

fn certs_error(e: rcgen::Error) -> TrustError {
    TrustError::Certs(e.to_string())
}

/// The CA's key: read from `dir/ca.key`, or made with `dir/ca.pem` now.
fn ca(dir: &Path) -> Result<(KeyPair, bool), TrustError> {
    let (cert, key) = (dir.join("ca.pem"), dir.join("ca.key"));
    let file_error = |p: &Path, e: String| TrustError::File {
        field: "--gen-certs".into(),
        path: p.to_owned(),
        reason: e,
    };
    if key.exists() {
        let pem = std::fs::read_to_string(&key).map_err(|e| file_error(&key, e.to_string()))?;
        let k = KeyPair::from_pem(&pem).map_err(|e| file_error(&key, e.to_string()))?;
        return Ok((k, false));
    }
    let k = KeyPair::generate().map_err(certs_error)?;
    let c = ca_params()?.self_signed(&k).map_err(certs_error)?;
    write_new(&key, &k.serialize_pem(), 0o600).map_err(|e| file_error(&key, e.to_string()))?;
    write_new(&cert, &c.pem(), 0o644).map_err(|e| file_error(&cert, e.to_string()))?;
    Ok((k, true))
}

/// The CA's parameters (the same each time, so that an existing CA's key
/// issues certificates that chain to its certificate).
fn ca_params() -> Result<CertificateParams, TrustError> {
    let mut p = CertificateParams::new(Vec::<String>::new()).map_err(certs_error)?;
    p.distinguished_name.push(DnType::CommonName, CA_NAME);
    p.is_ca = IsCa::Ca(BasicConstraints::Constrained(0));
    p.key_usages = vec![KeyUsagePurpose::KeyCertSign, KeyUsagePurpose::CrlSign];
    validity(&mut p);
    Ok(p)
}

/// A host's or user's parameters: its addresses and name as alternative
/// names, usable by a server and a client.
fn leaf_params(s: &Subject) -> Result<CertificateParams, TrustError> {
    let mut names = s.addresses.clone();
    names.push(s.name.clone());
    let mut p =
        CertificateParams::new(names).map_err(|e| TrustError::Certs(format!("{}: {e}", s.name)))?;
    p.distinguished_name
        .push(DnType::CommonName, s.name.as_str());
    p.key_usages = vec![KeyUsagePurpose::DigitalSignature];
    p.extended_key_usages = vec![
        ExtendedKeyUsagePurpose::ServerAuth,
        ExtendedKeyUsagePurpose::ClientAuth,
    ];
    validity(&mut p);
    Ok(p)
}

/// From 1 January of this year, for [`VALID_YEARS`].
fn validity(p: &mut CertificateParams) {
    /// Seconds in a mean Gregorian year.
    const YEAR_S: u64 = 31_556_952;
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let year = 1970 + i32::try_from(now / YEAR_S).unwrap_or(0);
    p.not_before = rcgen::date_time_ymd(year, 1, 1);
    p.not_after = rcgen::date_time_ymd(year + VALID_YEARS, 1, 1);
}

/// Writes a new file `path` (never over an existing one) with `mode`.
fn write_new(path: &Path, text: &str, mode: u32) -> std::io::Result<()> {
    let mut f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(mode)
        .open(path)?;
    f.write_all(text.as_bytes())?;
    f.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subjects_parse() {
        let s: Subject = "lab-a=10.0.0.2,lab-a.local".parse().unwrap();
        assert_eq!(s.name, "lab-a");
        assert_eq!(s.addresses, ["10.0.0.2", "lab-a.local"]);
        assert!("alice".parse::<Subject>().unwrap().addresses.is_empty());
        assert!("a/b=1.2.3.4".parse::<Subject>().is_err());
        assert!("".parse::<Subject>().is_err());
    }

    #[test]
    fn a_ca_is_made_once_and_certificates_are_never_overwritten() {
        let dir = std::env::temp_dir().join(format!("attsync-certs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let a: Subject = "a=127.0.0.1".parse().unwrap();
        let issued = generate(&dir, std::slice::from_ref(&a)).unwrap();
        assert!(issued.new_ca);
        assert_eq!(issued.files.len(), 2);
        let ca = std::fs::read(dir.join("ca.pem")).unwrap();
        let b: Subject = "b".parse().unwrap();
        assert!(!generate(&dir, &[b]).unwrap().new_ca);
        assert_eq!(
            std::fs::read(dir.join("ca.pem")).unwrap(),
            ca,
            "the CA is kept"
        );
        assert!(generate(&dir, &[a]).is_err(), "a is never overwritten");
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(dir.join("a.key"))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o077, 0, "a key is private: {mode:o}");
        let files = super::super::TlsFiles {
            ca: dir.join("ca.pem"),
            cert: dir.join("b.pem"),
            key: dir.join("b.key"),
        };
        assert_eq!(files.check(super::super::FLAGS), Ok(()));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
