//! `attsync check SCENARIO --hosts HOSTS.toml` (issue 12): a good placement
//! file prints each host's nodes, the local ones and the cut edges — checked
//! here against the links worked out from the scenario's own `[[edge]]` and
//! `[[leader_link]]` tables; every kind of bad file is refused with exit
//! code 2, one line per problem as `FILE: FIELD: REASON`, all at once, and
//! before the scenario is even read.

mod common;

use common::PAPER;
use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsStr;
use std::fs;
use std::path::{Path, PathBuf};

/// A hosts file for the paper's scenario: the leader and agents 1, 3 on
/// `lab-a`, 4, 5 on `lab-b`, 2, 6, 7 local.
const SPLIT: &str = r#"
insecure = true

[[host]]
name = "lab-a"
endpoint = "tcp/127.0.0.1:7447"
agents = [3, 1]
leader = true

[[host]]
name = "lab-b"
endpoint = "tcp/localhost:7448"
agents = [5, 4]
"#;

/// The machine each placed node of [`SPLIT`] is on (the others: local).
const SPLIT_PLACED: [(u32, &str); 5] = [
    (0, "lab-a"),
    (1, "lab-a"),
    (3, "lab-a"),
    (4, "lab-b"),
    (5, "lab-b"),
];

/// How `check` names the orchestrator's machine.
const LOCAL: &str = "(local)";

/// `text` written to `name` in a new temporary directory (removed when
/// the first value is dropped).
fn write(name: &str, text: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    fs::write(&path, text).unwrap();
    (dir, path)
}

/// `attsync check SCENARIO --hosts HOSTS`.
fn check(scenario: &Path, hosts: &Path) -> common::Out {
    let args = [
        "check".as_ref(),
        scenario.as_os_str(),
        "--hosts".as_ref(),
        hosts.as_os_str(),
    ];
    common::attsync(Path::new(env!("CARGO_MANIFEST_DIR")), &args)
}

/// Every directed link of the scenario file `scenario` (sender, receiver),
/// read from its TOML: each `[[edge]]` both ways, each `[[leader_link]]`
/// from node 0.
fn links(scenario: &Path) -> Vec<(u32, u32)> {
    let doc: toml::Table = common::read(scenario).parse().unwrap();
    let ints = |v: &toml::Value| u32::try_from(v.as_integer().unwrap()).unwrap();
    let mut out = Vec::new();
    for e in doc["edge"].as_array().unwrap() {
        let ends = e["agents"].as_array().unwrap();
        let (a, b) = (ints(&ends[0]), ints(&ends[1]));
        out.extend([(a, b), (b, a)]);
    }
    for l in doc["leader_link"].as_array().unwrap() {
        out.push((0, ints(&l["agent"])));
    }
    out
}

/// The cut edges `check` printed: (sender's machine, receiver's machine,
/// sender, receiver), and the count it announced.
fn printed_cut(stdout: &str) -> (usize, BTreeSet<(String, String, u32, u32)>) {
    let mut lines = stdout.lines().skip_while(|l| !l.starts_with("cut edges: "));
    let head = lines.next().expect("a `cut edges:` line");
    let count = head["cut edges: ".len()..].parse().unwrap();
    let mut cut = BTreeSet::new();
    for line in lines {
        let (pair, list) = line.trim().split_once(": ").unwrap();
        let (pair, n) = pair.rsplit_once(" (").unwrap();
        let (from, to) = pair.split_once(" → ").unwrap();
        let edges: Vec<&str> = list.split(", ").collect();
        assert_eq!(n.trim_end_matches(')'), edges.len().to_string(), "{line}");
        for e in edges {
            let (a, b) = e.split_once('→').unwrap();
            let edge = (
                from.into(),
                to.into(),
                a.parse().unwrap(),
                b.parse().unwrap(),
            );
            assert!(cut.insert(edge), "{e} printed twice");
        }
    }
    (count, cut)
}

/// The nodes `check` printed per machine (host name, or [`LOCAL`]).
fn printed_nodes(stdout: &str) -> BTreeMap<String, Vec<u32>> {
    let mut nodes = BTreeMap::new();
    let placement = stdout
        .lines()
        .skip_while(|l| !l.starts_with("placement ("))
        .skip(1)
        .take_while(|l| !l.starts_with("cut edges: "));
    for line in placement {
        let line = line.trim();
        let machine = match line.strip_prefix("host ") {
            Some(rest) => rest.split_whitespace().next().unwrap(),
            None if line.starts_with(LOCAL) => LOCAL,
            None => continue,
        };
        let list = line
            .split_once("nodes [")
            .unwrap()
            .1
            .split(']')
            .next()
            .unwrap();
        let ids = list
            .split(", ")
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().unwrap())
            .collect();
        nodes.insert(machine.to_owned(), ids);
    }
    nodes
}

