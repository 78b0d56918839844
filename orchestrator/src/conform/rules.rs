//! The rules `attsync conform` checks (PROTOCOL.md § conformance) and the report.

use std::fmt::Write as _;
use std::path::PathBuf;

/// One rule of PROTOCOL.md.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RuleId {
    /// Refuses a configuration of another protocol version.
    Version,
    /// Opens its ports with attsync's types and limits and reports `Ready`.
    Connects,
    /// One state per exchange, stamped with the due (step, stage), right version and sender.
    InOrder,
    /// Does not advance before it has its inputs (stage by stage).
    WaitsForInputs,
    /// Publishes finite states whose attitude is a rotation.
    ValidStates,
    /// Refuses a non-finite input, keeps its last value and goes on.
    RefusesInvalid,
    /// Samples at step 0, every `sample_every` steps and the last, then `Done`.
    Telemetry,
    /// Exits with status 0 when told to stop.
    Stops,
    /// Leaves no iceoryx2 node and no process behind.
    Clean,
    /// Publishes what the built-in law of its scheme computes from its inputs.
    Law,
}

impl RuleId {
    /// Every rule, in report order.
    pub const ALL: [RuleId; 10] = [
        RuleId::Version,
        RuleId::Connects,
        RuleId::InOrder,
        RuleId::WaitsForInputs,
        RuleId::ValidStates,
        RuleId::RefusesInvalid,
        RuleId::Telemetry,
        RuleId::Stops,
        RuleId::Clean,
        RuleId::Law,
    ];

    /// Short name (as in PROTOCOL.md).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            RuleId::Version => "version",
            RuleId::Connects => "connects",
            RuleId::InOrder => "in-order",
            RuleId::WaitsForInputs => "waits-for-inputs",
            RuleId::ValidStates => "valid-states",
            RuleId::RefusesInvalid => "refuses-invalid",
            RuleId::Telemetry => "telemetry",
            RuleId::Stops => "stops",
            RuleId::Clean => "clean",
            RuleId::Law => "law",
        }
    }

    /// What the rule asks.
    #[must_use]
    pub fn text(self) -> &'static str {
        match self {
            RuleId::Version => "refuses a config of another protocol version (exits non-zero)",
            RuleId::Connects => "opens its ports with attsync's types and limits, reports Ready",
            RuleId::InOrder => "publishes one state per exchange, stamped (n, s) in order",
            RuleId::WaitsForInputs => "waits for every input of a stage before advancing",
            RuleId::ValidStates => "publishes finite states whose attitude is a rotation",
            RuleId::RefusesInvalid => "refuses a NaN input, keeps its last value, goes on",
            RuleId::Telemetry => "reports samples at the due steps, then Done",
            RuleId::Stops => "exits with status 0 when told to stop",
            RuleId::Clean => "leaves no iceoryx2 node and no process behind",
            RuleId::Law => "publishes what the built-in law computes from its inputs",
        }
    }
}

/// A rule's outcome.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Verdict {
    /// The rule holds.
    Pass,
    /// It does not, because…
    Fail(String),
    /// It could not be checked, because… (counts as a failure).
    NotChecked(String),
    /// For information only (does not fail the run): the candidate
    /// deliberately departs from the rule, and by how much.
    Info(String),
}

impl Verdict {
    /// Whether the verdict lets the run pass (`Pass` or `Info`).
    #[must_use]
    pub fn ok(&self) -> bool {
        matches!(self, Verdict::Pass | Verdict::Info(_))
    }
}

/// A rule and its outcome.
#[derive(Debug, Clone)]
pub struct Rule {
    /// Which rule.
    pub id: RuleId,
    /// Outcome.
    pub verdict: Verdict,
}

/// Every rule's outcome.
#[derive(Debug, Clone)]
pub struct Report {
    /// In [`RuleId::ALL`] order.
    pub rules: Vec<Rule>,
    /// The candidate's output.
    pub log: PathBuf,
}

impl Report {
    /// All rules not yet checked.
    #[must_use]
    pub fn new(log: PathBuf) -> Self {
        Self {
            rules: RuleId::ALL
                .iter()
                .map(|&id| Rule {
                    id,
                    verdict: Verdict::NotChecked("not reached".into()),
                })
                .collect(),
            log,
        }
    }

    fn rule(&mut self, id: RuleId) -> &mut Rule {
        self.rules
            .iter_mut()
            .find(|r| r.id == id)
            .expect("every rule is in the report")
    }

    /// Records a pass, unless the rule has already failed.
    pub fn pass(&mut self, id: RuleId) {
        let r = self.rule(id);
        if !matches!(r.verdict, Verdict::Fail(_)) {
            r.verdict = Verdict::Pass;
        }
    }

    /// Records a failure (the first reason is kept).
    pub fn fail(&mut self, id: RuleId, why: impl Into<String>) {
        let r = self.rule(id);
        if !matches!(r.verdict, Verdict::Fail(_)) {
            r.verdict = Verdict::Fail(why.into());
        }
    }

    /// Records a departure for information only, unless already decided
    /// otherwise (a failure is kept).
    pub fn info(&mut self, id: RuleId, why: impl Into<String>) {
        let r = self.rule(id);
        if !matches!(r.verdict, Verdict::Fail(_)) {
            r.verdict = Verdict::Info(why.into());
        }
    }

    /// Marks a rule as not checkable, unless already decided.
    pub fn not_checked(&mut self, id: RuleId, why: impl Into<String>) {
        let r = self.rule(id);
        if matches!(r.verdict, Verdict::NotChecked(_)) {
            r.verdict = Verdict::NotChecked(why.into());
        }
    }

    /// The verdict of `id`.
    #[must_use]
    pub fn verdict(&self, id: RuleId) -> &Verdict {
        &self
            .rules
            .iter()
            .find(|r| r.id == id)
            .expect("present")
            .verdict
    }

    /// Whether every rule passed (or was reported for information only).
    #[must_use]
    pub fn passed(&self) -> bool {
        self.rules.iter().all(|r| r.verdict.ok())
    }

    /// One line per rule.
    #[must_use]
    pub fn table(&self) -> String {
        let mut s = String::new();
        for r in &self.rules {
            let (tag, why) = match &r.verdict {
                Verdict::Pass => ("PASS", String::new()),
                Verdict::Fail(w) => ("FAIL", format!("\n       {w}")),
                Verdict::NotChecked(w) => ("SKIP", format!("\n       not checked: {w}")),
                Verdict::Info(w) => ("INFO", format!("\n       for information: {w}")),
            };
            let _ = writeln!(s, "{tag}  {:<17} {}{why}", r.id.name(), r.id.text());
        }
        let count = |f: fn(&Verdict) -> bool| self.rules.iter().filter(|r| f(&r.verdict)).count();
        let n_pass = count(|v| *v == Verdict::Pass);
        let n_info = count(|v| matches!(v, Verdict::Info(_)));
        let info = match n_info {
            0 => String::new(),
            n => format!(", {n} for information only"),
        };
        // An INFO rule is not judged: it counts in neither figure.
        let _ = write!(
            s,
            "{n_pass}/{} rules pass{info}; the candidate's output: {}",
            self.rules.len() - n_info,
            self.log.display()
        );
        s
    }
}
