//! Shared-memory payloads. Field order is the byte order (`#[repr(C)]`, no
//! implicit padding: every struct is laid out so that offsets are multiples
//! of 8 where an `f64` or `u64` starts). PROTOCOL.md lists the offsets.

use attitude::network::Exchanged;
use iceoryx2::prelude::ZeroCopySend;
use nalgebra::{Matrix3, Vector3};

/// Version of the payload layouts and the stepping rules. A receiver refuses
/// a message whose `version` differs.
pub const PROTOCOL_VERSION: u32 = 3;

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