#[test]
fn a_good_file_prints_the_placement_and_the_cut_edges_of_the_paper() {
    let (_dir, hosts) = write("hosts.toml", SPLIT);
    let out = check(Path::new(PAPER), &hosts);
    out.assert_ok();
    assert!(
        out.stdout.starts_with(&format!("{PAPER}: OK")),
        "{}",
        out.stdout
    );
    let placed: BTreeMap<u32, &str> = SPLIT_PLACED.into_iter().collect();
    let machine = |n: u32| placed.get(&n).copied().unwrap_or(LOCAL).to_owned();
    let expected: BTreeSet<_> = links(Path::new(PAPER))
        .into_iter()
        .filter(|&(a, b)| machine(a) != machine(b))
        .map(|(a, b)| (machine(a), machine(b), a, b))
        .collect();
    assert!(!expected.is_empty());
    let (count, cut) = printed_cut(&out.stdout);
    assert_eq!(count, expected.len(), "{}", out.stdout);
    assert_eq!(cut, expected, "{}", out.stdout);
    let mut nodes: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    for n in 0..=7 {
        nodes.entry(machine(n)).or_default().push(n);
    }
    assert_eq!(printed_nodes(&out.stdout), nodes, "{}", out.stdout);
    for endpoint in ["tcp/127.0.0.1:7447", "tcp/localhost:7448"] {
        assert!(out.stdout.contains(endpoint), "{}", out.stdout);
    }
}

#[test]
fn every_node_on_hosts_leaves_nothing_local_and_the_same_host_cuts_nothing() {
    let (_dir, hosts) = write(
        "one.toml",
        "[[host]]\nname = \"all\"\nendpoint = \"tcp/[::1]:7447\"\nagents = [7, 6, 5, 4, 3, 2, 1]\nleader = true\n",
    );
    let out = check(Path::new(PAPER), &hosts);
    out.assert_ok();
    let (count, cut) = printed_cut(&out.stdout);
    assert_eq!((count, cut.len()), (0, 0), "{}", out.stdout);
    let nodes = printed_nodes(&out.stdout);
    assert_eq!(nodes["all"], (0..=7).collect::<Vec<u32>>());
    assert_eq!(nodes[LOCAL], Vec::<u32>::new());
}

/// `check` of the paper with the hosts file `text`: exit code 2 and exactly
/// the lines `FILE: FIELD: REASON…` for the `(field, reason)` pairs given,
/// in order (a reason is matched as the start of the line's reason).
#[track_caller]
fn refused(text: &str, problems: &[(&str, &str)]) {
    let (_dir, hosts) = write("hosts.toml", text);
    let out = check(Path::new(PAPER), &hosts);
    out.assert_code(2);
    assert!(out.stdout.is_empty(), "nothing printed: {}", out.stdout);
    let lines: Vec<&str> = out.stderr.lines().collect();
    assert_eq!(
        lines.len(),
        problems.len(),
        "one line per problem:\n{}",
        out.stderr
    );
    for (line, (field, reason)) in lines.iter().zip(problems) {
        let start = format!("{}: {field}: {reason}", hosts.display());
        assert!(
            line.starts_with(&start),
            "expected `{start}…`, got\n{}",
            out.stderr
        );
    }
}

/// One `[[host]]` table.
fn host(name: &str, endpoint: &str, rest: &str) -> String {
    format!("[[host]]\nname = \"{name}\"\nendpoint = \"{endpoint}\"\n{rest}\n")
}

const EP: &str = "tcp/127.0.0.1:7447";

#[test]
fn syntax_and_schema_errors_name_the_field_and_the_reason() {
    refused(
        "[[host]\nname = 1\n",
        &[("line 1, column 8", "unclosed array table")],
    );
    refused(
        &host("a", EP, "agents = [1]\ncolour = 1\n[extra]\nx = 1"),
        &[
            ("extra", "unknown field `extra`"),
            ("host[0].colour", "unknown field `colour`"),
        ],
    );
    refused(
        "[[host]]\nendpoint = 7447\nagents = [1, -2]\nleader = \"yes\"\n",
        &[
            (
                "host[0].agents[1]",
                "invalid value: integer `-2`, expected u32",
            ),
            (
                "host[0].endpoint",
                "invalid type: integer `7447`, expected a string",
            ),
            (
                "host[0].leader",
                "invalid type: string \"yes\", expected a boolean",
            ),
            ("host[0].name", "missing field `name`"),
        ],
    );
}

