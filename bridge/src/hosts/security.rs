//! How a hosts file's links are secured: its `[tls]` table (paths
//! relative to the file) or `insecure = true`, unless the command line
//! says otherwise ([`Hosts::secure`]); every endpoint must then fit.

use super::file::HostsFile;
use super::{Hosts, HostsError};
use crate::trust::{FieldNames, Security, TlsFiles};
use scenario::Issue;
use std::path::Path;

/// The `[tls]` table's field names, for messages.
const FIELDS: FieldNames = FieldNames {
    ca: "tls.ca",
    cert: "tls.cert",
    key: "tls.key",
};

/// The security `parsed` (read from `path`) asks for, if any; its
/// problems go to `issues`.
pub(super) fn of_file(
    path: &Path,
    parsed: &HostsFile,
    issues: &mut Vec<Issue>,
) -> Option<Security> {
    let dir = path.parent().unwrap_or(Path::new("."));
    match (&parsed.tls, parsed.insecure) {
        (Some(_), true) => {
            issues.push(issue(
                "insecure",
                "a [tls] table and insecure = true exclude each other".into(),
            ));
            None
        }
        (None, true) => Some(Security::Insecure),
        (None, false) => None,
        (Some(t), false) => {
            let files = TlsFiles {
                ca: dir.join(&t.ca),
                cert: dir.join(&t.cert),
                key: dir.join(&t.key),
            };
            match files.check(FIELDS) {
                Ok(()) => Some(Security::Tls(files)),
                Err(crate::trust::TrustError::File {
                    field,
                    path,
                    reason,
                }) => {
                    issues.push(issue(&field, format!("{}: {reason}", path.display())));
                    None
                }
                Err(e) => {
                    issues.push(issue("tls", e.to_string()));
                    None
                }
            }
        }
    }
}

impl Hosts {
    /// Settles the security: `given` (from the command line) if any, else
    /// the file's; then checks that every endpoint fits it. Neither is an
    /// error saying what to write.
    pub fn secure(mut self, given: Option<Security>) -> Result<Self, HostsError> {
        self.security = Some(self.settled(given)?);
        Ok(self)
    }

    /// The security [`Hosts::secure`] would settle on, checked.
    pub fn settled(&self, given: Option<Security>) -> Result<Security, HostsError> {
        let Some(security) = given.or_else(|| self.security.clone()) else {
            let reason = "no security: add a [tls] table (ca, cert, key: attsync host --gen-certs DIR makes them) \
                          with quic/ endpoints, or insecure = true for plain TCP without authentication \
                          (or give --ca/--cert/--key, or --insecure)";
            return Err(self.invalid(vec![issue("tls", reason.into())]));
        };
        let issues: Vec<Issue> = (self.hosts.iter().enumerate())
            .filter_map(|(h, host)| {
                let reason = security.endpoint_problem(&host.endpoint)?;
                Some(issue(&format!("host[{h}].endpoint"), reason))
            })
            .collect();
        if !issues.is_empty() {
            return Err(self.invalid(issues));
        }
        Ok(security)
    }

    fn invalid(&self, issues: Vec<Issue>) -> HostsError {
        HostsError::Invalid(self.path.clone(), issues)
    }
}

fn issue(field: &str, reason: String) -> Issue {
    Issue {
        field: field.to_owned(),
        reason,
    }
}
