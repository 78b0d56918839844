//! Every way a scenario can break the paper's assumptions is caught before
//! anything runs, and reported with the file, the field and the reason.
//!
//! The paper (docs/paper.md) assumes:
//! - Assumption 1: the followers' graph is undirected and acyclic (a forest),
//!   and every agent is reachable from the leader through some leader link;
//! - every gain matrix `A` (`A_i0`, `A_ij`, `Āᵢ`) is symmetric positive
//!   definite with three distinct eigenvalues; inertias `Jᵢ` are SPD;
//! - the leader generator `P` (eq. `leader`) has simple, non-zero eigenvalues
//!   on the imaginary axis and all others with negative real part;
//! - scheme 1 needs the observer gains `k_R, k_ω, k_σ`, and every agent needs
//!   its observer's initial state and `Āᵢ`; Theorem 1's gain condition
//!   (Appendix D, `F ≻ 0`) is sufficient only, so its failure is a warning.
//!
//! Each test mutates [`BASE`] (a valid three-agent path 1–2–3, leader link to
//! agent 1, scheme 1 with the paper's gains and `P`) through `--set`
//! overrides or text edits, and checks the `Issue` (field and reason) and the
//! error's `Display` (`x.toml: field: reason`, one line per issue).

use attsync::scenario::{Issue, Loaded, ScenarioError, load, load_str};
use nalgebra::Matrix3;
use std::path::Path;

/// The file name used in messages.
const FILE: &str = "x.toml";

/// A valid scheme-1 scenario: agents 1–2–3 on a path, the leader talks to 1.
/// Values from the paper's experiment (agents 1–3). Every `[[...]]` array
/// ends the file in the order agent, leader_link, edge, so that blocks can be
/// appended.
const BASE: &str = r#"
name = "base"

[simulation]
dt = 0.001
duration = 1.0
coupling = "continuous"

[output]
sample_period = 0.01

[scheme]
kind = "observer-time-varying"
observer = { k_r = 9.0, k_omega = 14.0, k_sigma = 12.0 }
control = { k_r = 8.0, k_omega = 13.0 }

[leader]
reference = "time-varying"
p = [[-1.0, 0.0, 0.0], [0.0, 0.0, -0.7071067811865475], [0.0, 0.7071067811865476, 0.0]]
attitude = { axis = [1.0, 4.0, 2.0], angle_pi = 0.8 }
omega = [1.0, 2.0, 0.0]
sigma = [1.0, 0.0, 0.0]

[[agent]]
id = 1
inertia = [0.1, 0.3, 0.2]
attitude = { axis = [1.0, 1.0, 0.0], angle_pi = 0.1 }
omega = [1.5, 1.0, 2.0]
control_gain = [11.0, 12.0, 13.0]
observer = { attitude = { axis = [1.0, 1.0, 0.0], angle_pi = -0.1 }, omega = [1.0, 1.5, 2.0], sigma = [2.0, 1.5, 1.0] }

[[agent]]
id = 2
inertia = [0.2, 0.4, 0.4]
attitude = { axis = [1.0, 1.0, 0.0], angle_pi = 0.2 }
omega = [2.5, 2.0, 3.0]
control_gain = [12.0, 13.0, 14.0]
observer = { attitude = { axis = [1.0, 1.0, 0.0], angle_pi = -0.2 }, omega = [2.0, 2.5, 3.0], sigma = [3.0, 2.5, 2.0] }

[[agent]]
id = 3
inertia = [0.3, 0.5, 0.6]
attitude = { axis = [1.0, 1.0, 0.0], angle_pi = 0.3 }
omega = [3.5, 3.0, 4.0]
control_gain = [13.0, 14.0, 15.0]
observer = { attitude = { axis = [1.0, 1.0, 0.0], angle_pi = -0.3 }, omega = [3.0, 3.5, 4.0], sigma = [4.0, 3.5, 3.0] }

[[leader_link]]
agent = 1
gain = [15.0, 16.0, 17.0]

[[edge]]
agents = [1, 2]
gain = [12.0, 13.0, 14.0]

[[edge]]
agents = [2, 3]
gain = [13.0, 14.0, 15.0]
"#;

/// A fourth agent, valid for scheme 1, attached to nothing.
const AGENT_4: &str = r#"
[[agent]]
id = 4
inertia = [0.4, 0.6, 0.8]
attitude = { axis = [1.0, 1.0, 0.0], angle_pi = 0.4 }
omega = [4.5, 4.0, 5.0]
control_gain = [14.0, 15.0, 16.0]
observer = { attitude = { axis = [1.0, 1.0, 0.0], angle_pi = -0.4 }, omega = [4.0, 4.5, 5.0], sigma = [5.0, 4.5, 4.0] }
"#;

fn try_load(text: &str, sets: &[&str]) -> Result<Loaded, ScenarioError> {
    let sets: Vec<String> = sets.iter().map(|s| (*s).to_string()).collect();
    load_str(Path::new(FILE), text, &sets)
}

#[track_caller]
fn valid(text: &str, sets: &[&str]) -> Loaded {
    try_load(text, sets).unwrap_or_else(|e| panic!("expected a valid scenario, got:\n{e}"))
}

