//! The Protobuf messages of a recording, as Rust structs (prost's derive):
//! Foxglove's well-known `foxglove.FrameTransforms` (and the messages it is
//! made of) and attsync's own `attsync.AgentErrors` and `attsync.AgentTorque`.
//!
//! Each struct here has its twin in [`super::descriptor`], which describes the
//! same message (names, field numbers, types) to readers that know nothing of
//! attsync. The two are kept side by side on purpose: a field changed here
//! must be changed there (the test `tests/mcap/read_check.py` decodes every
//! message through the descriptor and would fail).
//!
//! Foxglove's definitions (`schemas/proto/foxglove/*.proto` of
//! foxglove/foxglove-sdk) are matched field for field; the doc lines are ours.

use prost_types::Timestamp;

/// `foxglove.Vector3`: a translation, m.
#[derive(Clone, Copy, PartialEq, prost::Message)]
pub struct Vector3 {
    /// x (field 1).
    #[prost(double, tag = "1")]
    pub x: f64,
    /// y (field 2).
    #[prost(double, tag = "2")]
    pub y: f64,
    /// z (field 3).
    #[prost(double, tag = "3")]
    pub z: f64,
}

/// `foxglove.Quaternion`: a rotation as a unit quaternion `w + xi + yj + zk`.
#[derive(Clone, Copy, PartialEq, prost::Message)]
pub struct Quaternion {
    /// x (field 1).
    #[prost(double, tag = "1")]
    pub x: f64,
    /// y (field 2).
    #[prost(double, tag = "2")]
    pub y: f64,
    /// z (field 3).
    #[prost(double, tag = "3")]
    pub z: f64,
    /// w, the scalar part (field 4).
    #[prost(double, tag = "4")]
    pub w: f64,
}

/// `foxglove.FrameTransform`: where the child frame is in the parent frame
/// (its origin: `translation`; its axes: `rotation`, child → parent).
#[derive(Clone, PartialEq, prost::Message)]
pub struct FrameTransform {
    /// When the transform holds (field 1, `google.protobuf.Timestamp`).
    #[prost(message, optional, tag = "1")]
    pub timestamp: Option<Timestamp>,
    /// The parent frame (field 2).
    #[prost(string, tag = "2")]
    pub parent_frame_id: String,
    /// The child frame (field 3).
    #[prost(string, tag = "3")]
    pub child_frame_id: String,
    /// The child's origin in the parent frame (field 4).
    #[prost(message, optional, tag = "4")]
    pub translation: Option<Vector3>,
    /// The child's orientation in the parent frame (field 5).
    #[prost(message, optional, tag = "5")]
    pub rotation: Option<Quaternion>,
}

/// `foxglove.FrameTransforms`: several transforms in one message.
#[derive(Clone, PartialEq, prost::Message)]
pub struct FrameTransforms {
    /// The transforms (field 1, repeated).
    #[prost(message, repeated, tag = "1")]
    pub transforms: Vec<FrameTransform>,
}

/// `attsync.ObserverErrors`: an agent's observer against the leader.
#[derive(Clone, Copy, PartialEq, prost::Message)]
pub struct ObserverErrors {
    /// `|R̂ᵢ R₀ᵀ|_I ∈ [0, 1]` (field 1).
    #[prost(double, tag = "1")]
    pub att_err: f64,
    /// `‖ω̂ᵢ − ω₀‖`, rad/s (field 2).
    #[prost(double, tag = "2")]
    pub angvel_err: f64,
}

/// `attsync.AgentErrors`: one agent's synchronisation errors at one sample,
/// the values of its `errors.csv` row.
#[derive(Clone, PartialEq, prost::Message)]
pub struct AgentErrors {
    /// The sample's simulated time (field 1).
    #[prost(message, optional, tag = "1")]
    pub timestamp: Option<Timestamp>,
    /// `|Rᵢ R₀ᵀ|_I ∈ [0, 1]` (field 2).
    #[prost(double, tag = "2")]
    pub att_err: f64,
    /// `‖ωᵢ − ω₀‖`, rad/s (field 3).
    #[prost(double, tag = "3")]
    pub angvel_err: f64,
    /// The observer's errors (field 4), absent for the observerless scheme:
    /// a message field has presence in proto3, so "no observer" is not
    /// confused with an error of 0.
    #[prost(message, optional, tag = "4")]
    pub observer: Option<ObserverErrors>,
}

/// `attsync.AgentTorque`: the torque `τᵢ` one agent applied at stage 0 of
/// the sample's step (after its actuator's limits), N·m, body frame, and
/// its norm: the `tau` of its `states.bin` record, NaN at the last sample
/// (no torque follows the last step).
#[derive(Clone, PartialEq, prost::Message)]
pub struct AgentTorque {
    /// The sample's simulated time (field 1).
    #[prost(message, optional, tag = "1")]
    pub timestamp: Option<Timestamp>,
    /// `τᵢ` along the body's x axis, N·m (field 2).
    #[prost(double, tag = "2")]
    pub x: f64,
    /// Along y (field 3).
    #[prost(double, tag = "3")]
    pub y: f64,
    /// Along z (field 4).
    #[prost(double, tag = "4")]
    pub z: f64,
    /// `‖τᵢ‖`, N·m (field 5).
    #[prost(double, tag = "5")]
    pub norm: f64,
}