#[test]
fn names_endpoints_the_leader_and_agents_are_checked_at_once() {
    let text = [
        host(
            "a b",
            "udp/127.0.0.1:7447",
            "agents = [3, 0, 3]\nleader = true",
        ),
        host("", "tcp/127.0.0.1:0", "agents = [5]"),
        host("lab", "tcp/300.1.1.1:7447", "agents = [5]\nleader = true"),
        host("lab", "tcp/127.0.0.1", "agents = [6]"),
        host("idle", "tcp/h_1:7447", "agents = []"),
    ]
    .concat();
    refused(
        &text,
        &[
            (
                "host[0].name",
                "`a b` is not a name of 1 to 64 letters, digits, `_` or `-`",
            ),
            (
                "host[0].endpoint",
                "`udp/127.0.0.1:7447` is not a QUIC, TLS or TCP endpoint (`udp`)",
            ),
            ("host[0].agents[1]", "0 is the leader's node, not an agent"),
            (
                "host[0].agents[2]",
                "agent 3 is already placed at host[0].agents[0]",
            ),
            ("host[1].name", "is empty"),
            (
                "host[1].endpoint",
                "`tcp/127.0.0.1:0`: port `0` is not a number from 1 to 65535",
            ),
            (
                "host[2].endpoint",
                "`tcp/300.1.1.1:7447`: `300.1.1.1` is not an IPv4 address",
            ),
            ("host[2].leader", "the leader is already on host[0]"),
            (
                "host[2].agents[0]",
                "agent 5 is already placed at host[1].agents[0]",
            ),
            ("host[3].name", "`lab` is already the name of host[2]"),
            ("host[3].endpoint", "`tcp/127.0.0.1` has no port"),
            (
                "host[4].endpoint",
                "`tcp/h_1:7447`: `h_1` is not an IP address or a host name",
            ),
            ("host[4]", "host `idle` runs nothing"),
        ],
    );
}

#[test]
fn an_empty_file_and_agents_the_scenario_lacks_are_refused() {
    refused("", &[("host", "the file places nothing")]);
    refused(
        &[
            host("a", EP, "agents = [1, 9]"),
            host("b", "tcp/localhost:1", "agents = [12]"),
        ]
        .concat(),
        &[
            (
                "host[0].agents[1]",
                "agent 9 does not exist (the scenario has 7 agents)",
            ),
            (
                "host[1].agents[0]",
                "agent 12 does not exist (the scenario has 7 agents)",
            ),
        ],
    );
}

#[test]
fn a_bad_hosts_file_is_refused_before_the_scenario_is_read() {
    let (dir, hosts) = write("hosts.toml", &host("a", "tcp/x:99999", "agents = [1]"));
    let out = check(&dir.path().join("no-such-scenario.toml"), &hosts);
    out.assert_code(2);
    let expected = format!(
        "{}: host[0].endpoint: `tcp/x:99999`: port `99999` is not a number from 1 to 65535\n",
        hosts.display()
    );
    assert_eq!(out.stderr, expected);
}

#[test]
fn unreadable_oversized_and_non_utf8_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.toml");
    let out = check(Path::new(PAPER), &missing);
    out.assert_code(2);
    assert!(
        out.stderr
            .starts_with(&format!("{}: cannot read: ", missing.display())),
        "{}",
        out.stderr
    );
    let big = dir.path().join("big.toml");
    let limit = attsync::hosts::MAX_FILE_BYTES;
    fs::File::create(&big).unwrap().set_len(limit + 1).unwrap();
    let out = check(Path::new(PAPER), &big);
    out.assert_code(2);
    let expected = format!(
        "{}: its size, {} bytes, is over the limit of {limit} bytes (64 MiB) for a hosts file\n",
        big.display(),
        limit + 1
    );
    assert_eq!(out.stderr, expected);
    let latin1 = dir.path().join("latin1.toml");
    fs::write(&latin1, b"[[host]]\nname = \"caf\xe9\"\n").unwrap();
    let out = check(Path::new(PAPER), &latin1);
    out.assert_code(2);
    assert_eq!(
        out.stderr,
        format!(
            "{}: not UTF-8 text (invalid byte at offset 20)\n",
            latin1.display()
        )
    );
}

/// `attsync ARGS…` in `dir`: each argument a string or a path.
fn attsync_in(dir: &Path, args: &[&dyn AsRef<OsStr>]) -> common::Out {
    let args: Vec<&OsStr> = args.iter().map(|a| a.as_ref()).collect();
    common::attsync(dir, &args)
}

