//! Shared-memory payloads. Field order is the byte order (`#[repr(C)]`, no
//! implicit padding: every struct is laid out so that offsets are multiples
//! of 8 where an `f64` or `u64` starts). PROTOCOL.md lists the offsets.

use attitude::network::{AgentState, Exchanged};
use attitude::reference::LeaderState;
use iceoryx2::prelude::ZeroCopySend;
use nalgebra::{Matrix3, Vector3};

/// Version of the payload layouts and the stepping rules. A receiver refuses
/// a message whose `version` differs.
pub const PROTOCOL_VERSION: u32 = 2;

/// Row-major copy of a matrix.
#[must_use]
pub fn to_rows(m: &Matrix3<f64>) -> [f64; 9] {
    let t = m.transpose();
    let mut out = [0.0; 9];
    out.copy_from_slice(t.as_slice());
    out
}

/// Matrix from a row-major array.
#[must_use]
pub fn from_rows(a: &[f64; 9]) -> Matrix3<f64> {
    Matrix3::from_row_slice(a)
}

/// A node's exchanged state at one exchange (step, stage): what neighbours
/// and followers of the leader read. Service `attsync/<run>/node/<id>/state`.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("attsync::StateMsg")]
pub struct StateMsg {
    /// [`PROTOCOL_VERSION`].
    pub version: u32,
    /// Sender's node id (0 = leader).
    pub sender: u32,
    /// Integrator step n (the exchange belongs to t = n·dt + c_s·dt).
    pub step: u64,
    /// RKMK4 stage 0..3 within the step.
    pub stage: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Wall-clock time of publication, ns since the Unix epoch (0 if the
    /// sender does not stamp). Only real-time mode reads it, to measure the
    /// age of information; lockstep results never depend on it.
    pub sent_unix_ns: u64,
    /// Attitude (body → inertial), row-major.
    pub r: [f64; 9],
    /// Angular velocity, body frame, rad/s.
    pub w: [f64; 3],
    /// Angular acceleration, rad/s² (0 where the scheme has none).
    pub s: [f64; 3],
}

impl StateMsg {
    /// Stamps `x` as `sender`'s state at `(step, stage)`.
    #[must_use]
    pub fn new(sender: u32, step: u64, stage: u32, x: &Exchanged) -> Self {
        Self {
            version: PROTOCOL_VERSION,
            sender,
            step,
            stage,
            reserved: 0,
            sent_unix_ns: 0,
            r: to_rows(&x.r),
            w: x.w.into(),
            s: x.s.into(),
        }
    }

    /// The same message stamped with the current wall-clock time.
    #[must_use]
    pub fn stamped_now(self) -> Self {
        Self {
            sent_unix_ns: unix_ns_now(),
            ..self
        }
    }

    /// The exchanged state if its values can be trusted: every number
    /// finite and `r` a rotation (`‖rᵀr − I‖_F ≤` [`ROTATION_TOLERANCE`],
    /// `det r > 0`). Values from another process are never used unchecked.
    pub fn validated(&self) -> Result<Exchanged, Invalid> {
        let x = self.exchanged();
        x.trust().map(|()| x)
    }

    /// The exchanged state (exact copy of the sent values).
    #[must_use]
    pub fn exchanged(&self) -> Exchanged {
        Exchanged {
            r: from_rows(&self.r),
            w: Vector3::from(self.w),
            s: Vector3::from(self.s),
        }
    }
}

pub use attitude::network::{ROTATION_TOLERANCE, Untrusted as Invalid};

/// Nanoseconds since the Unix epoch, now (`CLOCK_REALTIME`).
#[must_use]
pub fn unix_ns_now() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// What a telemetry message reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum TelemetryKind {
    /// The node has connected all its ports and waits for `Start`.
    Ready = 1,
    /// The node's state at an output sample (`step` is the step index).
    Sample = 2,
    /// The node has done its last step; `peak_torque` is final. In
    /// real-time mode `w` = [stages started late, largest lateness (wall s), 0].
    Done = 3,
    /// Counters of one incoming link, sent before `Done`: `step` = the
    /// sender's id, `w` = [sent, delivered, lost], `w_hat` = [sum of the age
    /// of information over evaluated stages (s), largest age (s), stages
    /// evaluated], `s_hat[0]` = messages rejected as invalid.
    LinkStats = 4,
    /// The node gives up while stepping, just before it exits: `step` = the
    /// id of the input whose state did not arrive in time, or `u64::MAX`
    /// for any other reason (e.g. a receiver that stopped reading).
    Failed = 5,
}

