//! `attsync-bench ring-node …`: one process of a **bare iceoryx2 lockstep
//! ring** (or, with `--inputs/--outputs`, of a bare lockstep over any given
//! graph). It is started by `attsync-bench run`, never by hand; to try one
//! by hand, start `--n N` of them with the same `--run/--root` and create
//! the file `ROOT/start` once every `ROOT/ready-<i>` exists.
//!
//! It does exactly what an attsync node does per exchange, minus the model:
//! the same per-run namespace ([`msgs::namespace::config`]), the same openers
//! ([`msgs::open::state`], [`msgs::open::wake`]) with a [`Limits`] built here
//! (nodes N, max_fanout 2, state_buffer 64, telemetry_buffer 256), the same
//! 144-byte [`StateMsg`], the same publisher backpressure (`RetryUntilDelivered`,
//! the runtime's [`attsync_agent::backpressure`] pause and retry until the stage timeout) and the same
//! [`attsync_agent::wait::Waiter`]. Per step: 4 exchanges; per exchange:
//! publish, notify the receivers (if the strategy lets them block), then take
//! each input's message, one at a time, and check its (step, stage) stamp.
//!
//! Barriers: (1) readiness like the runtime: both inputs have a publisher and
//! our state service has as many subscribers as we have receivers (bounded);
//! then the node attaches its subscribers (`update_connections`) and creates
//! `ROOT/ready-<i>`; (2) start: it polls (1 ms, like the
//! runtime's control poll) for `ROOT/start`, which the driver creates once
//! every node is ready; (3) finish: after its last exchange it creates
//! `ROOT/done-<i>` and waits until every receiver has also finished (so that
//! its last samples are consumed before its publisher goes away). Every wait
//! is bounded.
//!
//! Output: one line on stdout,
//! `ring-node index=I steps=S start_unix=T0 end_unix=T1 elapsed=E peak_rss_kb=K`
//! (times in seconds; `elapsed` covers the lockstep loop only).

use crate::error::{BenchError, Result};
use attsync_agent::backpressure::{Pacer, retry_until};
use attsync_agent::wait::Waiter;
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PubSub;
use msgs::config::{Contention, WaitStrategy};
use msgs::{Limits, PROTOCOL_VERSION, StateMsg};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// What one ring node does (parsed from the `ring-node` command line).
#[derive(Debug, Clone)]
pub struct RingNode {
    /// Run id: iceoryx2 namespace `attsync/<run>/`, file prefix `as<run>_`.
    pub run: String,
    /// Directory of the run: iceoryx2 root `ROOT/iox/`, barrier files in `ROOT/`.
    pub root: PathBuf,
    /// This node's id (its index on the ring).
    pub index: u32,
    /// Number of nodes.
    pub n: u32,
    /// Integrator steps (4 exchanges each).
    pub steps: u64,
    /// Waiting strategy.
    pub wait: WaitStrategy,
    /// Ids whose state this node reads; default: ring neighbours i−1, i+1 (mod N).
    pub inputs: Option<Vec<u32>>,
    /// Ids that read this node's state; default: ring neighbours i−1, i+1 (mod N).
    pub outputs: Option<Vec<u32>>,
    /// `Limits::max_fanout` of the run; default 2.
    pub max_fanout: usize,
    /// Longest wait for one exchange's inputs, s.
    pub stage_timeout: f64,
    /// Longest wait for each barrier, s.
    pub barrier_timeout: f64,
    /// Longest single sleep on the wake event (default the runtime's 1 ms).
    pub block_slice: Duration,
    /// Who copes with competitors (an adaptive waiter's holds).
    pub contention: Contention,
}

/// What a ring node measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingReport {
    /// Node id.
    pub index: u32,
    /// Steps done.
    pub steps: u64,
    /// Wall-clock time at the start of the lockstep loop, s since the epoch.
    pub start_unix: f64,
    /// Wall-clock time at its end, s since the epoch.
    pub end_unix: f64,
    /// Duration of the lockstep loop (monotonic clock), s.
    pub elapsed: f64,
    /// Peak resident set size (VmHWM), kB.
    pub peak_rss_kb: u64,
}