/// The issues of an `Invalid` error, and its `Display`.
#[track_caller]
fn invalid(text: &str, sets: &[&str]) -> (Vec<Issue>, String) {
    match try_load(text, sets) {
        Ok(_) => panic!("expected ScenarioError::Invalid, but the scenario loaded"),
        Err(e) => {
            let msg = e.to_string();
            match e {
                ScenarioError::Invalid { file, issues } => {
                    assert_eq!(file, Path::new(FILE));
                    assert!(!issues.is_empty(), "Invalid with no issues");
                    assert_eq!(
                        msg.lines().count(),
                        issues.len(),
                        "one line per issue:\n{msg}"
                    );
                    (issues, msg)
                }
                other => panic!("expected ScenarioError::Invalid, got {other:?}"),
            }
        }
    }
}

/// Asserts that an issue on `field` whose reason contains `reason` is
/// reported, and that the error's Display shows it as `x.toml: field: reason`.
#[track_caller]
fn expect_issue(text: &str, sets: &[&str], field: &str, reason: &str) -> Vec<Issue> {
    let (issues, msg) = invalid(text, sets);
    let hit = issues
        .iter()
        .find(|i| i.field == field && i.reason.contains(reason))
        .unwrap_or_else(|| panic!("no issue on `{field}` containing `{reason}`; got:\n{msg}"));
    let line = format!("{FILE}: {field}: {}", hit.reason);
    assert!(
        msg.lines().any(|l| l == line),
        "Display lacks `{line}`:\n{msg}"
    );
    issues
}

/// As [`expect_issue`], and that it is the only issue.
#[track_caller]
fn expect_only_issue(text: &str, sets: &[&str], field: &str, reason: &str) {
    let issues = expect_issue(text, sets, field, reason);
    assert_eq!(issues.len(), 1, "expected one issue, got {issues:#?}");
}

/// The message of a `Parse` error, after checking it names the file.
#[track_caller]
fn parse_error(text: &str, sets: &[&str]) -> String {
    match try_load(text, sets) {
        Err(e @ ScenarioError::Parse { .. }) => {
            let msg = e.to_string();
            assert!(msg.starts_with(&format!("{FILE}: ")), "{msg}");
            msg
        }
        Err(e) => panic!("expected ScenarioError::Parse, got {e:?}"),
        Ok(_) => panic!("expected ScenarioError::Parse, but the scenario loaded"),
    }
}

/// `text` with the single occurrence of `from` replaced by `to`.
#[track_caller]
fn edit(text: &str, from: &str, to: &str) -> String {
    assert_eq!(
        text.matches(from).count(),
        1,
        "`{from}` must occur exactly once"
    );
    text.replacen(from, to, 1)
}

/// `text` without the single line that contains `needle`.
#[track_caller]
fn without_line(text: &str, needle: &str) -> String {
    let hits = text.lines().filter(|l| l.contains(needle)).count();
    assert_eq!(hits, 1, "`{needle}` must be on exactly one line");
    text.lines()
        .filter(|l| !l.contains(needle))
        .map(|l| format!("{l}\n"))
        .collect()
}

fn append(extra: &str) -> String {
    format!("{BASE}{extra}")
}

fn edge(a: u32, b: u32) -> String {
    format!("\n[[edge]]\nagents = [{a}, {b}]\ngain = [20.0, 21.0, 22.0]\n")
}

fn leader_link(agent: u32) -> String {
    format!("\n[[leader_link]]\nagent = {agent}\ngain = [20.0, 21.0, 22.0]\n")
}

// ---------------------------------------------------------------- baseline

#[test]
fn base_scenario_is_valid_without_warnings() {
    let l = valid(BASE, &[]);
    let r = &l.resolved;
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    assert_eq!(r.edges, vec![(1, 2), (2, 3)]);
    assert_eq!(r.leader_links, vec![1]);
    assert_eq!(r.network.agents.len(), 3);
    assert_eq!(r.network.steps, 1000);
    assert_eq!(r.network.sample_every, 10);
    assert_eq!(l.name(), "base");
    // Ξ + LLᵀ of the path with the leader at one end is positive definite.
    assert_eq!(r.spectrum.len(), 3);
    assert!(r.spectrum[0] > 0.0, "{:?}", r.spectrum);
}

#[test]
fn shipped_scenarios_are_valid_without_warnings() {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios"));
    let files = [
        "paper/timevarying.toml",
        "paper/constant-observer.toml",
        "paper/constant-observerless.toml",
        "paper-network-oscillating-reference.toml",
    ];
    for f in files {
        let l = load(&dir.join(f), &[]).unwrap_or_else(|e| panic!("{f}:\n{e}"));
        assert!(
            l.resolved.warnings.is_empty(),
            "{f}: {:?}",
            l.resolved.warnings
        );
        assert_eq!(l.resolved.network.agents.len(), 7, "{f}");
    }
}

// ------------------------------------------------------------------ graph

#[test]
fn follower_cycle_is_rejected() {
    // 1–2–3 plus 1–3 closes a triangle.
    expect_only_issue(
        &append(&edge(1, 3)),
        &[],
        "edge[2].agents",
        "closes a cycle",
    );
    let (issues, _) = invalid(&append(&edge(3, 1)), &[]);
    assert!(issues[0].reason.contains("forest"), "{issues:?}");
}