impl TelemetryKind {
    /// Decodes the wire value.
    #[must_use]
    pub fn from_u32(v: u32) -> Option<Self> {
        match v {
            1 => Some(Self::Ready),
            2 => Some(Self::Sample),
            3 => Some(Self::Done),
            4 => Some(Self::LinkStats),
            5 => Some(Self::Failed),
            _ => None,
        }
    }
}

/// A node's report to the orchestrator. Service
/// `attsync/<run>/node/<id>/telemetry`.
///
/// For an agent: `r, w` the body, `r_hat, w_hat, s_hat` the observer. For
/// the leader (sender 0): `r = R₀`, `w = ω₀`, `s_hat = σ₀`, the rest zero.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("attsync::TelemetryMsg")]
pub struct TelemetryMsg {
    /// [`PROTOCOL_VERSION`].
    pub version: u32,
    /// Sender's node id.
    pub sender: u32,
    /// Step index of the sample.
    pub step: u64,
    /// [`TelemetryKind`] as `u32`.
    pub kind: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// `Rᵢ` (or `R₀`), row-major.
    pub r: [f64; 9],
    /// `ωᵢ` (or `ω₀`).
    pub w: [f64; 3],
    /// `R̂ᵢ`, row-major.
    pub r_hat: [f64; 9],
    /// `ω̂ᵢ`.
    pub w_hat: [f64; 3],
    /// `σ̂ᵢ` (or `σ₀`).
    pub s_hat: [f64; 3],
    /// Largest ‖τᵢ‖ so far, N·m (0 for the leader).
    pub peak_torque: f64,
}

impl TelemetryMsg {
    /// A message with no state (for `Ready`, or `Done` carrying the peak torque).
    #[must_use]
    pub fn bare(sender: u32, step: u64, kind: TelemetryKind, peak_torque: f64) -> Self {
        Self {
            version: PROTOCOL_VERSION,
            sender,
            step,
            kind: kind as u32,
            reserved: 0,
            r: [0.0; 9],
            w: [0.0; 3],
            r_hat: [0.0; 9],
            w_hat: [0.0; 3],
            s_hat: [0.0; 3],
            peak_torque,
        }
    }

    /// An agent's sample.
    #[must_use]
    pub fn agent(sender: u32, step: u64, x: &AgentState, peak_torque: f64) -> Self {
        Self {
            r: to_rows(&x.r),
            w: x.w.into(),
            r_hat: to_rows(&x.r_hat),
            w_hat: x.w_hat.into(),
            s_hat: x.s_hat.into(),
            ..Self::bare(sender, step, TelemetryKind::Sample, peak_torque)
        }
    }

    /// The leader's sample.
    #[must_use]
    pub fn leader(step: u64, x: &LeaderState) -> Self {
        Self {
            r: to_rows(&x.r0),
            w: x.w0.into(),
            s_hat: x.s0.into(),
            ..Self::bare(0, step, TelemetryKind::Sample, 0.0)
        }
    }

    /// Counters of the link `from` → `sender`.
    #[must_use]
    pub fn link_stats(sender: u32, from: u32, s: &attitude::link::LinkStats) -> Self {
        Self {
            w: [s.sent as f64, s.delivered as f64, s.lost as f64],
            w_hat: [s.age_sum, s.age_max, s.evaluations as f64],
            s_hat: [s.rejected as f64, 0.0, 0.0],
            ..Self::bare(sender, u64::from(from), TelemetryKind::LinkStats, 0.0)
        }
    }

    /// Decodes link counters: (from, stats).
    #[must_use]
    pub fn decode_link_stats(&self) -> (u32, attitude::link::LinkStats) {
        (
            self.step as u32,
            attitude::link::LinkStats {
                sent: self.w[0] as u64,
                delivered: self.w[1] as u64,
                lost: self.w[2] as u64,
                age_sum: self.w_hat[0],
                age_max: self.w_hat[1],
                evaluations: self.w_hat[2] as u64,
                rejected: self.s_hat[0] as u64,
            },
        )
    }

    /// Decodes an agent's state.
    #[must_use]
    pub fn agent_state(&self) -> AgentState {
        AgentState {
            r: from_rows(&self.r),
            w: Vector3::from(self.w),
            r_hat: from_rows(&self.r_hat),
            w_hat: Vector3::from(self.w_hat),
            s_hat: Vector3::from(self.s_hat),
        }
    }

