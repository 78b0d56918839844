//! Mutual TLS in the tests across hosts, set up as a lab sets it up
//! (`attsync host --gen-certs`): one test CA per test process, a
//! certificate per daemon naming the addresses it is dialled at, and one
//! for the orchestrator ([`user`]). Everything under
//! `target/<profile>/test-ca/<pid>/` (the directories of processes that
//! are gone are removed when a new one starts).

use crate::workspace::{bin, bin_dir};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};

/// One party's files under mutual TLS.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Identity {
    /// The test CA's certificate.
    pub ca: PathBuf,
    /// The party's certificate.
    pub cert: PathBuf,
    /// The party's key.
    pub key: PathBuf,
}

impl Identity {
    /// `--ca CA --cert CERT --key KEY`.
    #[must_use]
    pub fn flags(&self) -> Vec<String> {
        let s = |p: &Path| p.display().to_string();
        vec![
            "--ca".into(),
            s(&self.ca),
            "--cert".into(),
            s(&self.cert),
            "--key".into(),
            s(&self.key),
        ]
    }

    /// A hosts file's `[tls]` table.
    #[must_use]
    pub fn table(&self) -> String {
        format!(
            "[tls]\nca = {:?}\ncert = {:?}\nkey = {:?}\n\n",
            self.ca, self.cert, self.key
        )
    }
}

/// This process's CA directory (made on first use, with the user's identity).
fn dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let root = bin_dir().join("test-ca");
        remove_stale(&root);
        let d = root.join(std::process::id().to_string());
        let _ = std::fs::remove_dir_all(&d);
        gen_certs(&d, &["tester".to_string()]);
        d
    })
}

/// Removes the CA directories of test processes that are gone.
fn remove_stale(root: &Path) {
    let Ok(rd) = std::fs::read_dir(root) else {
        return;
    };
    for e in rd.filter_map(Result::ok) {
        let name = e.file_name().to_string_lossy().into_owned();
        if !name.parse().is_ok_and(attsync_sched::process::exists) {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

/// `attsync host --gen-certs dir --for …` (serialised: the CA is made once).
fn gen_certs(dir: &Path, subjects: &[String]) {
    static LOCK: Mutex<()> = Mutex::new(());
    let _held = LOCK
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut cmd = Command::new(bin("attsync"));
    cmd.arg("host").arg("--gen-certs").arg(dir);
    for s in subjects {
        cmd.args(["--for", s]);
    }
    let out = cmd.output().expect("attsync host --gen-certs");
    assert!(
        out.status.success(),
        "attsync host --gen-certs: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn identity(dir: &Path, name: &str) -> Identity {
    Identity {
        ca: dir.join("ca.pem"),
        cert: dir.join(format!("{name}.pem")),
        key: dir.join(format!("{name}.key")),
    }
}

/// The orchestrator's identity (signed by this process's test CA).
#[must_use]
pub fn user() -> Identity {
    identity(dir(), "tester")
}

/// A new identity for a daemon named after `name`, dialled at `addresses`
/// (IP addresses or DNS names).
#[must_use]
pub fn host(name: &str, addresses: &[String]) -> Identity {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let unique = format!("{name}-{}", NEXT.fetch_add(1, Ordering::Relaxed));
    let d = dir();
    gen_certs(d, &[format!("{unique}={}", addresses.join(","))]);
    identity(d, &unique)
}

/// An identity signed by another CA (made now in `dir`): one the daemons
/// of [`host`] do not trust.
#[must_use]
pub fn stranger(dir: &Path) -> Identity {
    gen_certs(dir, &["mallory".to_string()]);
    identity(dir, "mallory")
}

/// The address of endpoint `e` (`quic/1.2.3.4:5` → `1.2.3.4`).
#[must_use]
pub fn address_of(e: &str) -> String {
    let rest = e.split_once('/').map_or(e, |(_, r)| r);
    let addr = rest.rsplit_once(':').map_or(rest, |(a, _)| a);
    addr.trim_matches(['[', ']']).to_string()
}