#[test]
fn agent_unreachable_from_leader_is_rejected() {
    expect_only_issue(
        &append(AGENT_4),
        &[],
        "agent[3]",
        "agent 4 is not reachable from the leader",
    );
    // Cutting the path: agents 2 and 3 form a component without a leader link.
    let cut = edit(BASE, "agents = [1, 2]", "agents = [3, 4]");
    let text = format!("{cut}{AGENT_4}");
    let issues = expect_issue(&text, &[], "agent[1]", "agent 2 is not reachable");
    expect_issue(&text, &[], "agent[2]", "agent 3 is not reachable");
    expect_issue(&text, &[], "agent[3]", "agent 4 is not reachable");
    assert_eq!(issues.len(), 3, "{issues:#?}");
}

#[test]
fn missing_leader_link_is_rejected() {
    let text = without_line(
        &without_line(BASE, "agent = 1"),
        "gain = [15.0, 16.0, 17.0]",
    );
    let text = edit(&text, "[[leader_link]]\n", "");
    // Only the one clear message, not one "unreachable" per agent.
    expect_only_issue(&text, &[], "leader_link", "no agent hears the leader");
}

#[test]
fn self_loop_is_rejected() {
    expect_only_issue(&append(&edge(3, 3)), &[], "edge[2].agents", "self-loop 3–3");
}

#[test]
fn duplicate_edge_is_rejected_in_either_order() {
    expect_only_issue(
        &append(&edge(1, 2)),
        &[],
        "edge[2].agents",
        "duplicate edge 1–2 (also edge[0])",
    );
    expect_only_issue(
        &append(&edge(2, 1)),
        &[],
        "edge[2].agents",
        "duplicate edge 1–2 (also edge[0])",
    );
    expect_only_issue(
        &append(&edge(3, 2)),
        &[],
        "edge[2].agents",
        "duplicate edge 2–3 (also edge[1])",
    );
}

#[test]
fn unknown_agent_in_edge_is_rejected() {
    expect_only_issue(
        &append(&edge(3, 9)),
        &[],
        "edge[2].agents",
        "unknown agent id 9",
    );
    // Id 0 is the leader: the message says how to link it.
    expect_only_issue(
        &append(&edge(0, 3)),
        &[],
        "edge[2].agents",
        "[[leader_link]]",
    );
}

#[test]
fn unknown_agent_in_leader_link_is_rejected() {
    expect_only_issue(
        &append(&leader_link(9)),
        &[],
        "leader_link[1].agent",
        "unknown agent id 9",
    );
    expect_only_issue(
        &append(&leader_link(0)),
        &[],
        "leader_link[1].agent",
        "unknown agent id 0",
    );
}

#[test]
fn duplicate_leader_link_is_rejected() {
    expect_only_issue(
        &append(&leader_link(1)),
        &[],
        "leader_link[1].agent",
        "duplicate leader link to agent 1 (also leader_link[0])",
    );
    // A second link to another agent is fine.
    let l = valid(&append(&leader_link(3)), &[]);
    assert_eq!(l.resolved.leader_links, vec![1, 3]);
}

#[test]
fn duplicate_agent_id_is_rejected() {
    expect_issue(
        BASE,
        &["agent[2].id=2"],
        "agent[2].id",
        "duplicate id 2 (also agent[1])",
    );
}

#[test]
fn agent_id_zero_is_rejected() {
    expect_issue(
        BASE,
        &["agent[2].id=0"],
        "agent[2].id",
        "must be ≥ 1 (id 0 is the leader)",
    );
}

// ---------------------------------------------------------- gain matrices

#[test]
fn gain_matrix_not_symmetric_is_rejected() {
    let rows = "[[12.0, 1.0, 0.0], [0.0, 13.0, 0.0], [0.0, 0.0, 14.0]]";
    expect_only_issue(
        BASE,
        &[&format!("edge[0].gain={rows}")],
        "edge[0].gain",
        "a gain matrix A must be symmetric positive definite",
    );
    expect_only_issue(
        BASE,
        &[&format!("leader_link[0].gain={rows}")],
        "leader_link[0].gain",
        "symmetric positive definite",
    );
    // A symmetric non-diagonal matrix with distinct eigenvalues is accepted.
    valid(
        BASE,
        &["edge[0].gain=[[12.0, 1.0, 0.0], [1.0, 13.0, 0.0], [0.0, 0.0, 15.0]]"],
    );
}

#[test]
fn gain_matrix_not_positive_definite_is_rejected() {
    expect_only_issue(
        BASE,
        &["leader_link[0].gain=[-1.0, 2.0, 3.0]"],
        "leader_link[0].gain",
        "symmetric positive definite",
    );
    // Symmetric, with an eigenvalue 0: [[1, 1], [1, 1]] ⊕ 2.
    expect_only_issue(
        BASE,
        &["edge[1].gain=[[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 2.0]]"],
        "edge[1].gain",
        "symmetric positive definite",
    );
}

#[test]
fn gain_matrix_with_repeated_eigenvalue_is_rejected() {
    expect_only_issue(
        BASE,
        &["edge[1].gain=[10.0, 10.0, 12.0]"],
        "edge[1].gain",
        "three distinct eigenvalues",
    );
    // Not diagonal: eigenvalues 10, 12, 12.
    expect_only_issue(
        BASE,
        &["leader_link[0].gain=[[11.0, 1.0, 0.0], [1.0, 11.0, 0.0], [0.0, 0.0, 12.0]]"],
        "leader_link[0].gain",
        "three distinct eigenvalues",
    );
}

#[test]
fn control_gain_a_bar_must_be_a_paper_gain_matrix() {
    expect_only_issue(
        BASE,
        &["agent[0].control_gain=[1.0, 1.0, 1.0]"],
        "agent[0].control_gain",
        "three distinct eigenvalues",
    );
    expect_only_issue(
        BASE,
        &["agent[1].control_gain=[0.0, 1.0, 2.0]"],
        "agent[1].control_gain",
        "symmetric positive definite",
    );
}