    /// Decodes the leader's state.
    #[must_use]
    pub fn leader_state(&self) -> LeaderState {
        LeaderState {
            r0: from_rows(&self.r),
            w0: Vector3::from(self.w),
            s0: Vector3::from(self.s_hat),
        }
    }
}

/// Orchestrator commands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum ControlCommand {
    /// Every node is ready: begin stepping.
    Start = 1,
    /// Leave: release every port and exit 0.
    Stop = 2,
}

/// A command from the orchestrator to every node. Service
/// `attsync/<run>/control` (history 2: a node that connects late still sees it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("attsync::ControlMsg")]
pub struct ControlMsg {
    /// [`PROTOCOL_VERSION`].
    pub version: u32,
    /// [`ControlCommand`] as `u32`.
    pub command: u32,
    /// For `Start`: the wall-clock time at which simulated time 0 begins,
    /// ns since the Unix epoch (real-time mode paces every node from it;
    /// lockstep ignores it). 0 otherwise.
    pub start_unix_ns: u64,
}

impl ControlMsg {
    /// A command.
    #[must_use]
    pub fn new(command: ControlCommand) -> Self {
        Self {
            version: PROTOCOL_VERSION,
            command: command as u32,
            start_unix_ns: 0,
        }
    }

    /// `Start`, with simulated time 0 at `start_unix_ns`.
    #[must_use]
    pub fn start_at(start_unix_ns: u64) -> Self {
        Self {
            start_unix_ns,
            ..Self::new(ControlCommand::Start)
        }
    }

    /// Decodes the command.
    #[must_use]
    pub fn command(&self) -> Option<ControlCommand> {
        match self.command {
            1 => Some(ControlCommand::Start),
            2 => Some(ControlCommand::Stop),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{align_of, offset_of, size_of};

    #[test]
    fn layouts_are_the_documented_ones() {
        assert_eq!(offset_of!(StateMsg, step), 8);
        assert_eq!(offset_of!(StateMsg, stage), 16);
        assert_eq!(offset_of!(StateMsg, sent_unix_ns), 24);
        assert_eq!(offset_of!(StateMsg, r), 32);
        assert_eq!(offset_of!(StateMsg, w), 104);
        assert_eq!(offset_of!(StateMsg, s), 128);
        assert_eq!(size_of::<StateMsg>(), 152);
        assert_eq!(offset_of!(TelemetryMsg, r), 24);
        assert_eq!(offset_of!(TelemetryMsg, r_hat), 120);
        assert_eq!(offset_of!(TelemetryMsg, peak_torque), 240);
        assert_eq!(size_of::<TelemetryMsg>(), 248);
        assert_eq!(offset_of!(ControlMsg, start_unix_ns), 8);
        assert_eq!(size_of::<ControlMsg>(), 16);
        assert_eq!(align_of::<StateMsg>(), 8);
    }

    #[test]
    fn state_round_trips_bit_exactly() {
        let x = Exchanged {
            r: attitude::so3::rot(0.3, &Vector3::new(0.6, 0.0, 0.8)),
            w: Vector3::new(1.0 / 3.0, -2.0, 1e-300),
            s: Vector3::new(f64::MIN_POSITIVE, 0.1, 7.0),
        };
        let m = StateMsg::new(4, 17, 2, &x);
        assert_eq!(m.exchanged(), x);
        assert_eq!(m.r[1], x.r[(0, 1)]);
        assert_eq!(m.validated(), Ok(x));
    }

    #[test]
    fn untrustworthy_states_are_refused() {
        let x = Exchanged::identity();
        let mut m = StateMsg::new(1, 0, 0, &x);
        m.w[2] = f64::NAN;
        assert_eq!(m.validated(), Err(Invalid::NonFinite));
        let mut m = StateMsg::new(1, 0, 0, &x);
        m.s[0] = f64::INFINITY;
        assert_eq!(m.validated(), Err(Invalid::NonFinite));
        let mut m = StateMsg::new(1, 0, 0, &x);
        m.r[0] = 1.001;
        assert!(matches!(m.validated(), Err(Invalid::NotARotation(d)) if d > 1e-3));
        let mut m = StateMsg::new(1, 0, 0, &x);
        m.r[8] = -1.0; // a reflection is orthogonal but not a rotation
        assert!(matches!(m.validated(), Err(Invalid::NotARotation(_))));
        let mut m = StateMsg::new(1, 0, 0, &x);
        m.r[1] = 1e-9; // round-off is accepted
        assert!(m.validated().is_ok());
    }
}
