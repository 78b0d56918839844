//! Telemetry: what a node reports to the orchestrator, as a typed
//! [`Telemetry`] value, and its wire form [`TelemetryMsg`]. Encoding
//! ([`TelemetryMsg::encode`]) and decoding ([`TelemetryMsg::decode`]) sit
//! side by side; PROTOCOL.md § 5 gives the same byte layout per kind.
//!
//! The wire form is a 16-byte header (`version`, `sender`, `kind`,
//! `reserved`) and a 232-byte body whose layout depends on the kind. Every
//! counter is a `u64`, every quantity an `f64`, every code a `u32`: nothing
//! travels as another type, and unused bytes are 0.

use crate::payload::{PROTOCOL_VERSION, from_rows, to_rows};
use attitude::guard::Quantity;
use attitude::link::LinkStats;
use attitude::network::AgentState;
use attitude::reference::LeaderState;
use iceoryx2::prelude::ZeroCopySend;
use nalgebra::Vector3;
use thiserror::Error;

/// Bytes of the body of a [`TelemetryMsg`].
pub const BODY_BYTES: usize = 232;

/// A node's report to the orchestrator, decoded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Telemetry {
    /// The node has connected all its ports and waits for `Start`.
    Ready,
    /// An agent's state at the start of step `step`.
    Sample {
        /// Step index n (the state at t = n·dt).
        step: u64,
        /// The body and observer state.
        state: AgentState,
        /// Largest ‖τᵢ‖ applied so far, N·m.
        peak_torque: f64,
    },
    /// The torque an agent applied at stage 0 of step `step` (t = n·dt,
    /// from the step's start state), sent once that stage was evaluated,
    /// at sampled steps before the last; optional (a node that never
    /// sends it has its torques recorded as NaN).
    Torque {
        /// Step index n.
        step: u64,
        /// `τᵢ` after the actuator's limits, N·m, body frame.
        tau: Vector3<f64>,
    },
    /// The leader's state at the start of step `step`.
    LeaderSample {
        /// Step index n.
        step: u64,
        /// `R₀, ω₀, σ₀`.
        state: LeaderState,
    },
    /// Counters of one incoming link, reported before `Done`.
    LinkStats {
        /// The sender of the link.
        from: u32,
        /// Its counters.
        stats: LinkStats,
    },
    /// The node has done its last step.
    Done(Done),
    /// The node gives up while stepping, just before it exits.
    Failed(FailReason),
    /// A built-in agent has reached the step its timeline crashes it at
    /// (PROTOCOL.md § 10.10): its state then, after its links' counters
    /// (`LinkStats`); it publishes nothing more and waits to be killed.
    Crashed {
        /// The step it crashes at.
        step: u64,
        /// Its state at the start of that step.
        state: AgentState,
        /// Largest ‖τᵢ‖ applied so far, N·m.
        peak_torque: f64,
    },
}

impl Telemetry {
    /// Whether this is a periodic report of the trajectory (`Sample`,
    /// `LeaderSample`, `Torque`): sent without waking the orchestrator,
    /// which drains its telemetry often anyway (PROTOCOL.md § 6).
    #[must_use]
    pub fn is_sample(&self) -> bool {
        matches!(
            self,
            Self::Sample { .. } | Self::LeaderSample { .. } | Self::Torque { .. }
        )
    }
}

/// The end of a node's steps.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Done {
    /// Steps done (= the configuration's `steps`).
    pub steps: u64,
    /// Largest ‖τᵢ‖ applied, N·m (0 for the leader).
    pub peak_torque: f64,
    /// Peak resident set size of the node's process (VmHWM), kB; 0 if unknown.
    pub peak_rss_kb: u64,
    /// Wall time at which the node began stepping (after `Start`), ns since the Unix epoch.
    pub started_unix_ns: u64,
    /// Wall time at which it finished its last step, ns since the Unix epoch.
    pub done_unix_ns: u64,
    /// How well the node kept to its schedule (real-time mode; zeros in lockstep).
    pub pacing: Pacing,
}

/// Real-time pacing of one node.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pacing {
    /// Stages started more than one step (dt/factor of wall time) late.
    pub late_stages: u64,
    /// Largest lateness of a stage start, wall s.
    pub max_lateness: f64,
}