#[test]
fn inertia_must_be_spd() {
    expect_only_issue(
        BASE,
        &["agent[1].inertia=[0.1, -0.3, 0.2]"],
        "agent[1].inertia",
        "the inertia J must be symmetric positive definite",
    );
    expect_only_issue(
        BASE,
        &["agent[2].inertia=[[0.3, 0.1, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.6]]"],
        "agent[2].inertia",
        "the inertia J must be symmetric positive definite",
    );
    // Repeated principal moments are physical (an axisymmetric body).
    valid(BASE, &["agent[0].inertia=[0.2, 0.2, 0.2]"]);
}

// -------------------------------------------------------------- leader P

#[test]
fn p_with_positive_real_eigenvalue_is_rejected() {
    expect_only_issue(
        BASE,
        &["leader.p=[[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]"],
        "leader.p",
        "violates the paper's condition on P",
    );
}

#[test]
fn p_with_zero_eigenvalue_is_rejected() {
    expect_only_issue(
        BASE,
        &["leader.p=[[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]"],
        "leader.p",
        "violates the paper's condition on P",
    );
    // A single zero eigenvalue next to the paper's oscillating pair.
    expect_only_issue(
        BASE,
        &[
            "leader.p=[[0.0, 0.0, 0.0], [0.0, 0.0, -0.7071067811865475], [0.0, 0.7071067811865476, 0.0]]",
        ],
        "leader.p",
        "violates the paper's condition on P",
    );
}

#[test]
fn p_is_required_by_scheme_1() {
    let text = without_line(BASE, "p = [[");
    expect_only_issue(&text, &[], "leader.p", "is required");
}

// ---------------------------------------------------- non-finite numbers

#[test]
fn non_finite_numbers_are_rejected() {
    let cases: &[(&str, &str, &str)] = &[
        ("agent[0].omega=[nan, 0.0, 0.0]", "agent[0].omega", "finite"),
        ("agent[1].omega=[0.0, inf, 0.0]", "agent[1].omega", "finite"),
        ("leader.omega=[0.0, 0.0, -inf]", "leader.omega", "finite"),
        ("leader.sigma=[nan, 0.0, 0.0]", "leader.sigma", "finite"),
        (
            "agent[0].inertia=[inf, 0.3, 0.2]",
            "agent[0].inertia",
            "must hold finite numbers",
        ),
        (
            "agent[0].inertia=[[nan, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, 0.2]]",
            "agent[0].inertia",
            "must hold finite numbers",
        ),
        (
            "edge[0].gain=[nan, 13.0, 14.0]",
            "edge[0].gain",
            "must hold finite numbers",
        ),
        (
            "leader_link[0].gain=[15.0, inf, 17.0]",
            "leader_link[0].gain",
            "must hold finite numbers",
        ),
        (
            "agent[2].control_gain=[13.0, 14.0, nan]",
            "agent[2].control_gain",
            "must hold finite numbers",
        ),
        (
            "leader.p=[[nan, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]",
            "leader.p",
            "must hold finite numbers",
        ),
        (
            "simulation.dt=nan",
            "simulation.dt",
            "must be a finite number",
        ),
        (
            "simulation.dt=inf",
            "simulation.dt",
            "must be a finite number",
        ),
        (
            "simulation.duration=inf",
            "simulation.duration",
            "must be a finite number",
        ),
        (
            "output.sample_period=nan",
            "output.sample_period",
            "must be a finite number",
        ),
        (
            "scheme.control.k_r=nan",
            "scheme.control.k_r",
            "must be a finite number",
        ),
        (
            "scheme.observer.k_sigma=inf",
            "scheme.observer.k_sigma",
            "must be a finite number",
        ),
        (
            "agent[0].attitude={ axis = [1.0, 0.0, 0.0], angle_rad = nan }",
            "agent[0].attitude.angle_rad",
            "must be a finite number",
        ),
        (
            "agent[0].attitude={ axis = [nan, 0.0, 0.0], angle_rad = 1.0 }",
            "agent[0].attitude.axis",
            "must be finite and non-zero",
        ),
        (
            "agent[1].observer.attitude={ quaternion = [1.0, nan, 0.0, 0.0] }",
            "agent[1].observer.attitude.quaternion",
            "must be finite and non-zero",
        ),
        (
            "leader.attitude={ matrix = [[1.0, 0.0, 0.0], [0.0, inf, 0.0], [0.0, 0.0, 1.0]] }",
            "leader.attitude.matrix",
            "must hold finite numbers",
        ),
        (
            "agent[2].observer.omega=[nan, 0.0, 0.0]",
            "agent[2].observer.omega",
            "finite",
        ),
        (
            "agent[2].observer.sigma=[0.0, 0.0, inf]",
            "agent[2].observer.sigma",
            "finite",
        ),
    ];
    for (set, field, reason) in cases {
        expect_only_issue(BASE, &[set], field, reason);
    }
}