impl RingReport {
    /// The stdout line.
    #[must_use]
    pub fn line(&self) -> String {
        format!(
            "ring-node index={} steps={} start_unix={:.6} end_unix={:.6} elapsed={:.6} peak_rss_kb={}",
            self.index, self.steps, self.start_unix, self.end_unix, self.elapsed, self.peak_rss_kb
        )
    }

    /// Parses [`RingReport::line`].
    #[must_use]
    pub fn parse(line: &str) -> Option<Self> {
        let mut r = Self {
            index: 0,
            steps: 0,
            start_unix: 0.0,
            end_unix: 0.0,
            elapsed: 0.0,
            peak_rss_kb: 0,
        };
        let mut seen = 0;
        for tok in line.strip_prefix("ring-node ")?.split_whitespace() {
            let (k, v) = tok.split_once('=')?;
            match k {
                "index" => r.index = v.parse().ok()?,
                "steps" => r.steps = v.parse().ok()?,
                "start_unix" => r.start_unix = v.parse().ok()?,
                "end_unix" => r.end_unix = v.parse().ok()?,
                "elapsed" => r.elapsed = v.parse().ok()?,
                "peak_rss_kb" => r.peak_rss_kb = v.parse().ok()?,
                _ => return None,
            }
            seen += 1;
        }
        (seen == 6).then_some(r)
    }
}

/// Barrier file names under the run directory.
pub mod files {
    /// Created by node `i` once it is connected.
    #[must_use]
    pub fn ready(i: u32) -> String {
        format!("ready-{i}")
    }
    /// Created by the driver once every node is ready.
    pub const START: &str = "start";
    /// Created by node `i` after its last exchange.
    #[must_use]
    pub fn done(i: u32) -> String {
        format!("done-{i}")
    }
}

