//! `attsync-bench zenoh-ping`: Zenoh's own round trip for a payload the
//! size of a state, between two processes on loopback — the floor under
//! the bridge's cost across a cut edge (issue 12, BENCHMARKS.md).
//!
//! The pinging process listens, a `zenoh-pong` child dials it; both open
//! their session with attsync's own configuration
//! ([`attsync::remote::zconfig::peer`]: peer mode, explicit endpoints,
//! scouting off) and the publishers as the bridge declares them
//! (congestion control `Block`, `express`). The pong echoes each sample from
//! its subscriber callback (no thread hop: Zenoh alone); the ping receives
//! through a FIFO channel on its own thread, as the bridge does.
//! attsync's configuration ([`Transport::Lowlatency`]) uses Zenoh's
//! low-latency transport (QoS off), which writes to the socket from the
//! calling thread; [`Transport::Default`] switches it back to Zenoh's
//! default transport (a TX task, QoS on). [`Transport::Tcp`] is the floor:
//! the same payload echoed over a plain blocking TCP socket
//! (`TCP_NODELAY`), no Zenoh at all.

use anyhow::{Context as _, bail};
use std::io::{Read as _, Write as _};
use std::net::{TcpListener, TcpStream};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::qos::CongestionControl;

const PING: &str = "attsync-bench/ping";
const PONG: &str = "attsync-bench/pong";

/// What carries the ping.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Transport {
    /// A plain blocking TCP socket: the floor.
    Tcp,
    /// Zenoh's default transport (a TX task, QoS on).
    Default,
    /// Zenoh as attsync configures it: `transport/unicast/lowlatency` (QoS off).
    Lowlatency,
}

impl Transport {
    fn name(self) -> &'static str {
        match self {
            Self::Tcp => "plain TCP",
            Self::Default => "zenoh default",
            Self::Lowlatency => "zenoh lowlatency",
        }
    }
}

/// One measurement's parameters.
#[derive(Debug, Clone, Copy)]
pub struct Ping {
    /// Payload bytes (a `StateMsg` is 144 B; the bridge adds its header).
    pub payload: usize,
    /// Round trips measured (after `warmup`).
    pub rounds: usize,
    /// Round trips not counted.
    pub warmup: usize,
    /// What carries it.
    pub transport: Transport,
    /// The ping's TCP port on 127.0.0.1.
    pub port: u16,
}

fn config(
    listen: &[String],
    connect: &[String],
    lowlatency: bool,
) -> anyhow::Result<zenoh::Config> {
    let insecure = attsync::trust::Security::Insecure;
    let mut c = attsync::remote::zconfig::peer(listen, connect, &insecure)?;
    if !lowlatency {
        for (k, v) in [
            ("transport/unicast/lowlatency", "false"),
            ("transport/unicast/qos/enabled", "true"),
        ] {
            c.insert_json5(k, v)
                .map_err(|e| anyhow::anyhow!("{k}: {e}"))?;
        }
    }
    Ok(c)
}

fn open(c: zenoh::Config) -> anyhow::Result<zenoh::Session> {
    zenoh::open(c)
        .wait()
        .map_err(|e| anyhow::anyhow!("zenoh: {e}"))
}

/// A publisher of `key` as the bridge declares its links' (`Block`, `express`).
fn publisher(
    s: &zenoh::Session,
    key: &'static str,
) -> anyhow::Result<zenoh::pubsub::Publisher<'static>> {
    s.declare_publisher(key)
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))
}

