//! A network namespace's link to ours, for a [`crate::HostSandbox`] with a
//! network of its own ([`crate::HostSandbox::networked`]): a veth pair, one
//! end in the root namespace (the test's), the other in the host's, on a
//! /30 of `10.231.0.0/16` of its own ([`Veth`]), and optionally a real
//! delay on both ends (`tc qdisc … netem delay`, [`Veth::netem_delay`]).
//!
//! Parallel runs never collide: a pair is claimed by creating its root end,
//! whose name carries the subnet's index (`atsy<k>r`; `ip link add` fails
//! for a name that exists), and an index whose addresses are already on
//! this machine is skipped. The pair goes when dropped (`ip link del`), and
//! in any case with the host's namespace (the kernel removes a veth pair
//! when either end's namespace ends), so a failed test leaves nothing.

use std::net::Ipv4Addr;
use std::process::{Command, Output, Stdio};
use std::time::Duration;

/// How many /30 subnets `10.231.0.0/16` holds.
const SUBNETS: u32 = 1 << 14;

/// The second octet of every test subnet: 10.231.x.y.
const SECOND_OCTET: u8 = 231;

/// A veth pair between the root namespace and a host's.
#[derive(Debug)]
pub struct Veth {
    /// The root namespace's end.
    pub root_if: String,
    /// The host's end.
    pub host_if: String,
    /// The root end's address.
    pub root_addr: Ipv4Addr,
    /// The host end's address.
    pub host_addr: Ipv4Addr,
    /// A process in the host's network namespace.
    pid: u32,
}

impl Veth {
    /// A pair to the network namespace of process `pid`, both ends up and
    /// addressed. Panics, saying why, if `ip` refuses.
    #[must_use]
    pub fn connect(pid: u32) -> Self {
        let taken = run(Command::new("ip").args(["-4", "-o", "addr", "show"]));
        let taken = String::from_utf8_lossy(&taken.stdout).into_owned();
        let start = std::process::id().wrapping_mul(2_654_435_761) % SUBNETS;
        for k in (0..SUBNETS).map(|i| (start + i) % SUBNETS) {
            let (root_addr, host_addr) = addresses(k);
            if taken.contains(&format!("inet {root_addr}/"))
                || taken.contains(&format!("inet {host_addr}/"))
            {
                continue;
            }
            let (root_if, host_if) = (format!("atsy{k}r"), format!("atsy{k}n"));
            // Built only once claimed: dropping it deletes `root_if`.
            if claim(&root_if, &host_if, pid) {
                let v = Self {
                    root_if,
                    host_if,
                    root_addr,
                    host_addr,
                    pid,
                };
                v.configure();
                return v;
            }
        }
        panic!("no free veth name / subnet in 10.{SECOND_OCTET}.0.0/16");
    }

    /// Addresses both ends and brings them up.
    fn configure(&self) {
        let cidr = |a: Ipv4Addr| format!("{a}/30");
        ok(Command::new("ip").args(["addr", "add", &cidr(self.root_addr), "dev", &self.root_if]));
        ok(Command::new("ip").args(["link", "set", &self.root_if, "up"]));
        ok(self
            .in_host("ip")
            .args(["addr", "add", &cidr(self.host_addr), "dev", &self.host_if]));
        ok(self
            .in_host("ip")
            .args(["link", "set", &self.host_if, "up"]));
    }

    /// `program` run in the host's network namespace.
    fn in_host(&self, program: &str) -> Command {
        let mut c = Command::new("nsenter");
        c.arg(format!("--target={}", self.pid))
            .args(["--net", "--", program]);
        c
    }

    /// `tc qdisc add dev <end> root netem delay <delay>` on both ends, so
    /// that every packet across waits `delay` (a round trip twice that).
    /// `Err` with `tc`'s words if it refuses (a kernel built without
    /// `sch_netem`, as some VMs' are), neither end then delayed.
    ///
    /// # Errors
    /// `NetemRefused` with `tc`'s words.
    pub fn netem_delay(&self, delay: Duration) -> Result<(), NetemRefused> {
        let d = format!("{}us", delay.as_micros());
        let netem = ["qdisc", "add", "dev"];
        let args = |dev: &str| {
            let mut a: Vec<String> = netem.iter().map(|s| (*s).to_string()).collect();
            a.extend([dev, "root", "netem", "delay", &d].map(String::from));
            a
        };
        let outs = [
            run(Command::new("tc").args(args(&self.root_if))),
            run(self.in_host("tc").args(args(&self.host_if))),
        ];
        let Some(failed) = outs.iter().find(|o| !o.status.success()) else {
            return Ok(());
        };
        // Neither end delayed, rather than one.
        let del = |dev: &str| ["qdisc", "del", "dev", dev, "root"].map(String::from);
        let _ = run(Command::new("tc").args(del(&self.root_if)));
        let _ = run(self.in_host("tc").args(del(&self.host_if)));
        Err(NetemRefused(
            String::from_utf8_lossy(&failed.stderr).trim().to_string(),
        ))
    }
}

/// `tc` refused the netem delay (its words on stderr).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NetemRefused(pub String);

impl std::fmt::Display for NetemRefused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NetemRefused {}

impl Drop for Veth {
    fn drop(&mut self) {
        // Already gone if the host's namespace ended first.
        let _ = run(Command::new("ip").args(["link", "del", &self.root_if]));
    }
}

/// The addresses of subnet `k`, `10.231.(k / 64).(4 · (k % 64))/30`: the
/// root end's (.1) and the host end's (.2).
fn addresses(k: u32) -> (Ipv4Addr, Ipv4Addr) {
    let base = u32::from(Ipv4Addr::new(10, SECOND_OCTET, 0, 0)) + 4 * k;
    (Ipv4Addr::from(base + 1), Ipv4Addr::from(base + 2))
}

/// Creates the pair `root_if` (here) – `host_if` (in `pid`'s network
/// namespace); `false` if the name is taken (another run's).
fn claim(root_if: &str, host_if: &str, pid: u32) -> bool {
    let pid = pid.to_string();
    let out = run(Command::new("ip").args([
        "link", "add", root_if, "type", "veth", "peer", "name", host_if, "netns", &pid,
    ]));
    if out.status.success() {
        return true;
    }
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("File exists"),
        "`ip link add {root_if} type veth …` failed ({}): {err}— the network namespace tests \
         need root (CI runs as root), they are not skipped",
        out.status
    );
    false
}

/// Whether this namespace has a network interface named `name`.
#[must_use]
pub fn link_exists(name: &str) -> bool {
    run(Command::new("ip").args(["link", "show", "dev", name]))
        .status
        .success()
}

/// Runs `cmd` to its end, its output captured.
fn run(cmd: &mut Command) -> Output {
    cmd.stdin(Stdio::null())
        .output()
        .unwrap_or_else(|e| panic!("cannot start {:?}: {e}", cmd.get_program()))
}

/// Runs `cmd`, panicking with its stderr if it fails.
fn ok(cmd: &mut Command) {
    let out = run(cmd);
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}