#[test]
fn run_and_sweep_refuse_a_bad_or_misfitting_hosts_file_before_anything_starts() {
    let (dir, bad) = write("bad.toml", &host("a", EP, "agents = [1, 1]"));
    let unknown = dir.path().join("unknown.toml");
    let insecure = format!("insecure = true\n{}", host("a", EP, "agents = [9]"));
    fs::write(&unknown, insecure).unwrap();
    let out = dir.path().join("out");
    let run = |hosts: &Path| {
        let args: [&dyn AsRef<OsStr>; 7] = [
            &"run", &PAPER, &"--quiet", &"--out", &out, &"--hosts", &hosts,
        ];
        attsync_in(dir.path(), &args)
    };
    let sweep = |hosts: &Path| {
        let param = ["--param", "network.delay", "--values", "0,0.01"];
        let args: [&dyn AsRef<OsStr>; 10] = [
            &"sweep", &PAPER, &param[0], &param[1], &param[2], &param[3], &"--out", &out,
            &"--hosts", &hosts,
        ];
        attsync_in(dir.path(), &args)
    };
    let twice = format!(
        "{}: host[0].agents[1]: agent 1 is already placed at host[0].agents[0]",
        bad.display()
    );
    let missing = format!(
        "{}: host[0].agents[0]: agent 9 does not exist (the scenario has 7 agents)",
        unknown.display()
    );
    for (what, o, expected) in [
        ("run", run(&bad), &twice),
        ("sweep", sweep(&bad), &twice),
        ("run", run(&unknown), &missing),
        ("sweep", sweep(&unknown), &missing),
    ] {
        o.assert_code(2);
        // (After `insecure = true`'s warning.)
        assert!(
            o.stderr.lines().any(|l| l.starts_with(expected.as_str())),
            "{what}: {}",
            o.stderr
        );
        assert!(!out.exists(), "{what} wrote {}", out.display());
    }
}

#[test]
fn hosts_need_the_process_engine_and_conform_says_it_runs_on_this_machine_only() {
    let (dir, hosts) = write("hosts.toml", SPLIT);
    let args: [&dyn AsRef<OsStr>; 6] = [
        &"run",
        &PAPER,
        &"--engine",
        &"in-process",
        &"--hosts",
        &hosts,
    ];
    let out = attsync_in(dir.path(), &args);
    out.assert_code(2);
    let expected = "error: --hosts needs --engine processes";
    assert!(
        out.stderr.lines().any(|l| l.starts_with(expected)),
        "{}",
        out.stderr
    );
    let args: [&dyn AsRef<OsStr>; 5] = [&"conform", &"--hosts", &hosts, &"--", &"true"];
    let out = attsync_in(dir.path(), &args);
    out.assert_code(2);
    let expected = "error: --hosts: conform runs one candidate on this machine only";
    assert!(out.stderr.starts_with(expected), "{}", out.stderr);
}

#[test]
fn a_run_across_hosts_says_how_to_secure_it_and_refuses_tls_over_tcp() {
    let (dir, none) = write("none.toml", &host("a", EP, "agents = [1]"));
    let tls = dir.path().join("tls.toml");
    let text = format!(
        "insecure = true\n{}",
        host("a", "tls/127.0.0.1:7447", "agents = [1]")
    );
    fs::write(&tls, text).unwrap();
    let out = dir.path().join("out");
    let run = |hosts: &Path, extra: &[&str]| {
        let mut args: Vec<&dyn AsRef<OsStr>> = vec![
            &"run", &PAPER, &"--quiet", &"--out", &out, &"--hosts", &hosts,
        ];
        args.extend(extra.iter().map(|e| e as &dyn AsRef<OsStr>));
        attsync_in(dir.path(), &args)
    };
    let o = run(&none, &[]);
    o.assert_code(2);
    let expected = format!("{}: tls: no security: add a [tls] table", none.display());
    assert!(o.stderr.starts_with(&expected), "{}", o.stderr);
    // TLS over TCP is refused, with its reason.
    let o = run(&tls, &[]);
    o.assert_code(2);
    assert!(
        o.stderr.contains("host[0].endpoint: `tls/127.0.0.1:7447`"),
        "{}",
        o.stderr
    );
    assert!(o.stderr.contains("zenoh#2557"), "{}", o.stderr);
    let o = run(
        &none,
        &["--ca", "/nonexistent/ca.pem", "--cert", "c", "--key", "k"],
    );
    o.assert_code(2);
    assert!(
        o.stderr.contains("--ca: /nonexistent/ca.pem: "),
        "{}",
        o.stderr
    );
    assert!(!out.exists(), "nothing is written");
}