/// The pong: echoes every ping until the ping's session goes (or 120 s).
pub fn pong(connect: &str, transport: Transport) -> anyhow::Result<()> {
    if transport == Transport::Tcp {
        return tcp_pong(connect);
    }
    let lowlatency = transport == Transport::Lowlatency;
    let s = open(config(&[], &[connect.to_string()], lowlatency)?)?;
    let publisher = publisher(&s, PONG)?;
    let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
    let _sub = s
        .declare_subscriber(PING)
        .callback(move |sample| {
            let bytes = sample.payload().to_bytes();
            if bytes.is_empty() {
                let _ = done_tx.send(());
            }
            let _ = publisher.put(bytes.into_owned()).wait();
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let _ = done_rx.recv_timeout(Duration::from_secs(120));
    Ok(())
}

/// The plain TCP pong: echoes `payload`-sized reads until the ping closes.
fn tcp_pong(connect: &str) -> anyhow::Result<()> {
    let addr = connect.trim_start_matches("tcp/");
    let mut s = TcpStream::connect(addr).with_context(|| format!("connect {addr}"))?;
    s.set_nodelay(true)?;
    let mut len = [0_u8; 4];
    s.read_exact(&mut len)?;
    let mut buf = vec![0_u8; u32::from_le_bytes(len) as usize];
    while s.read_exact(&mut buf).is_ok() {
        s.write_all(&buf)?;
    }
    Ok(())
}

/// Starts this program's `zenoh-pong` towards `endpoint`.
fn spawn_pong(endpoint: &str, transport: Transport) -> anyhow::Result<std::process::Child> {
    let exe = std::env::current_exe().context("this program's path")?;
    let t = clap::ValueEnum::to_possible_value(&transport).expect("no skipped variant");
    Command::new(exe)
        .args([
            "zenoh-pong",
            "--connect",
            endpoint,
            "--transport",
            t.get_name(),
        ])
        .stdin(Stdio::null())
        .spawn()
        .context("zenoh-pong")
}

/// Waits at most 5 s for `child` to end, then kills it.
fn reap(mut child: std::process::Child) -> anyhow::Result<()> {
    let deadline = Instant::now() + Duration::from_secs(5);
    while child.try_wait()?.is_none() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = child.kill();
    let _ = child.wait();
    Ok(())
}

/// Round-trip times over plain TCP, µs, in order.
fn tcp_ping(p: Ping) -> anyhow::Result<Vec<f64>> {
    let listener = TcpListener::bind(("127.0.0.1", p.port))?;
    let child = spawn_pong(&format!("tcp/127.0.0.1:{}", p.port), p.transport)?;
    let (mut s, _) = listener.accept()?;
    s.set_nodelay(true)?;
    s.set_read_timeout(Some(Duration::from_secs(5)))?;
    let body = vec![0xA5_u8; p.payload.max(1)];
    s.write_all(&(body.len() as u32).to_le_bytes())?;
    let mut back = vec![0_u8; body.len()];
    let mut rtt = Vec::with_capacity(p.rounds);
    for i in 0..p.warmup + p.rounds {
        let t0 = Instant::now();
        s.write_all(&body)?;
        s.read_exact(&mut back)
            .with_context(|| format!("no pong for round {i}"))?;
        if i >= p.warmup {
            rtt.push(t0.elapsed().as_secs_f64() * 1e6);
        }
    }
    drop(s);
    reap(child)?;
    Ok(rtt)
}

/// Round-trip times, µs, in order.
pub fn ping(p: Ping) -> anyhow::Result<Vec<f64>> {
    if p.transport == Transport::Tcp {
        return tcp_ping(p);
    }
    let endpoint = format!("tcp/127.0.0.1:{}", p.port);
    let lowlatency = p.transport == Transport::Lowlatency;
    let s = open(config(std::slice::from_ref(&endpoint), &[], lowlatency)?)?;
    let replies = s
        .declare_subscriber(PONG)
        .with(zenoh::handlers::FifoChannel::new(64))
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let publisher = publisher(&s, PING)?;
    let child = spawn_pong(&endpoint, p.transport)?;
    let result = rounds(&publisher, &replies, p);
    let _ = publisher.put(Vec::<u8>::new()).wait();
    reap(child)?;
    result
}

fn rounds(
    publisher: &zenoh::pubsub::Publisher<'_>,
    replies: &zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<zenoh::sample::Sample>>,
    p: Ping,
) -> anyhow::Result<Vec<f64>> {
    let body = vec![0xA5_u8; p.payload.max(1)];
    // Until the pong is up: ping every 50 ms, for at most 10 s.
    let up = Instant::now() + Duration::from_secs(10);
    loop {
        publisher
            .put(body.clone())
            .wait()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        if replies
            .recv_timeout(Duration::from_millis(50))
            .ok()
            .flatten()
            .is_some()
        {
            break;
        }
        if Instant::now() > up {
            bail!("zenoh-pong did not answer within 10 s");
        }
    }
    while replies.try_recv().ok().flatten().is_some() {}
    let mut rtt = Vec::with_capacity(p.rounds);
    for i in 0..p.warmup + p.rounds {
        let t0 = Instant::now();
        publisher
            .put(body.clone())
            .wait()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        match replies.recv_timeout(Duration::from_secs(5)) {
            Ok(Some(_)) => {}
            _ => bail!("no pong for round {i} within 5 s"),
        }
        if i >= p.warmup {
            rtt.push(t0.elapsed().as_secs_f64() * 1e6);
        }
    }
    Ok(rtt)
}

/// `p`-quantile of sorted values.
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let i = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[i]
}

/// One Markdown row: payload, transport, rounds, RTT p50 / p90 / p99 /
/// mean, one way (p50 / 2).
#[must_use]
pub fn row(p: &Ping, rtt: &[f64]) -> String {
    let mut s = rtt.to_vec();
    s.sort_by(f64::total_cmp);
    let mean = s.iter().sum::<f64>() / s.len() as f64;
    format!(
        "| {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |",
        p.payload,
        p.transport.name(),
        s.len(),
        quantile(&s, 0.5),
        quantile(&s, 0.9),
        quantile(&s, 0.99),
        mean,
        quantile(&s, 0.5) / 2.0
    )
}

/// The table's header.
pub const HEADER: &str = "| payload B | transport | rounds | RTT p50 µs | p90 µs | p99 µs | mean µs | one way (p50 ÷ 2) µs |\n|---:|---|---:|---:|---:|---:|---:|---:|";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_of_sorted_values() {
        let v: Vec<f64> = (0..=100).map(f64::from).collect();
        assert_eq!(quantile(&v, 0.5), 50.0);
        assert_eq!(quantile(&v, 0.99), 99.0);
        let r = row(
            &Ping {
                payload: 152,
                rounds: 3,
                warmup: 0,
                transport: Transport::Default,
                port: 1,
            },
            &[3.0, 1.0, 2.0],
        );
        assert!(r.starts_with("| 152 | zenoh default | 3 | 2.0 |"), "{r}");
    }
}
