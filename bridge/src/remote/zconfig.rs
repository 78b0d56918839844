//! The Zenoh configuration of every session attsync opens, always explicit:
//! peer mode, the given listen and connect endpoints only (no default
//! listener), multicast scouting and gossip off, a short lease so that
//! a lost peer is noticed within [`LEASE_MS`], and its [`Security`]:
//! mutual TLS (every link shows a certificate of the lab's CA, the dialled
//! side's naming the address dialled), or plain TCP when `--insecure`.

use crate::trust::Security;
use thiserror::Error;

/// How long a silent link lives, ms (Zenoh's default is 10 000). A
/// daemon killed outright closes its sockets and is noticed at once; a
/// machine that vanishes is noticed after this.
pub const LEASE_MS: u64 = 2000;

/// An endpoint Zenoh does not accept, or a session that cannot open.
#[derive(Debug, Error)]
pub enum ConfigError {
    /// An endpoint is not in Zenoh's syntax, or not of the security's protocol.
    #[error("{flag}: {reason}")]
    Endpoint {
        /// Where it came from (`--listen`, a host's `endpoint`…).
        flag: String,
        /// The text.
        endpoint: String,
        /// Why not (naming the endpoint).
        reason: String,
    },
    /// The session did not open (a port taken, …).
    #[error("zenoh: cannot open the session: {0}")]
    Open(String),
}

/// Checks `endpoint` (from `flag`): Zenoh's syntax, and the protocol of
/// `security` (`quic/`, or `tcp/` when insecure).
pub fn check_endpoint(flag: &str, endpoint: &str, security: &Security) -> Result<(), ConfigError> {
    let bad = |reason: String| ConfigError::Endpoint {
        flag: flag.to_string(),
        endpoint: endpoint.to_string(),
        reason,
    };
    let _: zenoh::config::EndPoint = endpoint.parse().map_err(|e| {
        bad(format!(
            "`{endpoint}` is not an endpoint (expected e.g. quic/127.0.0.1:7447): {e}"
        ))
    })?;
    match security.endpoint_problem(endpoint) {
        Some(reason) => Err(bad(reason)),
        None => Ok(()),
    }
}

/// The configuration of a peer that listens on `listen` and dials
/// `connect`, secured by `security`.
pub fn peer(
    listen: &[String],
    connect: &[String],
    security: &Security,
) -> Result<zenoh::Config, ConfigError> {
    let mut c = zenoh::Config::default();
    let list = |v: &[String]| serde_json::to_string(v).expect("strings serialise");
    let settings = [
        ("mode", "\"peer\"".to_string()),
        ("listen/endpoints", list(listen)),
        ("connect/endpoints", list(connect)),
        // Dial in the background, again and again (a host started before
        // the host it dials, a host restarted), every 100 ms to 1 s.
        ("connect/timeout_ms", "-1".into()),
        ("connect/exit_on_failure", "false".into()),
        (
            "connect/retry",
            r#"{"period_init_ms": 100, "period_max_ms": 1000, "period_increase_factor": 2}"#.into(),
        ),
        ("scouting/multicast/enabled", "false".into()),
        ("scouting/gossip/enabled", "false".into()),
        ("transport/link/tx/lease", LEASE_MS.to_string()),
        // Write each message from the calling thread, no TX task: ~20 %
        // off an exchange across a cut (BENCHMARKS.md, session 11). It does
        // not fragment, so larger payloads go in `pieces`; it needs QoS off,
        // and every session of a run must use it (a peer with the default
        // transport cannot open a link with it).
        ("transport/unicast/lowlatency", "true".into()),
        ("transport/unicast/qos/enabled", "false".into()),
    ];
    for (key, value) in settings.into_iter().chain(tls(security)) {
        c.insert_json5(key, &value)
            .map_err(|e| ConfigError::Open(format!("{key} = {value}: {e}")))?;
    }
    Ok(c)
}

/// Zenoh's TLS settings for `security`: the lab's CA, this party's
/// certificate and key on both ends of a link, client certificates
/// required (mutual TLS), the dialled side's name checked.
fn tls(security: &Security) -> Vec<(&'static str, String)> {
    let Security::Tls(files) = security else {
        return Vec::new();
    };
    let path = |p: &std::path::Path| serde_json::to_string(&p.to_string_lossy()).expect("text");
    vec![
        ("transport/link/tls/root_ca_certificate", path(&files.ca)),
        ("transport/link/tls/listen_certificate", path(&files.cert)),
        ("transport/link/tls/listen_private_key", path(&files.key)),
        ("transport/link/tls/connect_certificate", path(&files.cert)),
        ("transport/link/tls/connect_private_key", path(&files.key)),
        ("transport/link/tls/enable_mtls", "true".into()),
        ("transport/link/tls/verify_name_on_connect", "true".into()),
    ]
}

/// Opens a peer session ([`peer`]).
pub fn open(
    listen: &[String],
    connect: &[String],
    security: &Security,
) -> Result<zenoh::Session, ConfigError> {
    use zenoh::Wait;
    zenoh::open(peer(listen, connect, security)?)
        .wait()
        .map_err(|e| ConfigError::Open(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tls() -> Security {
        Security::Tls(crate::trust::TlsFiles {
            ca: "/lab/ca.pem".into(),
            cert: "/lab/a.pem".into(),
            key: "/lab/a.key".into(),
        })
    }

    #[test]
    fn endpoints_are_checked_naming_the_flag() {
        let insecure = Security::Insecure;
        assert!(check_endpoint("--listen", "tcp/127.0.0.1:7447", &insecure).is_ok());
        assert!(check_endpoint("--listen", "quic/127.0.0.1:7447", &tls()).is_ok());
        let e = check_endpoint("--listen", "127.0.0.1:7447", &insecure).unwrap_err();
        assert!(
            e.to_string().starts_with("--listen: `127.0.0.1:7447`"),
            "{e}"
        );
        let e = check_endpoint("--connect", "udp/127.0.0.1:7447", &insecure).unwrap_err();
        assert!(e.to_string().contains("only quic/"), "{e}");
        let e = check_endpoint("--listen", "tcp/127.0.0.1:7447", &tls()).unwrap_err();
        assert!(e.to_string().contains("--insecure"), "{e}");
    }

    #[test]
    fn tls_is_mutual_and_checks_names() {
        let c = peer(&["quic/127.0.0.1:0".into()], &[], &tls()).expect("valid");
        let json = |k: &str| c.get_json(k).expect(k);
        assert_eq!(json("transport/link/tls/enable_mtls"), "true");
        assert_eq!(json("transport/link/tls/verify_name_on_connect"), "true");
        assert_eq!(
            json("transport/link/tls/root_ca_certificate"),
            r#""/lab/ca.pem""#
        );
        assert_eq!(
            json("transport/link/tls/connect_private_key"),
            r#""/lab/a.key""#
        );
    }

    #[test]
    fn the_configuration_is_explicit() {
        let c = peer(&["tcp/127.0.0.1:0".into()], &[], &Security::Insecure).expect("valid");
        let json = |k: &str| c.get_json(k).expect(k);
        assert_eq!(json("scouting/multicast/enabled"), "false");
        assert_eq!(json("scouting/gossip/enabled"), "false");
        assert_eq!(json("listen/endpoints"), r#"["tcp/127.0.0.1:0"]"#);
        assert_eq!(json("connect/endpoints"), "[]");
    }
}