#[test]
fn non_finite_numbers_are_rejected_from_the_file_text() {
    // Without overrides the text itself is parsed (a different code path).
    expect_only_issue(
        &edit(BASE, "dt = 0.001", "dt = nan"),
        &[],
        "simulation.dt",
        "must be a finite number",
    );
    expect_only_issue(
        &edit(BASE, "omega = [1.5, 1.0, 2.0]", "omega = [1.5, inf, 2.0]"),
        &[],
        "agent[0].omega",
        "finite",
    );
    expect_only_issue(
        &edit(
            BASE,
            "inertia = [0.2, 0.4, 0.4]",
            "inertia = [0.2, -inf, 0.4]",
        ),
        &[],
        "agent[1].inertia",
        "must hold finite numbers",
    );
    expect_only_issue(
        &edit(
            BASE,
            "agents = [2, 3]\ngain = [13.0, 14.0, 15.0]",
            "agents = [2, 3]\ngain = [13.0, nan, 15.0]",
        ),
        &[],
        "edge[1].gain",
        "must hold finite numbers",
    );
}

// ------------------------------------------------------------------ time

#[test]
fn dt_must_be_positive() {
    // One issue only: duration and sample period are not also blamed.
    expect_only_issue(BASE, &["simulation.dt=0"], "simulation.dt", "must be > 0");
    expect_only_issue(
        BASE,
        &["simulation.dt=-0.001"],
        "simulation.dt",
        "must be > 0, got -0.001",
    );
}

#[test]
fn duration_must_be_a_positive_multiple_of_dt() {
    expect_only_issue(
        BASE,
        &["simulation.duration=1.0005"],
        "simulation.duration",
        "must be a whole multiple of simulation.dt = 0.001",
    );
    expect_only_issue(
        BASE,
        &["simulation.duration=0.0004"],
        "simulation.duration",
        "whole multiple",
    );
    expect_only_issue(
        BASE,
        &["simulation.duration=0"],
        "simulation.duration",
        "must be > 0",
    );
    expect_only_issue(
        BASE,
        &["simulation.duration=-1"],
        "simulation.duration",
        "must be > 0",
    );
    // Integers are numbers too, and binary noise (0.3 / 0.1) is tolerated.
    assert_eq!(
        valid(BASE, &["simulation.duration=2"])
            .resolved
            .network
            .steps,
        2000
    );
    // dt = 0.1 s is beyond RK4's stable step of BASE's tracking loop
    // (docs/stiffness.md), refused unless --no-stiffness-check; the rule
    // tested here is the multiple of dt.
    let sets: Vec<String> = [
        "simulation.dt=0.1",
        "simulation.duration=0.3",
        "output.sample_period=0.1",
    ]
    .map(String::from)
    .to_vec();
    let l = attsync::scenario::load_str_with(
        Path::new(FILE),
        BASE,
        &sets,
        attsync::scenario::StiffnessCheck::Warn,
    )
    .unwrap_or_else(|e| panic!("expected a valid scenario, got:\n{e}"));
    assert_eq!(l.resolved.network.steps, 3);
}

#[test]
fn sample_period_must_be_a_multiple_of_dt() {
    expect_only_issue(
        BASE,
        &["output.sample_period=0.0015"],
        "output.sample_period",
        "must be a whole multiple of simulation.dt",
    );
    expect_only_issue(
        BASE,
        &["output.sample_period=0"],
        "output.sample_period",
        "must be > 0",
    );
}

#[test]
fn sampled_coupling_needs_a_period() {
    expect_only_issue(
        BASE,
        &["simulation.coupling=sampled"],
        "simulation.period",
        "is required with coupling = \"sampled\"",
    );
    let l = valid(
        BASE,
        &["simulation.coupling=sampled", "simulation.period=0.005"],
    );
    assert_eq!(
        l.resolved.network.coupling,
        attitude::network::Coupling::Sampled { every: 5 }
    );
}

#[test]
fn period_with_continuous_coupling_is_rejected() {
    expect_only_issue(
        BASE,
        &["simulation.period=0.005"],
        "simulation.period",
        "is only used with coupling = \"sampled\"",
    );
}

#[test]
fn sampled_period_must_be_a_multiple_of_dt() {
    expect_only_issue(
        BASE,
        &["simulation.coupling=sampled", "simulation.period=0.0025"],
        "simulation.period",
        "must be a whole multiple of simulation.dt",
    );
    expect_only_issue(
        BASE,
        &["simulation.coupling=sampled", "simulation.period=-0.005"],
        "simulation.period",
        "must be > 0",
    );
}

// ------------------------------------------------------------- rotations

#[test]
fn rotation_with_two_forms_is_rejected() {
    expect_only_issue(
        BASE,
        &["agent[0].attitude.quaternion=[1.0, 0.0, 0.0, 0.0]"],
        "agent[0].attitude",
        "give exactly one of",
    );
    expect_only_issue(
        BASE,
        &[
            "leader.attitude={ quaternion = [1.0, 0.0, 0.0, 0.0], matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] }",
        ],
        "leader.attitude",
        "give exactly one of",
    );
    expect_only_issue(
        BASE,
        &["leader.attitude={}"],
        "leader.attitude",
        "give exactly one of",
    );
}

#[test]
fn rotation_without_angle_or_axis_is_rejected() {
    expect_only_issue(
        BASE,
        &["agent[0].attitude={ axis = [1.0, 0.0, 0.0] }"],
        "agent[0].attitude",
        "give exactly one of angle_rad, angle_deg, angle_pi",
    );
    expect_only_issue(
        BASE,
        &["agent[0].attitude={ axis = [1.0, 0.0, 0.0], angle_deg = 30.0, angle_rad = 0.5 }"],
        "agent[0].attitude",
        "give exactly one of angle_rad, angle_deg, angle_pi",
    );
    expect_only_issue(
        BASE,
        &["agent[1].attitude={ angle_deg = 30.0 }"],
        "agent[1].attitude.axis",
        "an angle needs an axis",
    );
}

