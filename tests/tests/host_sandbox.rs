//! The multi-host tests' simulated host (`attsync_tests::HostSandbox`,
//! issue 12): shared memory does not pass between a host and the machine,
//! nor between two hosts; each host has its own `TMPDIR`; a host's
//! processes die with it (even those that left its process group), and a
//! process's group with its handle; a networked host has its own network
//! (loopback and its veth end) and its veth pair goes with it. Needs root (`unshare --mount`): CI runs
//! as root, and without it these tests fail, saying so.

use attsync_tests::{HostProcess, HostSandbox, free_port, wait_until};
use std::fs;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// Longest wait for a command in a sandbox to finish or to start.
const WAIT: Duration = Duration::from_secs(30);

/// `sh -c script` in `host`, run to its end (panics with its stderr if it fails); its stdout.
fn sh(host: &mut HostSandbox, script: &str) -> String {
    let mut cmd = Command::new("sh");
    cmd.args(["-c", script]);
    let mut p = host.spawn(&cmd);
    let status = p.wait_timeout(WAIT).expect("the script ends");
    assert!(status.success(), "{}: {status}: {}", p.what(), p.stderr());
    p.stdout()
}

/// Whether process `pid` is gone (or a zombie, dead but not reaped).
fn gone(pid: u32) -> bool {
    !attsync_sched::process::alive(pid)
}

/// `sh -c script` started in `host`, and the number its first line of
/// output says (a pid the script echoes), once written.
fn started(host: &mut HostSandbox, script: &str) -> (HostProcess, u32) {
    let mut cmd = Command::new("sh");
    cmd.args(["-c", script]);
    let p = host.spawn(&cmd);
    let pid = wait_until(WAIT, Duration::from_millis(10), || {
        p.stdout().lines().next()?.parse::<u32>().ok()
    })
    .unwrap_or_else(|| panic!("{}: no pid printed: {}", p.what(), p.stderr()));
    (p, pid)
}

#[test]
fn shared_memory_does_not_pass_between_hosts_and_the_machine() {
    let (mut a, mut b) = (HostSandbox::new("a"), HostSandbox::new("b"));
    let tag = format!("attsync-sandbox-test-{}", std::process::id());
    let (inside, outside) = (format!("{tag}-in-a"), format!("{tag}-out"));
    let outside_path = Path::new("/dev/shm").join(&outside);
    fs::write(&outside_path, b"machine").unwrap();
    let listed = sh(
        &mut a,
        &format!("echo a > /dev/shm/{inside} && ls -a /dev/shm"),
    );
    fs::remove_file(&outside_path).unwrap();
    assert!(listed.lines().any(|l| l == inside), "{listed}");
    assert!(
        !listed.contains(&outside),
        "the machine's /dev/shm seen in a: {listed}"
    );
    assert!(
        !Path::new("/dev/shm").join(&inside).exists(),
        "a's file seen outside"
    );
    assert_eq!(
        a.shm_entries(),
        [inside.clone()].into(),
        "a's /dev/shm from outside"
    );
    assert!(
        b.shm_entries().is_empty(),
        "a fresh host's /dev/shm is empty"
    );
    let in_b = sh(&mut b, "ls -a /dev/shm");
    assert!(!in_b.contains(&tag), "a's file seen in b: {in_b}");
    // What a host's processes left stays visible after they ended.
    sh(&mut a, &format!("rm /dev/shm/{inside}"));
    assert!(a.shm_entries().is_empty());
}

#[test]
fn each_host_has_its_own_tmpdir_and_starts_in_the_given_directory() {
    let (mut a, mut b) = (HostSandbox::new("a"), HostSandbox::new("b"));
    let seen = |host: &mut HostSandbox| sh(host, "echo \"$TMPDIR\"").trim().to_owned();
    let (ta, tb) = (seen(&mut a), seen(&mut b));
    assert_eq!(Path::new(&ta), a.tmpdir());
    assert_eq!(Path::new(&tb), b.tmpdir());
    assert_ne!(ta, tb);
    assert_ne!(Some(ta.clone()), std::env::var("TMPDIR").ok());
    sh(&mut a, "touch \"$TMPDIR/x\"");
    assert_eq!(a.tmp_entries(), ["x".to_owned()].into());
    assert!(b.tmp_entries().is_empty());
    let dir = tempfile::tempdir().unwrap();
    let mut cmd = Command::new("sh");
    cmd.args(["-c", "pwd; echo \"$GREETING\""])
        .current_dir(dir.path())
        .env("GREETING", "hello");
    let mut p = a.spawn(&cmd);
    p.wait_timeout(WAIT).expect("the script ends");
    let expected = format!("{}\nhello\n", dir.path().display());
    assert_eq!(p.stdout(), expected);
}

