//! A host's Zenoh endpoint, `quic/<address>:<port>` (mutual TLS),
//! `tcp/<address>:<port>` (insecure) or `tls/…` (refused later, with its
//! reason, by [`crate::trust::Security::endpoint_problem`]): the only shapes a hosts file accepts (Zenoh's locator syntax, no
//! `?metadata` or `#configuration` suffix). Which of the two a file may use
//! is its security's business ([`crate::trust::Security::endpoint_problem`]).

use std::net::{Ipv4Addr, Ipv6Addr};

/// The protocols accepted.
const PROTOCOLS: [&str; 3] = ["quic/", "tcp/", "tls/"];

/// Longest DNS name (RFC 1035), in bytes.
const MAX_NAME_BYTES: usize = 253;

/// Longest DNS label (RFC 1035), in bytes.
const MAX_LABEL_BYTES: usize = 63;

/// Why `endpoint` is not `<protocol>/<address>:<port>`, if it is not.
pub(super) fn problem(endpoint: &str) -> Option<String> {
    let Some(rest) = PROTOCOLS.iter().find_map(|p| endpoint.strip_prefix(p)) else {
        let protocol = endpoint.split_once('/').map_or(endpoint, |(p, _)| p);
        return Some(format!(
            "`{endpoint}` is not a QUIC, TLS or TCP endpoint (`{protocol}`): write quic/<ip-or-name>:<port>, e.g. quic/127.0.0.1:7447"
        ));
    };
    if rest.contains(['?', '#']) {
        return Some(format!(
            "`{endpoint}`: no metadata (`?`) or configuration (`#`) suffix is accepted"
        ));
    }
    let Some((address, port)) = rest.rsplit_once(':') else {
        return Some(format!(
            "`{endpoint}` has no port: write quic/<ip-or-name>:<port>"
        ));
    };
    address_problem(address)
        .or_else(|| port_problem(port))
        .map(|reason| format!("`{endpoint}`: {reason}"))
}

/// Why `port` is not a port 1–65535, if it is not.
fn port_problem(port: &str) -> Option<String> {
    match port.parse::<u16>() {
        Ok(p) if p > 0 => None,
        _ => Some(format!("port `{port}` is not a number from 1 to 65535")),
    }
}

/// Why `address` is neither an IPv4 address, a bracketed IPv6 address nor
/// a DNS name, if it is not.
fn address_problem(address: &str) -> Option<String> {
    if address.is_empty() {
        return Some("the address is empty".into());
    }
    if let Some(v6) = address.strip_prefix('[') {
        return match v6.strip_suffix(']').map(str::parse::<Ipv6Addr>) {
            Some(Ok(_)) => None,
            _ => Some(format!("`{address}` is not an IPv6 address in brackets")),
        };
    }
    let numeric = address.bytes().all(|b| b.is_ascii_digit() || b == b'.');
    if numeric {
        return match address.parse::<Ipv4Addr>() {
            Ok(_) => None,
            Err(_) => Some(format!("`{address}` is not an IPv4 address")),
        };
    }
    name_problem(address)
}

/// Why `name` is not a DNS name (labels of letters, digits and `-`, not at
/// either end), if it is not.
fn name_problem(name: &str) -> Option<String> {
    let label_ok = |l: &str| {
        !l.is_empty()
            && l.len() <= MAX_LABEL_BYTES
            && l.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-')
            && !l.starts_with('-')
            && !l.ends_with('-')
    };
    if name.len() > MAX_NAME_BYTES || !name.split('.').all(label_ok) {
        return Some(format!(
            "`{name}` is not an IP address or a host name (letters, digits, `-` and `.`)"
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::problem;

    #[test]
    fn tls_and_tcp_endpoints_are_accepted() {
        for ok in [
            "quic/127.0.0.1:7447",
            "quic/lab-pc-2.local:7447",
            "tcp/127.0.0.1:7447",
            "tcp/[::1]:1",
            "tcp/lab-pc-2.local:65535",
            "tcp/localhost:7447",
        ] {
            assert_eq!(problem(ok), None, "{ok}");
        }
    }

    #[test]
    fn every_other_shape_is_refused_with_its_reason() {
        for (bad, reason) in [
            (
                "udp/127.0.0.1:7447",
                "not a QUIC, TLS or TCP endpoint (`udp`)",
            ),
            ("127.0.0.1:7447", "not a QUIC, TLS or TCP endpoint"),
            ("tcp/127.0.0.1", "has no port"),
            (
                "tcp/127.0.0.1:0",
                "port `0` is not a number from 1 to 65535",
            ),
            ("tcp/127.0.0.1:65536", "port `65536`"),
            ("tcp/127.0.0.1:x", "port `x`"),
            ("tcp/300.0.0.1:7447", "`300.0.0.1` is not an IPv4 address"),
            ("tcp/[::g]:7447", "not an IPv6 address"),
            ("tcp/a_b:7447", "not an IP address or a host name"),
            ("tcp/-a:7447", "not an IP address or a host name"),
            ("tcp/:7447", "the address is empty"),
            ("tcp/h:7447?prio=1", "no metadata"),
        ] {
            let got = problem(bad).unwrap_or_else(|| panic!("{bad} accepted"));
            assert!(got.contains(reason), "{bad}: {got}");
        }
    }
}