/// Why a node gave up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FailReason {
    /// The state of input `from` did not arrive within `stage_timeout`.
    InputTimeout {
        /// The input waited for.
        from: u32,
    },
    /// Input `from` broke the protocol (wrong stamp, version or sender).
    BadInput {
        /// The offending input.
        from: u32,
    },
    /// Anything else (e.g. a receiver that stopped reading its state).
    Other,
    /// The node's own state left the envelope ([`attitude::guard`]) at
    /// the end of step `step - 1` (t = step·dt).
    Diverged {
        /// The step whose state is out (t = step · dt).
        step: u64,
        /// What left the envelope.
        quantity: Quantity,
        /// Its value (a norm, a non-finite entry, or an orthogonality defect).
        value: f64,
    },
}

/// Wire codes of [`Telemetry`] kinds (`kind` field).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum TelemetryKind {
    /// [`Telemetry::Ready`].
    Ready = 1,
    /// [`Telemetry::Sample`].
    Sample = 2,
    /// [`Telemetry::Done`].
    Done = 3,
    /// [`Telemetry::LinkStats`].
    LinkStats = 4,
    /// [`Telemetry::Failed`].
    Failed = 5,
    /// [`Telemetry::LeaderSample`].
    LeaderSample = 6,
    /// [`Telemetry::Torque`].
    Torque = 7,
    /// [`Telemetry::Crashed`].
    Crashed = 8,
}

impl TelemetryKind {
    /// Every kind.
    pub const ALL: [Self; 8] = [
        Self::Ready,
        Self::Sample,
        Self::Done,
        Self::LinkStats,
        Self::Failed,
        Self::LeaderSample,
        Self::Torque,
        Self::Crashed,
    ];

    /// The kind whose wire code is `code` (`None`: no kind has it).
    #[must_use]
    pub fn of_code(code: u32) -> Option<Self> {
        Self::ALL.into_iter().find(|&k| k as u32 == code)
    }

    fn of(t: &Telemetry) -> Self {
        match t {
            Telemetry::Ready => Self::Ready,
            Telemetry::Sample { .. } => Self::Sample,
            Telemetry::Torque { .. } => Self::Torque,
            Telemetry::LeaderSample { .. } => Self::LeaderSample,
            Telemetry::LinkStats { .. } => Self::LinkStats,
            Telemetry::Done(_) => Self::Done,
            Telemetry::Failed(_) => Self::Failed,
            Telemetry::Crashed { .. } => Self::Crashed,
        }
    }
}

/// Wire codes of [`FailReason`]s.
const REASON_INPUT_TIMEOUT: u32 = 1;
const REASON_BAD_INPUT: u32 = 2;
const REASON_OTHER: u32 = 3;
const REASON_DIVERGED: u32 = 4;

/// The wire code of a diverged [`Quantity`] (`Failed` reason 4, field
/// `quantity` at offset 32; PROTOCOL.md § 5). The one mapping between the
/// two: [`quantity_of_code`] is its inverse.
#[must_use]
pub fn quantity_code(q: Quantity) -> u32 {
    match q {
        Quantity::R => 1,
        Quantity::Omega => 2,
        Quantity::RHat => 3,
        Quantity::OmegaHat => 4,
        Quantity::SigmaHat => 5,
        Quantity::R0 => 6,
        Quantity::Omega0 => 7,
        Quantity::Sigma0 => 8,
    }
}

/// The [`Quantity`] of wire code `code` (`None`: no quantity has it); the
/// inverse of [`quantity_code`].
#[must_use]
pub fn quantity_of_code(code: u32) -> Option<Quantity> {
    Quantity::ALL
        .into_iter()
        .find(|&q| quantity_code(q) == code)
}

/// A telemetry message that cannot be decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum TelemetryError {
    /// The sender speaks another protocol version.
    #[error("it speaks protocol version {theirs}, attsync {ours}")]
    Version {
        /// The message's version.
        theirs: u32,
        /// [`PROTOCOL_VERSION`].
        ours: u32,
    },
    /// The `kind` field holds no known kind.
    #[error("unknown telemetry kind {0}")]
    UnknownKind(u32),
    /// A `Failed` message with an unknown reason code.
    #[error("unknown failure reason {0}")]
    UnknownReason(u32),
    /// A `Failed` (diverged) message with an unknown quantity code.
    #[error("unknown diverged quantity {0}")]
    UnknownQuantity(u32),
}

