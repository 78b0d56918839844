//! The daemon's trust boundary (issue 33), on loopback:
//! - an orchestrator whose certificate the daemon's CA did not sign, or
//!   one that speaks plain TCP, starts nothing there;
//! - a plug-in the daemon was not told to allow is refused before
//!   anything starts, naming the host, the node and the command;
//! - an allowed plug-in runs, and the run says it was mutual TLS;
//! - an insecure run is warned about, at start and in `summary.json`.
//!
//! The "anything" is a plug-in whose first act is to write a marker file:
//! the marker must not exist.

use attsync_tests::certs::{self, Identity};
use attsync_tests::{
    Daemon, HostSandbox, Sandbox, assert_hosts_clean, bin, free_port, hosts_file, paper,
    run_on_hosts, sh_plugin, summary, with_agent_lines,
};
use std::path::{Path, PathBuf};

const SETS: [&str; 1] = ["simulation.duration=1"];

/// The paper's scenario with agent 3 the plug-in `sh -c 'touch MARKER; …'`
/// (it then runs the built-in agent, so that an allowed one completes).
fn marking_scenario(tmp: &Sandbox, marker: &Path) -> PathBuf {
    let script = format!(
        "touch {:?}; exec \"$0\" \"$@\"",
        marker.display().to_string()
    );
    let agent = format!(", {:?}]\n", bin("attsync-agent").display().to_string());
    let extra = sh_plugin(&script).replacen("]\n", &agent, 1);
    with_agent_lines(tmp, &paper("constant-observerless"), 3, "marking", &extra)
}

/// `hosts` with its `[tls]` table replaced by `id`'s.
fn as_identity(tmp: &Sandbox, hosts: &Path, id: &Identity) -> PathBuf {
    let text = std::fs::read_to_string(hosts).expect("HOSTS.toml");
    let body = text.split_once("[[host]]").expect("a host").1;
    let file = tmp.join("as-other.toml");
    std::fs::write(&file, format!("{}[[host]]{body}", id.table())).expect("HOSTS.toml");
    file
}

#[test]
fn an_orchestrator_the_daemon_does_not_trust_starts_nothing() {
    let tmp = Sandbox::new("trust-untrusted");
    let marker = tmp.join("marker");
    let scenario = marking_scenario(&tmp, &marker);
    let a = Daemon::start_with("a", &[], &["--allow-plugin".into(), "/bin/sh".into()]);
    let hosts = hosts_file(tmp.path(), "hosts.toml", &[(&a, false, &[3])]);
    // A certificate of another CA.
    let mallory = certs::stranger(&tmp.join("other-ca"));
    let file = as_identity(&tmp, &hosts, &mallory);
    let out = tmp.join("results");
    let o = run_on_hosts(tmp.path(), &scenario, &out, &SETS, &file).output();
    assert_ne!(o.code(), Some(0), "{}", o.stderr);
    assert!(o.stderr.contains("host a (quic/"), "{}", o.stderr);
    assert!(o.stderr.contains("is unreachable"), "{}", o.stderr);
    // Plain TCP at the daemon's port (it listens on QUIC only).
    let tcp = tmp.join("tcp.toml");
    let port = a.endpoint.rsplit_once(':').expect("a port").1;
    let text = format!(
        "insecure = true\n\n[[host]]\nname = \"a\"\nendpoint = \"tcp/127.0.0.1:{port}\"\nagents = [3]\n"
    );
    std::fs::write(&tcp, text).expect("HOSTS.toml");
    let o = run_on_hosts(tmp.path(), &scenario, &out, &SETS, &tcp).output();
    assert_ne!(o.code(), Some(0), "{}", o.stderr);
    assert!(o.stderr.contains("is unreachable"), "{}", o.stderr);
    assert!(
        !marker.exists(),
        "the plug-in ran: an untrusted peer started it"
    );
    assert!(!a.log().contains("run started"), "{}", a.log());
    assert_hosts_clean(&[&a]);
}

#[test]
fn a_plugin_the_daemon_does_not_allow_is_refused_before_anything_starts() {
    let tmp = Sandbox::new("trust-refused");
    let marker = tmp.join("marker");
    let scenario = marking_scenario(&tmp, &marker);
    let a = Daemon::start("a", &[]);
    let hosts = hosts_file(tmp.path(), "hosts.toml", &[(&a, true, &[3, 5])]);
    let out = tmp.join("results");
    let o = run_on_hosts(tmp.path(), &scenario, &out, &SETS, &hosts).output();
    assert_ne!(o.code(), Some(0), "{}", o.stderr);
    let said = "host a refuses agent-3's plug-in command [\"sh\", \"-c\"";
    assert!(o.stderr.contains(said), "{}", o.stderr);
    assert!(o.stderr.contains("is not allowed here"), "{}", o.stderr);
    assert!(o.stderr.contains("--allow-plugin"), "{}", o.stderr);
    assert!(!marker.exists(), "the refused plug-in ran");
    assert!(!a.log().contains("run started"), "{}", a.log());
    assert_hosts_clean(&[&a]);
}

#[test]
fn an_allowed_plugin_runs_over_mutual_tls() {
    let tmp = Sandbox::new("trust-allowed");
    let marker = tmp.join("marker");
    let scenario = marking_scenario(&tmp, &marker);
    let a = Daemon::start_with("a", &[], &["--allow-plugin".into(), "/bin/sh".into()]);
    let hosts = hosts_file(tmp.path(), "hosts.toml", &[(&a, false, &[3])]);
    let out = tmp.join("results");
    let o = run_on_hosts(tmp.path(), &scenario, &out, &SETS, &hosts).output();
    o.assert_ok();
    assert!(!o.stderr.contains("INSECURE"), "{}", o.stderr);
    assert!(marker.exists(), "the allowed plug-in did not run");
    let s = summary(&out);
    assert_eq!(s["complete"], true, "{s:#}");
    assert_eq!(s["hosts"]["security"], "mutual-tls", "{s:#}");
    assert!(s["hosts"].get("warning").is_none(), "{s:#}");
    assert_hosts_clean(&[&a]);
}

#[test]
fn an_insecure_run_is_warned_about_at_start_and_in_its_summary() {
    let tmp = Sandbox::new("trust-insecure");
    let listen = format!("tcp/127.0.0.1:{}", free_port());
    let a = Daemon::start_on(HostSandbox::new("a"), &listen, listen.clone(), &[]);
    assert!(a.insecure());
    let hosts = hosts_file(tmp.path(), "hosts.toml", &[(&a, false, &[3])]);
    let out = tmp.join("results");
    let o = run_on_hosts(
        tmp.path(),
        &paper("constant-observerless"),
        &out,
        &SETS,
        &hosts,
    )
    .output();
    o.assert_ok();
    assert!(
        o.stderr.contains("warning: INSECURE: plain TCP"),
        "{}",
        o.stderr
    );
    assert!(a.log().contains("warning: INSECURE"), "{}", a.log());
    let s = summary(&out);
    assert_eq!(s["hosts"]["security"], "insecure", "{s:#}");
    let w = s["hosts"]["warning"].as_str().expect("a warning");
    assert!(w.starts_with("INSECURE"), "{w}");
    assert_hosts_clean(&[&a]);
}