#[test]
fn rotation_with_zero_axis_is_rejected() {
    expect_only_issue(
        BASE,
        &["agent[2].observer.attitude={ axis = [0.0, 0.0, 0.0], angle_deg = 30.0 }"],
        "agent[2].observer.attitude.axis",
        "must be finite and non-zero",
    );
}

#[test]
fn rotation_matrix_must_be_a_rotation() {
    // A reflection: orthogonal, det −1.
    expect_only_issue(
        BASE,
        &["leader.attitude={ matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]] }"],
        "leader.attitude.matrix",
        "is not a rotation",
    );
    // Not orthogonal.
    expect_only_issue(
        BASE,
        &["agent[0].attitude={ matrix = [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]] }"],
        "agent[0].attitude.matrix",
        "is not a rotation",
    );
}

#[test]
fn zero_quaternion_is_rejected() {
    expect_only_issue(
        BASE,
        &["agent[1].observer.attitude={ quaternion = [0.0, 0.0, 0.0, 0.0] }"],
        "agent[1].observer.attitude.quaternion",
        "must be finite and non-zero",
    );
}

#[test]
fn valid_quaternion_and_matrix_rotations_are_accepted() {
    // Rotation by 2π/3 about (1, 1, 1): x → y → z → x.
    let cycle = Matrix3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    let l = valid(
        BASE,
        &["agent[0].attitude={ quaternion = [0.5, 0.5, 0.5, 0.5] }"],
    );
    assert!((l.resolved.network.agents[0].initial.r - cycle).amax() < 1e-12);
    // Not normalised: normalised on use.
    let l = valid(
        BASE,
        &["agent[1].attitude={ quaternion = [2.0, 0.0, 0.0, 0.0] }"],
    );
    assert!((l.resolved.network.agents[1].initial.r - Matrix3::identity()).amax() < 1e-12);
    // A matrix, by rows: Rz(90°), the same as axis z with 90° or π/2.
    let rz = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    let l = valid(
        BASE,
        &["leader.attitude={ matrix = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]] }"],
    );
    assert!((l.resolved.network.leader.r0 - rz).amax() < 1e-15);
    for form in [
        "{ axis = [0.0, 0.0, 2.0], angle_deg = 90.0 }",
        "{ axis = [0.0, 0.0, 1.0], angle_pi = 0.5 }",
        "{ axis = [0.0, 0.0, 1.0], angle_rad = 1.5707963267948966 }",
    ] {
        let l = valid(BASE, &[&format!("agent[2].observer.attitude={form}")]);
        assert!(
            (l.resolved.network.agents[2].initial.r_hat - rz).amax() < 1e-12,
            "{form}"
        );
    }
}

// ---------------------------------------------------------------- scheme

#[test]
fn scheme_1_needs_observer_gains() {
    let text = without_line(BASE, "observer = { k_r = 9.0");
    expect_only_issue(
        &text,
        &[],
        "scheme.observer",
        "is required by scheme observer-time-varying",
    );
}

#[test]
fn scheme_1_needs_k_sigma() {
    expect_only_issue(
        BASE,
        &["scheme.observer={ k_r = 9.0, k_omega = 14.0 }"],
        "scheme.observer.k_sigma",
        "is required by scheme observer-time-varying",
    );
}

#[test]
fn scalar_gains_must_be_positive() {
    let cases = [
        ("scheme.control.k_r=0", "scheme.control.k_r"),
        ("scheme.control.k_omega=-13", "scheme.control.k_omega"),
        ("scheme.observer.k_r=0", "scheme.observer.k_r"),
        ("scheme.observer.k_omega=-1", "scheme.observer.k_omega"),
        ("scheme.observer.k_sigma=0", "scheme.observer.k_sigma"),
    ];
    for (set, field) in cases {
        expect_only_issue(BASE, &[set], field, "must be > 0");
    }
}

#[test]
fn scheme_1_needs_each_agents_observer_initial_state() {
    let text = without_line(BASE, "angle_pi = -0.2 }");
    expect_only_issue(
        &text,
        &[],
        "agent[1].observer",
        "the observer's initial state is required",
    );
    expect_only_issue(
        BASE,
        &[
            "agent[2].observer={ attitude = { axis = [1.0, 1.0, 0.0], angle_pi = -0.3 }, omega = [3.0, 3.5, 4.0] }",
        ],
        "agent[2].observer.sigma",
        "is required by scheme observer-time-varying",
    );
}

#[test]
fn scheme_1_needs_each_agents_control_gain() {
    let text = without_line(BASE, "control_gain = [13.0, 14.0, 15.0]");
    expect_only_issue(
        &text,
        &[],
        "agent[2].control_gain",
        "is required by scheme observer-time-varying",
    );
}

#[test]
fn constant_reference_must_not_give_omega_or_sigma() {
    let issues = expect_issue(
        BASE,
        &["leader.reference=constant"],
        "leader.omega",
        "must be absent for reference = \"constant\"",
    );
    expect_issue(
        BASE,
        &["leader.reference=constant"],
        "leader.sigma",
        "must be absent",
    );
    assert_eq!(issues.len(), 2, "{issues:#?}");
}