#[test]
fn dropping_a_host_kills_its_processes_even_outside_their_group() {
    let mut host = HostSandbox::new("doomed");
    // A child that leaves the process group (setsid), and its parent.
    let (p, pid) = started(&mut host, "setsid sleep 1000 & echo $!; exec sleep 1000");
    let parent = p.pid();
    assert!(!gone(pid) && !gone(parent));
    let mut live = host.processes();
    live.sort_unstable();
    let mut expected = vec![pid, parent];
    expected.sort_unstable();
    assert_eq!(live, expected, "the host's processes");
    drop(host);
    assert!(gone(pid), "the child outside the group survived its host");
    drop(p);
    assert!(gone(parent), "the parent survived");
}

#[test]
fn dropping_a_process_kills_its_group_and_the_host_lives_on() {
    let mut host = HostSandbox::new("lives-on");
    let (p, child) = started(&mut host, "sleep 1000 & echo $!; wait");
    drop(p);
    let dead = wait_until(WAIT, Duration::from_millis(10), || {
        gone(child).then_some(())
    });
    assert!(dead.is_some(), "the child in the group survived its handle");
    // The namespace is still there: a restarted command sees the same /dev/shm.
    sh(&mut host, "touch /dev/shm/kept");
    assert_eq!(sh(&mut host, "ls /dev/shm"), "kept\n");
}

#[test]
fn a_free_port_can_be_bound_on_the_loopback() {
    // free_port closes its probe, so another program (or a test running
    // beside this one) may take the port before we bind it: a few fresh
    // tries, at least one of which must bind.
    let tries: Vec<_> = (0..5)
        .map(|_| {
            let port = free_port();
            assert_ne!(port, 0);
            (port, std::net::TcpListener::bind(("127.0.0.1", port)))
        })
        .collect();
    assert!(tries.iter().any(|(_, l)| l.is_ok()), "{tries:?}");
}

#[test]
fn a_networked_host_sees_its_own_network_only_and_its_veth_goes_with_it() {
    let mut host = HostSandbox::networked("net");
    let veth = host.veth().expect("a veth pair");
    let (root_if, host_if) = (veth.root_if.clone(), veth.host_if.clone());
    let (root_addr, host_addr) = (veth.root_addr, veth.host_addr);
    let listed = sh(&mut host, "ip -4 -o addr show");
    let names: Vec<&str> = (listed.lines())
        .filter_map(|l| l.split_whitespace().nth(1))
        .collect();
    assert_eq!(names, ["lo", host_if.as_str()], "{listed}");
    assert!(listed.contains(&format!("inet {host_addr}/30")), "{listed}");
    // Our loopback is not the host's; our end of the veth is reachable.
    let ours = std::net::TcpListener::bind(("127.0.0.1", 0)).unwrap();
    let across = std::net::TcpListener::bind((root_addr, 0)).unwrap();
    let dial = |addr: std::net::SocketAddr| {
        format!(
            "python3 -c 'import socket,sys\ntry: socket.create_connection((\"{}\", {}), 5); print(\"up\")\n\
             except OSError: print(\"down\")'",
            addr.ip(),
            addr.port()
        )
    };
    assert_eq!(
        sh(&mut host, &dial(ours.local_addr().unwrap())).trim(),
        "down"
    );
    assert_eq!(
        sh(&mut host, &dial(across.local_addr().unwrap())).trim(),
        "up"
    );
    assert!(attsync_tests::link_exists(&root_if));
    drop(host);
    assert!(
        !attsync_tests::link_exists(&root_if),
        "{root_if} outlived its host"
    );
}