/// A node's report to the orchestrator, as it travels. Service
/// `attsync/<run>/node/<id>/telemetry`. Build it with [`Self::encode`],
/// read it with [`Self::decode`].
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("attsync::TelemetryMsg")]
pub struct TelemetryMsg {
    /// [`PROTOCOL_VERSION`].
    pub version: u32,
    /// Sender's node id.
    pub sender: u32,
    /// [`TelemetryKind`] as `u32`.
    pub kind: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Kind-dependent fields, little-endian (PROTOCOL.md § 5); the byte at
    /// message offset `o` is `body[o − 16]`.
    pub body: [u8; BODY_BYTES],
}

impl TelemetryMsg {
    /// `t` as sent by node `sender`.
    #[must_use]
    pub fn encode(sender: u32, t: &Telemetry) -> Self {
        let mut b = Writer([0; BODY_BYTES]);
        match t {
            Telemetry::Ready => {}
            Telemetry::Sample {
                step,
                state,
                peak_torque,
            }
            | Telemetry::Crashed {
                step,
                state,
                peak_torque,
            } => {
                b.u64(16, *step);
                b.f64s(24, &to_rows(&state.r));
                b.f64s(96, state.w.as_slice());
                b.f64s(120, &to_rows(&state.r_hat));
                b.f64s(192, state.w_hat.as_slice());
                b.f64s(216, state.s_hat.as_slice());
                b.f64(240, *peak_torque);
            }
            Telemetry::Torque { step, tau } => {
                b.u64(16, *step);
                b.f64s(24, tau.as_slice());
            }
            Telemetry::LeaderSample { step, state } => {
                b.u64(16, *step);
                b.f64s(24, &to_rows(&state.r0));
                b.f64s(96, state.w0.as_slice());
                b.f64s(120, state.s0.as_slice());
            }
            Telemetry::LinkStats { from, stats } => encode_link_stats(&mut b, *from, stats),
            Telemetry::Done(d) => encode_done(&mut b, d),
            Telemetry::Failed(f) => encode_failed(&mut b, f),
        }
        Self {
            version: PROTOCOL_VERSION,
            sender,
            kind: TelemetryKind::of(t) as u32,
            reserved: 0,
            body: b.0,
        }
    }

    /// The report this message carries.
    pub fn decode(&self) -> Result<Telemetry, TelemetryError> {
        if self.version != PROTOCOL_VERSION {
            return Err(TelemetryError::Version {
                theirs: self.version,
                ours: PROTOCOL_VERSION,
            });
        }
        let b = Reader(&self.body);
        let kind =
            TelemetryKind::of_code(self.kind).ok_or(TelemetryError::UnknownKind(self.kind))?;
        Ok(match kind {
            TelemetryKind::Ready => Telemetry::Ready,
            TelemetryKind::Sample => Telemetry::Sample {
                step: b.u64(16),
                state: agent_state(&b),
                peak_torque: b.f64(240),
            },
            TelemetryKind::Crashed => Telemetry::Crashed {
                step: b.u64(16),
                state: agent_state(&b),
                peak_torque: b.f64(240),
            },
            TelemetryKind::LeaderSample => Telemetry::LeaderSample {
                step: b.u64(16),
                state: LeaderState {
                    r0: from_rows(&b.f64s(24)),
                    w0: Vector3::from(b.f64s(96)),
                    s0: Vector3::from(b.f64s(120)),
                },
            },
            TelemetryKind::Torque => Telemetry::Torque {
                step: b.u64(16),
                tau: Vector3::from(b.f64s(24)),
            },
            TelemetryKind::LinkStats => decode_link_stats(&b),
            TelemetryKind::Done => Telemetry::Done(decode_done(&b)),
            TelemetryKind::Failed => Telemetry::Failed(decode_failed(&b)?),
        })
    }
}

/// The agent state of a `Sample` or `Crashed` body.
fn agent_state(b: &Reader) -> AgentState {
    AgentState {
        r: from_rows(&b.f64s(24)),
        w: Vector3::from(b.f64s(96)),
        r_hat: from_rows(&b.f64s(120)),
        w_hat: Vector3::from(b.f64s(192)),
        s_hat: Vector3::from(b.f64s(216)),
    }
}