#[test]
fn time_varying_reference_needs_omega_and_sigma() {
    let text = without_line(BASE, "omega = [1.0, 2.0, 0.0]");
    expect_only_issue(
        &text,
        &[],
        "leader.omega",
        "is required by reference = \"time-varying\"",
    );
    let text = without_line(BASE, "sigma = [1.0, 0.0, 0.0]");
    expect_only_issue(
        &text,
        &[],
        "leader.sigma",
        "is required by reference = \"time-varying\"",
    );
}

// ----------------------------------------------------- parse and override

#[test]
fn unknown_keys_are_parse_errors_naming_the_key() {
    let edits = [
        ("name = \"base\"", "name = \"base\"\ncolour = \"red\""),
        (
            "coupling = \"continuous\"",
            "coupling = \"continuous\"\ncolour = 1",
        ),
        ("sample_period = 0.01", "sample_period = 0.01\ncolour = 1"),
        ("k_sigma = 12.0 }", "k_sigma = 12.0, colour = 1 }"),
        (
            "sigma = [1.0, 0.0, 0.0]",
            "sigma = [1.0, 0.0, 0.0]\ncolour = 1",
        ),
        (
            "control_gain = [12.0, 13.0, 14.0]",
            "control_gain = [12.0, 13.0, 14.0]\ncolour = 1",
        ),
        (
            "sigma = [4.0, 3.5, 3.0] }",
            "sigma = [4.0, 3.5, 3.0], colour = 1 }",
        ),
        (
            "{ axis = [1.0, 1.0, 0.0], angle_pi = 0.3 }",
            "{ axis = [1.0, 1.0, 0.0], angle_pi = 0.3, colour = 1 }",
        ),
        (
            "gain = [15.0, 16.0, 17.0]",
            "gain = [15.0, 16.0, 17.0]\ncolour = 1",
        ),
        (
            "gain = [12.0, 13.0, 14.0]\n\n",
            "gain = [12.0, 13.0, 14.0]\ncolour = 1\n\n",
        ),
    ];
    for (from, to) in edits {
        let msg = parse_error(&edit(BASE, from, to), &[]);
        assert!(msg.contains("unknown field `colour`"), "{from}: {msg}");
        assert!(msg.contains("line"), "{from}: no line number: {msg}");
    }
    // Through --set, the message names the field path.
    let msg = parse_error(BASE, &["agent[1].colour=1"]);
    assert!(msg.contains("unknown field `colour`"), "{msg}");
    assert!(msg.contains("agent[1]"), "{msg}");
    let msg = parse_error(BASE, &["leader.attitude.colour=1"]);
    assert!(
        msg.contains("unknown field `colour`") && msg.contains("leader.attitude"),
        "{msg}"
    );
}

#[test]
fn wrong_shapes_and_values_are_parse_errors() {
    let msg = parse_error(BASE, &["edge[0].gain=[1.0, 2.0]"]);
    assert!(
        msg.contains("3 numbers (a diagonal) or 3 rows of 3 numbers"),
        "{msg}"
    );
    assert!(msg.contains("edge[0].gain"), "{msg}");
    let msg = parse_error(BASE, &["scheme.kind=observer-fancy"]);
    assert!(
        msg.contains("observer-fancy") && msg.contains("scheme.kind"),
        "{msg}"
    );
    let msg = parse_error(&without_line(BASE, "dt = 0.001"), &[]);
    assert!(msg.contains("missing field `dt`"), "{msg}");
    let msg = parse_error("this is not toml", &[]);
    assert!(msg.contains("line 1"), "{msg}");
}

#[test]
fn bad_overrides_are_override_errors() {
    for set in ["agent[7].id=3", "no_equals_sign", "name.sub=1", "=1"] {
        match try_load(BASE, &[set]) {
            Err(e @ ScenarioError::Override { .. }) => {
                let msg = e.to_string();
                assert!(msg.starts_with(&format!("{FILE}: --set ")), "{msg}");
            }
            other => panic!(
                "{set}: expected an Override error, got {:?}",
                other.map(|_| ())
            ),
        }
    }
}

// -------------------------------------------------------- several at once

#[test]
fn all_errors_are_reported_at_once() {
    let text = append(&format!("{}{}", edge(3, 3), leader_link(9)));
    let sets = [
        "edge[0].gain=[10.0, 10.0, 12.0]",
        "agent[2].inertia=[-1.0, 1.0, 1.0]",
        "leader.p=[[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]",
        "output.sample_period=0.0015",
        "scheme.control.k_omega=0",
        "agent[1].attitude={ quaternion = [0.0, 0.0, 0.0, 0.0] }",
    ];
    let (issues, msg) = invalid(&text, &sets);
    let fields: Vec<&str> = issues.iter().map(|i| i.field.as_str()).collect();
    for f in [
        "edge[0].gain",
        "agent[2].inertia",
        "leader.p",
        "output.sample_period",
        "scheme.control.k_omega",
        "agent[1].attitude.quaternion",
        "edge[2].agents",
        "leader_link[1].agent",
    ] {
        assert!(fields.contains(&f), "{f} missing from:\n{msg}");
    }
    assert_eq!(issues.len(), 8, "{msg}");
    assert!(msg.lines().all(|l| l.starts_with("x.toml: ")), "{msg}");
}

// --------------------------------------------------------------- warnings

