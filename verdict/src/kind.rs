//! The five classes of a run.

use std::fmt;

/// What a run's error history says about the run (serialised in kebab-case:
/// `"converged"`, `"converging"`, …).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    /// Below the tolerance over the last envelope block and not growing,
    /// a round-off floor included.
    Converged,
    /// Above the tolerance, the envelope decaying significantly.
    Converging,
    /// Above the tolerance, the envelope flat: an offset or a sustained
    /// oscillation.
    Persistent,
    /// The envelope growing significantly, or a non-finite error.
    Diverging,
    /// Too short to tell, or a trend the window cannot resolve yet.
    Undecided,
}

impl Kind {
    /// Every kind, in declaration order.
    pub const ALL: [Kind; 5] = [
        Kind::Converged,
        Kind::Converging,
        Kind::Persistent,
        Kind::Diverging,
        Kind::Undecided,
    ];

    /// The serialised name: `"converged"`, `"converging"`, `"persistent"`,
    /// `"diverging"` or `"undecided"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Kind::Converged => "converged",
            Kind::Converging => "converging",
            Kind::Persistent => "persistent",
            Kind::Diverging => "diverging",
            Kind::Undecided => "undecided",
        }
    }

    /// Whether running longer cannot change the verdict: every kind but
    /// [`Kind::Converging`] and [`Kind::Undecided`].
    #[must_use]
    pub fn is_final(self) -> bool {
        !matches!(self, Kind::Converging | Kind::Undecided)
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::Kind;

    #[test]
    fn names_and_finality() {
        let names: Vec<_> = Kind::ALL.iter().map(|k| k.name()).collect();
        assert_eq!(
            names,
            [
                "converged",
                "converging",
                "persistent",
                "diverging",
                "undecided"
            ]
        );
        let fin: Vec<_> = Kind::ALL.iter().map(|k| k.is_final()).collect();
        assert_eq!(fin, [true, false, true, true, false]);
        assert_eq!(Kind::Persistent.to_string(), "persistent");
    }
}