fn encode_link_stats(b: &mut Writer, from: u32, s: &LinkStats) {
    b.u32(16, from);
    b.u64(24, s.sent);
    b.u64(32, s.delivered);
    b.u64(40, s.lost);
    b.u64(48, s.rejected);
    b.u64(56, s.evaluations);
    b.f64(64, s.age_sum);
    b.f64(72, s.age_max);
    if let (Some(p50), Some(p99)) = (s.age_p50, s.age_p99) {
        b.u32(20, 1);
        b.f64(80, p50);
        b.f64(88, p99);
    }
}

fn decode_link_stats(b: &Reader) -> Telemetry {
    Telemetry::LinkStats {
        from: b.u32(16),
        stats: LinkStats {
            sent: b.u64(24),
            delivered: b.u64(32),
            lost: b.u64(40),
            rejected: b.u64(48),
            evaluations: b.u64(56),
            age_sum: b.f64(64),
            age_max: b.f64(72),
            age_p50: (b.u32(20) == 1).then(|| b.f64(80)),
            age_p99: (b.u32(20) == 1).then(|| b.f64(88)),
        },
    }
}

fn encode_done(b: &mut Writer, d: &Done) {
    b.u64(16, d.steps);
    b.f64(24, d.peak_torque);
    b.u64(32, d.peak_rss_kb);
    b.u64(40, d.started_unix_ns);
    b.u64(48, d.done_unix_ns);
    b.u64(56, d.pacing.late_stages);
    b.f64(64, d.pacing.max_lateness);
}

fn decode_done(b: &Reader) -> Done {
    Done {
        steps: b.u64(16),
        peak_torque: b.f64(24),
        peak_rss_kb: b.u64(32),
        started_unix_ns: b.u64(40),
        done_unix_ns: b.u64(48),
        pacing: Pacing {
            late_stages: b.u64(56),
            max_lateness: b.f64(64),
        },
    }
}

fn encode_failed(b: &mut Writer, f: &FailReason) {
    let (code, from) = match *f {
        FailReason::InputTimeout { from } => (REASON_INPUT_TIMEOUT, from),
        FailReason::BadInput { from } => (REASON_BAD_INPUT, from),
        FailReason::Other => (REASON_OTHER, 0),
        FailReason::Diverged {
            step,
            quantity,
            value,
        } => {
            b.u64(24, step);
            b.u32(32, quantity_code(quantity));
            b.f64(40, value);
            (REASON_DIVERGED, 0)
        }
    };
    b.u32(16, code);
    b.u32(20, from);
}

fn decode_failed(b: &Reader) -> Result<FailReason, TelemetryError> {
    let from = b.u32(20);
    match b.u32(16) {
        REASON_INPUT_TIMEOUT => Ok(FailReason::InputTimeout { from }),
        REASON_BAD_INPUT => Ok(FailReason::BadInput { from }),
        REASON_OTHER => Ok(FailReason::Other),
        REASON_DIVERGED => Ok(FailReason::Diverged {
            step: b.u64(24),
            quantity: quantity_of_code(b.u32(32))
                .ok_or(TelemetryError::UnknownQuantity(b.u32(32)))?,
            value: b.f64(40),
        }),
        code => Err(TelemetryError::UnknownReason(code)),
    }
}

/// Writes little-endian fields at message offsets (≥ 16) into a body.
struct Writer([u8; BODY_BYTES]);

impl Writer {
    fn put(&mut self, at: usize, bytes: &[u8]) {
        self.0[at - 16..at - 16 + bytes.len()].copy_from_slice(bytes);
    }
    fn u32(&mut self, at: usize, v: u32) {
        self.put(at, &v.to_le_bytes());
    }
    fn u64(&mut self, at: usize, v: u64) {
        self.put(at, &v.to_le_bytes());
    }
    fn f64(&mut self, at: usize, v: f64) {
        self.put(at, &v.to_le_bytes());
    }
    fn f64s(&mut self, at: usize, v: &[f64]) {
        for (k, x) in v.iter().enumerate() {
            self.f64(at + 8 * k, *x);
        }
    }
}

/// Reads little-endian fields at message offsets (≥ 16) from a body.
struct Reader<'a>(&'a [u8; BODY_BYTES]);