#[test]
fn appendix_d_gain_condition_failure_is_a_warning() {
    let l = valid(
        BASE,
        &["scheme.observer={ k_r = 9.0, k_omega = 1e-3, k_sigma = 1e-3 }"],
    );
    let r = &l.resolved;
    let m = r.appendix_d_min_eig.expect("scheme 1 reports λmin(F)");
    assert!(m <= 0.0, "λmin(F) = {m}");
    let w = r
        .warnings
        .iter()
        .find(|w| w.field == "scheme.observer")
        .unwrap_or_else(|| panic!("no warning on scheme.observer: {:?}", r.warnings));
    assert!(w.reason.contains("Appendix D"), "{w}");
}

#[test]
fn appendix_d_gain_condition_holds_with_the_papers_gains() {
    let r = valid(BASE, &[]).resolved;
    let m = r.appendix_d_min_eig.expect("scheme 1 reports λmin(F)");
    assert!(m > 0.0, "λmin(F) = {m}");
    assert!(
        r.warnings.iter().all(|w| w.field != "scheme.observer"),
        "{:?}",
        r.warnings
    );
    // Only scheme 1 has the condition.
    let r = valid(
        &without_line(
            &without_line(BASE, "omega = [1.0, 2.0, 0.0]"),
            "sigma = [1.0, 0.0, 0.0]",
        ),
        &["scheme.kind=observerless", "leader.reference=constant"],
    )
    .resolved;
    assert_eq!(r.appendix_d_min_eig, None);
}

#[test]
fn observerless_scheme_with_observer_section_warns() {
    let text = without_line(
        &without_line(BASE, "omega = [1.0, 2.0, 0.0]"),
        "sigma = [1.0, 0.0, 0.0]",
    );
    let l = valid(
        &text,
        &["scheme.kind=observerless", "leader.reference=constant"],
    );
    let w = &l.resolved.warnings;
    let has = |field: &str| {
        w.iter()
            .any(|i| i.field == field && i.reason.contains("ignored"))
    };
    assert!(has("scheme.observer"), "{w:?}");
    assert!(
        has("agent[0].observer") && has("agent[0].control_gain"),
        "{w:?}"
    );
    assert!(!l.resolved.network.agents[0].model.scheme.has_observer());
}

#[test]
fn observer_constant_scheme_with_sigma_terms_warns() {
    let text = without_line(
        &without_line(BASE, "omega = [1.0, 2.0, 0.0]"),
        "sigma = [1.0, 0.0, 0.0]",
    );
    let l = valid(
        &text,
        &["scheme.kind=observer-constant", "leader.reference=constant"],
    );
    let w = &l.resolved.warnings;
    assert!(
        w.iter().any(|i| i.field == "scheme.observer.k_sigma"),
        "{w:?}"
    );
    assert!(
        w.iter().any(|i| i.field == "agent[1].observer.sigma"),
        "{w:?}"
    );
}

// ------------------------------------------------- found bugs (ignored)

/// Every rotation that is accepted is the rotation the spec describes (or at
/// least a rotation): a spec is either rejected on its own field or resolved
/// to an orthogonal matrix with det +1 and the right angle.
#[test]
fn extreme_but_nonzero_rotation_specs_are_exact_or_rejected() {
    let deg30 = 30f64.to_radians();
    // (spec, expected rotation angle about the normalised axis, in rad)
    let cases = [
        ("{ quaternion = [1e-200, 0.0, 0.0, 0.0] }", 0.0),
        (
            "{ quaternion = [1e200, 1e200, 0.0, 0.0] }",
            std::f64::consts::FRAC_PI_2,
        ),
        ("{ axis = [1e200, 1e200, 0.0], angle_deg = 30.0 }", deg30),
        ("{ axis = [1e-160, 1e-160, 0.0], angle_deg = 30.0 }", deg30),
    ];
    for (spec, angle) in cases {
        match try_load(BASE, &[&format!("agent[0].attitude={spec}")]) {
            Ok(l) => {
                let r = l.resolved.network.agents[0].initial.r;
                assert!(r.iter().all(|x| x.is_finite()), "{spec}: accepted as {r}");
                assert!(
                    (r.transpose() * r - Matrix3::identity()).amax() < 1e-12,
                    "{spec}: {r}"
                );
                assert!((r.determinant() - 1.0).abs() < 1e-12, "{spec}: {r}");
                let cos = (r.trace() - 1.0) / 2.0;
                assert!(
                    (cos - angle.cos()).abs() < 1e-12,
                    "{spec}: angle {} not {angle}",
                    cos.acos()
                );
            }
            Err(ScenarioError::Invalid { issues, .. }) => {
                assert!(
                    issues
                        .iter()
                        .all(|i| i.field.starts_with("agent[0].attitude")),
                    "{spec}: {issues:?}"
                );
            }
            Err(e) => panic!("{spec}: {e}"),
        }
    }
}

#[test]
fn absurd_step_counts_are_rejected() {
    // 1e303 steps: `n as u64` saturates to u64::MAX and the run never ends.
    expect_only_issue(
        BASE,
        &["simulation.duration=1e300"],
        "simulation.duration",
        "",
    );
    expect_only_issue(
        BASE,
        &["output.sample_period=1e300"],
        "output.sample_period",
        "",
    );
}

#[test]
fn name_must_be_a_plain_directory_name() {
    for name in ["../escape", "a/b", "/tmp/abs", "", "."] {
        expect_only_issue(BASE, &[&format!("name=\"{name}\"")], "name", "");
    }
}