fn unix_now() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// Polls (every millisecond) until `cond` holds; `Err` after `timeout`.
fn poll_until(
    timeout: Duration,
    what: impl Fn() -> String,
    mut cond: impl FnMut() -> bool,
) -> Result<()> {
    let deadline = Instant::now() + timeout;
    while !cond() {
        if Instant::now() > deadline {
            return Err(BenchError::Timeout {
                seconds: timeout.as_secs_f64(),
                what: format!("waiting for {}", what()),
            });
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    Ok(())
}

fn touch(path: &Path) -> Result<()> {
    std::fs::write(path, b"").map_err(BenchError::io(path))
}

/// A ring node's ports, opened exactly as the node runtime opens them.
struct Ports {
    /// Our state service (its subscriber count is the readiness condition).
    own: PubSub<ipc::Service, StateMsg, ()>,
    publisher: Publisher<ipc::Service, StateMsg, ()>,
    /// Paces `publisher` while a receiver's buffer is full.
    pacer: Pacer,
    listener: Listener<ipc::Service>,
    /// One per input, in input order.
    subs: Vec<Subscriber<ipc::Service, StateMsg, ()>>,
    input_services: Vec<PubSub<ipc::Service, StateMsg, ()>>,
    /// The wake events of our receivers.
    notifiers: Vec<Notifier<ipc::Service>>,
}

impl Ports {
    fn open(
        node: &Node<ipc::Service>,
        run: &str,
        id: u32,
        io: (&[u32], &[u32]),
        limits: &Limits,
        stage_timeout: Duration,
    ) -> Result<Self> {
        let (inputs, outputs) = io;
        let own = msgs::open::state(node, run, id, limits).map_err(BenchError::iox_msg("state"))?;
        let pacer = Pacer::new(limits.state_buffer);
        let publisher = own
            .publisher_builder()
            .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
            .set_backpressure_handler(retry_until(stage_timeout, pacer.clone()))
            .create()
            .map_err(BenchError::iox("state publisher"))?;
        let listener = msgs::open::wake(node, run, id, limits)
            .map_err(BenchError::iox_msg("wake"))?
            .listener_builder()
            .create()
            .map_err(BenchError::iox("wake listener"))?;
        let mut subs = Vec::new();
        let mut input_services = Vec::new();
        for &j in inputs {
            let svc =
                msgs::open::state(node, run, j, limits).map_err(BenchError::iox_msg("state"))?;
            subs.push(
                svc.subscriber_builder()
                    .buffer_size(limits.state_buffer)
                    .create()
                    .map_err(BenchError::iox("state subscriber"))?,
            );
            input_services.push(svc);
        }
        let notifiers = outputs
            .iter()
            .map(|&j| {
                msgs::open::wake(node, run, j, limits)
                    .map_err(BenchError::iox_msg("wake"))?
                    .notifier_builder()
                    .create()
                    .map_err(BenchError::iox("wake notifier"))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            own,
            publisher,
            pacer,
            listener,
            subs,
            input_services,
            notifiers,
        })
    }

    /// Readiness (as in the runtime): every input has a publisher and our
    /// state service has `receivers` subscribers; then the subscribers are
    /// attached to their publishers (as the runtime does before `Ready`).
    fn wait_ready(&self, receivers: usize, barrier: Duration) -> Result<()> {
        poll_until(
            barrier,
            || {
                format!(
                    "connections (receivers {}/{receivers})",
                    self.own.dynamic_config().number_of_subscribers(),
                )
            },
            || {
                self.own.dynamic_config().number_of_subscribers() >= receivers
                    && self
                        .input_services
                        .iter()
                        .all(|s| s.dynamic_config().number_of_publishers() >= 1)
            },
        )?;
        for sub in &self.subs {
            sub.update_connections()
                .map_err(BenchError::iox("connect input"))?;
        }
        Ok(())
    }
}

/// The state a ring node publishes (identity attitude, zero rates).
fn state(id: u32, n: u64, s: u32) -> StateMsg {
    StateMsg {
        version: PROTOCOL_VERSION,
        sender: id,
        step: n,
        stage: s,
        reserved: 0,
        sent_unix_ns: 0,
        r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        w: [0.0; 3],
        s: [0.0; 3],
    }
}

impl RingNode {
    /// The node's inputs and outputs.
    fn topology(&self) -> Result<(Vec<u32>, Vec<u32>)> {
        let ring_mode = self.inputs.is_none() || self.outputs.is_none();
        if ring_mode && self.n < 3 {
            return Err(BenchError::Usage("a ring needs at least 3 nodes".into()));
        }
        if ring_mode && self.index >= self.n {
            return Err(BenchError::Usage(format!(
                "index {} not below n = {}",
                self.index, self.n
            )));
        }
        let ring = vec![
            (self.index + self.n - 1) % self.n,
            (self.index + 1) % self.n,
        ];
        Ok((
            self.inputs.clone().unwrap_or_else(|| ring.clone()),
            self.outputs.clone().unwrap_or(ring),
        ))
    }

    /// Runs the node: connect, barriers, lockstep loop, finish barrier.
    pub fn run(&self) -> Result<RingReport> {
        let (inputs, outputs) = self.topology()?;
        let (run, id) = (self.run.as_str(), self.index);
        let limits = Limits {
            nodes: self.n as usize,
            max_fanout: self.max_fanout,
            state_buffer: 64,
            telemetry_buffer: 256,
        };
        let barrier = Duration::from_secs_f64(self.barrier_timeout);

        let node = msgs::iox::create_node::<ipc::Service>(
            run,
            &self.root.join("iox"),
            &format!("ring_{id}"),
        )?;
        let stage_timeout = Duration::from_secs_f64(self.stage_timeout);
        let ports = Ports::open(&node, run, id, (&inputs, &outputs), &limits, stage_timeout)?;

        // Readiness barrier, then the start barrier.
        ports.wait_ready(outputs.len(), barrier)?;
        touch(&self.root.join(files::ready(id)))?;
        let start_file = self.root.join(files::START);
        poll_until(barrier, || "the start file".into(), || start_file.exists())?;

        let start_unix = unix_now();
        let t0 = Instant::now();
        self.lockstep(&ports, &inputs)?;
        let elapsed = t0.elapsed().as_secs_f64();
        let end_unix = unix_now();

        // Finish barrier: our receivers have consumed our last messages.
        touch(&self.root.join(files::done(id)))?;
        poll_until(
            barrier,
            || "the receivers to finish".into(),
            || {
                outputs
                    .iter()
                    .all(|&j| self.root.join(files::done(j)).exists())
            },
        )?;
        Ok(RingReport {
            index: id,
            steps: self.steps,
            start_unix,
            end_unix,
            elapsed,
            peak_rss_kb: msgs::telemetry::peak_rss_kb(),
        })
    }

    /// The lockstep loop: per exchange, publish, notify the receivers (if
    /// they may block), then take each input's message and check its stamp.
    fn lockstep(&self, p: &Ports, inputs: &[u32]) -> Result<()> {
        let id = self.index;
        let stage_timeout = Duration::from_secs_f64(self.stage_timeout);
        let mut waiter = Waiter::new(self.wait)
            .with_block_slice(self.block_slice)
            .with_contention(self.contention);
        let notify = waiter.receivers_may_block();
        for n in 0..self.steps {
            for s in 0..4u32 {
                p.publisher
                    .send_copy(state(id, n, s))
                    .map_err(BenchError::iox("state send"))?;
                p.pacer.sent();
                if notify {
                    for nt in &p.notifiers {
                        let _ = nt.notify();
                    }
                }
                let deadline = Instant::now() + stage_timeout;
                waiter.begin();
                for (k, sub) in p.subs.iter().enumerate() {
                    let msg = loop {
                        if let Some(sample) =
                            sub.receive().map_err(BenchError::iox("state receive"))?
                        {
                            break *sample;
                        }
                        if waiter.wait(&p.listener, deadline) {
                            return Err(BenchError::Timeout {
                                seconds: self.stage_timeout,
                                what: format!(
                                    "waiting for node {}'s step {n} stage {s}",
                                    inputs[k]
                                ),
                            });
                        }
                    };
                    let waited = stage_timeout.saturating_sub(deadline - Instant::now());
                    if waited >= self.block_slice && self.block_slice >= Duration::from_millis(100)
                    {
                        // With a long slice, a wait that long means no wake-up came.
                        eprintln!(
                            "ring-node {id}: step {n} stage {s}: waited {:.3} s for node {} (block slice {:.3} s)",
                            waited.as_secs_f64(),
                            inputs[k],
                            self.block_slice.as_secs_f64()
                        );
                    }
                    if msg.version != PROTOCOL_VERSION
                        || msg.sender != inputs[k]
                        || (msg.step, msg.stage) != (n, s)
                    {
                        return Err(BenchError::Protocol(format!(
                            "node {} sent sender {} step {} stage {} where step {n} stage {s} was due",
                            inputs[k], msg.sender, msg.step, msg.stage
                        )));
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_line_round_trips() {
        let r = RingReport {
            index: 3,
            steps: 40000,
            start_unix: 1_700_000_000.123_456,
            end_unix: 1_700_000_004.5,
            elapsed: 4.376_544,
            peak_rss_kb: 4321,
        };
        assert_eq!(RingReport::parse(&r.line()), Some(r));
        assert_eq!(RingReport::parse("ring-node index=1"), None);
    }

    #[test]
    fn ring_neighbours_wrap() {
        let node = RingNode {
            run: "x".into(),
            root: PathBuf::from("/nonexistent"),
            index: 0,
            n: 8,
            steps: 1,
            wait: WaitStrategy::Block,
            inputs: None,
            outputs: None,
            max_fanout: 2,
            stage_timeout: 1.0,
            barrier_timeout: 1.0,
            block_slice: Duration::from_millis(1),
            contention: Contention::Placement,
        };
        assert_eq!(node.topology().unwrap(), (vec![7, 1], vec![7, 1]));
    }
}