impl Reader<'_> {
    fn get<const N: usize>(&self, at: usize) -> [u8; N] {
        let mut out = [0; N];
        out.copy_from_slice(&self.0[at - 16..at - 16 + N]);
        out
    }
    fn u32(&self, at: usize) -> u32 {
        u32::from_le_bytes(self.get(at))
    }
    fn u64(&self, at: usize) -> u64 {
        u64::from_le_bytes(self.get(at))
    }
    fn f64(&self, at: usize) -> f64 {
        f64::from_le_bytes(self.get(at))
    }
    fn f64s<const N: usize>(&self, at: usize) -> [f64; N] {
        std::array::from_fn(|k| self.f64(at + 8 * k))
    }
}

/// Peak resident set size of this process (`VmHWM`), kB; 0 if unknown.
pub use attsync_sched::rusage::peak_rss_kb;

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;
    use std::mem::size_of;

    fn agent_state() -> AgentState {
        AgentState {
            r: attitude::so3::rot(0.3, &Vector3::new(0.6, 0.0, 0.8)),
            w: Vector3::new(1.0 / 3.0, -2.0, 1e-300),
            r_hat: Matrix3::identity(),
            w_hat: Vector3::new(f64::MIN_POSITIVE, 0.1, 7.0),
            s_hat: Vector3::new(-0.0, 5e-324, 1e300),
        }
    }

    #[test]
    fn layout_is_the_documented_one() {
        assert_eq!(size_of::<TelemetryMsg>(), 248);
        assert_eq!(std::mem::offset_of!(TelemetryMsg, body), 16);
        let m = TelemetryMsg::encode(
            3,
            &Telemetry::LinkStats {
                from: 7,
                stats: LinkStats {
                    sent: (1 << 60) + 1, // not representable as f64
                    ..LinkStats::default()
                },
            },
        );
        assert_eq!(m.kind, 4);
        assert_eq!(m.body[0], 7);
        assert_eq!(
            u64::from_le_bytes(m.body[8..16].try_into().unwrap()),
            (1 << 60) + 1
        );
    }

    #[test]
    fn every_kind_round_trips_bit_exactly() {
        let all = [
            Telemetry::Ready,
            Telemetry::Sample {
                step: 17,
                state: agent_state(),
                peak_torque: 2.5,
            },
            Telemetry::Torque {
                step: 40,
                tau: Vector3::new(-0.0, 5e-324, f64::NAN),
            },
            Telemetry::LeaderSample {
                step: u64::MAX,
                state: LeaderState {
                    r0: agent_state().r,
                    w0: Vector3::new(0.1, 0.2, 0.3),
                    s0: Vector3::new(-1.0, 0.0, 1e-10),
                },
            },
            Telemetry::LinkStats {
                from: 2,
                stats: LinkStats {
                    sent: 40_000,
                    delivered: 39_999,
                    lost: 1,
                    age_sum: 0.25,
                    age_max: 1e-3,
                    evaluations: 160_000,
                    rejected: u64::MAX,
                    age_p50: None,
                    age_p99: None,
                },
            },
            Telemetry::LinkStats {
                from: 3,
                stats: LinkStats {
                    age_p50: Some(1.25e-4),
                    age_p99: Some(9.5e-4),
                    ..LinkStats::default()
                },
            },
            Telemetry::Done(Done {
                steps: 40_000,
                peak_torque: 9.75,
                peak_rss_kb: 8_912,
                started_unix_ns: 1_764_600_000_000_000_000,
                done_unix_ns: 1_764_600_001_900_000_000,
                pacing: Pacing {
                    late_stages: 3,
                    max_lateness: 0.007,
                },
            }),
            Telemetry::Failed(FailReason::InputTimeout { from: 5 }),
            Telemetry::Failed(FailReason::BadInput { from: 0 }),
            Telemetry::Failed(FailReason::Other),
            Telemetry::Failed(FailReason::Diverged {
                step: 12,
                quantity: Quantity::SigmaHat,
                value: 3.2e5,
            }),
        ];
        for t in all {
            let m = TelemetryMsg::encode(4, &t);
            assert_eq!(m.sender, 4);
            let back = m.decode().expect("decodes");
            assert_eq!(
                TelemetryMsg::encode(4, &back).body,
                m.body,
                "{t:?} (bit for bit, NaN included)"
            );
            if !matches!(t, Telemetry::Torque { .. }) {
                assert_eq!(back, t, "{t:?}");
            }
        }
    }

    #[test]
    fn a_torque_is_kind_7_with_its_step_at_16_and_tau_at_24() {
        let tau = Vector3::new(0.5, -1.25, 3e-7);
        let m = TelemetryMsg::encode(5, &Telemetry::Torque { step: 90, tau });
        assert_eq!(m.kind, 7);
        assert_eq!(TelemetryKind::of_code(7), Some(TelemetryKind::Torque));
        // The 8 bytes at message offset `o`.
        let at = |o: usize| &m.body[o - 16..o - 8];
        assert_eq!(u64::from_le_bytes(at(16).try_into().unwrap()), 90);
        for (k, x) in tau.iter().enumerate() {
            assert_eq!(f64::from_le_bytes(at(24 + 8 * k).try_into().unwrap()), *x);
        }
        assert!(m.body[48 - 16..].iter().all(|&b| b == 0), "the rest is 0");
        assert_eq!(m.decode(), Ok(Telemetry::Torque { step: 90, tau }));
        assert!(Telemetry::Torque { step: 90, tau }.is_sample());
        assert!(!Telemetry::Ready.is_sample());
    }

    #[test]
    fn every_kind_has_its_own_code() {
        for (k, kind) in TelemetryKind::ALL.into_iter().enumerate() {
            assert_eq!(kind as u32, k as u32 + 1);
            assert_eq!(TelemetryKind::of_code(kind as u32), Some(kind));
        }
        assert_eq!(TelemetryKind::of_code(0), None);
        assert_eq!(TelemetryKind::of_code(9), None);
    }

    #[test]
    fn foreign_versions_kinds_and_reasons_are_refused() {
        let mut m = TelemetryMsg::encode(1, &Telemetry::Ready);
        m.version = 2;
        assert_eq!(
            m.decode(),
            Err(TelemetryError::Version {
                theirs: 2,
                ours: PROTOCOL_VERSION
            })
        );
        let mut m = TelemetryMsg::encode(1, &Telemetry::Ready);
        m.kind = 9;
        assert_eq!(m.decode(), Err(TelemetryError::UnknownKind(9)));
        let mut m = TelemetryMsg::encode(1, &Telemetry::Failed(FailReason::Other));
        m.body[0] = 77;
        assert_eq!(m.decode(), Err(TelemetryError::UnknownReason(77)));
        let diverged = FailReason::Diverged {
            step: 1,
            quantity: Quantity::R,
            value: f64::NAN,
        };
        let mut m = TelemetryMsg::encode(1, &Telemetry::Failed(diverged));
        assert_eq!(m.body[16], 1, "quantity code at offset 32");
        m.body[16] = 99;
        assert_eq!(m.decode(), Err(TelemetryError::UnknownQuantity(99)));
    }

    #[test]
    fn quantity_codes_are_a_bijection_onto_protocol_codes_1_to_8() {
        // PROTOCOL.md § 5: 1 r, 2 omega, 3 r_hat, 4 omega_hat, 5 sigma_hat,
        // 6 r0, 7 omega0, 8 sigma0.
        let names: Vec<&str> = (1..=8)
            .map(|c| quantity_of_code(c).expect("a quantity per code").name())
            .collect();
        assert_eq!(
            names,
            [
                "r",
                "omega",
                "r_hat",
                "omega_hat",
                "sigma_hat",
                "r0",
                "omega0",
                "sigma0"
            ]
        );
        let codes: std::collections::BTreeSet<u32> =
            Quantity::ALL.into_iter().map(quantity_code).collect();
        assert_eq!(
            codes.len(),
            Quantity::ALL.len(),
            "two quantities share a code"
        );
        for q in Quantity::ALL {
            assert_eq!(quantity_of_code(quantity_code(q)), Some(q));
        }
        assert_eq!(quantity_of_code(0), None);
        assert_eq!(quantity_of_code(9), None);
    }

    #[test]
    fn a_diverged_failure_carries_its_nan() {
        let m = TelemetryMsg::encode(
            2,
            &Telemetry::Failed(FailReason::Diverged {
                step: 7,
                quantity: Quantity::Omega,
                value: f64::NAN,
            }),
        );
        assert_eq!(m.body[0], 4, "reason 4 at offset 16");
        assert_eq!(u64::from_le_bytes(m.body[8..16].try_into().unwrap()), 7);
        match m.decode() {
            Ok(Telemetry::Failed(FailReason::Diverged {
                step: 7,
                quantity: Quantity::Omega,
                value,
            })) => assert!(value.is_nan()),
            other => panic!("{other:?}"),
        }
    }
}
