//! The scene of a recording: one coordinate frame per body, placed apart so
//! that a 3D view shows every attitude at once, and the messages of one
//! sample ([`transforms`], [`agent_errors`], [`agent_torques`]) stamped
//! with simulated time.
//!
//! # Frames
//! ```text
//! world                 the inertial frame (a body's R maps body → world)
//! ├─ leader             R₀, at the origin
//! ├─ agent-<id>         Rᵢ, on a circle of radius ρ around the origin (plane z = 0)
//! └─ estimate-<id>      R̂ᵢ (observer schemes only), SPACING above agent-<id>
//! ```
//! Agent k of n (in `states.bin` order) sits at angle `2πk/n` on the circle,
//! `ρ = max(SPACING, SPACING · n / 2π)`, so neighbours on the circle are
//! about `SPACING` apart. The positions are a layout for viewing only: the
//! model has attitudes, not positions.

use super::proto::{AgentErrors, AgentTorque, FrameTransform, FrameTransforms, ObserverErrors};
use super::proto::{Quaternion, Vector3};
use crate::results::layout::node_name;
use crate::results::states::{Header, Record};
use attitude::metrics::errors;
use nalgebra::Matrix3;
use prost_types::Timestamp;
use std::f64::consts::TAU;

/// The parent of every frame.
pub const WORLD: &str = "world";
/// Distance between neighbouring bodies of the scene, m.
pub const SPACING: f64 = 3.0;

/// `estimate-<id>`: the frame of agent `id`'s observer `R̂ᵢ`.
#[must_use]
pub fn estimate_frame(id: u32) -> String {
    format!("estimate-{id}")
}

/// The simulated time of `step`, ns from t = 0: `round(step · dt · 10⁹)`.
#[must_use]
pub fn time_ns(step: u64, dt: f64) -> u64 {
    (step as f64 * dt * 1e9).round() as u64
}

/// `time_ns` as a `google.protobuf.Timestamp`.
#[must_use]
pub fn timestamp(ns: u64) -> Timestamp {
    Timestamp {
        seconds: (ns / 1_000_000_000) as i64,
        nanos: (ns % 1_000_000_000) as i32,
    }
}

/// Where agent `k` of `n` sits (see the module's doc), m.
#[must_use]
pub fn agent_position(k: usize, n: usize) -> Vector3 {
    let radius = SPACING.max(SPACING * n as f64 / TAU);
    let angle = TAU * k as f64 / n as f64;
    Vector3 {
        x: radius * angle.cos(),
        y: radius * angle.sin(),
        z: 0.0,
    }
}

/// Where agent `k` of `n`'s estimate sits: `SPACING` above the agent, m.
#[must_use]
pub fn estimate_position(k: usize, n: usize) -> Vector3 {
    Vector3 {
        z: SPACING,
        ..agent_position(k, n)
    }
}

/// The unit quaternion of the row-major rotation `rows` (`q` and `−q` are
/// the same rotation; the sign is the one Shepperd's method gives).
#[must_use]
pub fn quaternion(rows: &[f64; 9]) -> Quaternion {
    let q = attitude::so3::quaternion(&Matrix3::from_row_slice(rows));
    Quaternion {
        x: q.i,
        y: q.j,
        z: q.k,
        w: q.w,
    }
}

/// `world → child` at time `ns`.
fn transform(ns: u64, child: String, at: Vector3, rows: &[f64; 9]) -> FrameTransform {
    FrameTransform {
        timestamp: Some(timestamp(ns)),
        parent_frame_id: WORLD.into(),
        child_frame_id: child,
        translation: Some(at),
        rotation: Some(quaternion(rows)),
    }
}

/// The `/tf` message of one record: world → leader, world → agent-i, and
/// world → estimate-i when the scheme has an observer.
#[must_use]
pub fn transforms(h: &Header, rec: &Record) -> FrameTransforms {
    let ns = time_ns(rec.step, h.dt);
    let origin = Vector3::default();
    let n = h.agent_ids.len();
    let mut all = vec![transform(ns, node_name(0), origin, &rec.leader.r0)];
    for (k, (&id, a)) in h.agent_ids.iter().zip(&rec.agents).enumerate() {
        all.push(transform(ns, node_name(id), agent_position(k, n), &a.r));
        if h.has_observer {
            all.push(transform(
                ns,
                estimate_frame(id),
                estimate_position(k, n),
                &a.r_hat,
            ));
        }
    }
    FrameTransforms { transforms: all }
}

/// The error messages of one record, one per agent in header order: the
/// values `errors.csv` holds (`attitude::metrics::errors`, the paper's
/// Section `simulation`), computed from the same states.
#[must_use]
pub fn agent_errors(h: &Header, rec: &Record) -> Vec<AgentErrors> {
    let ns = time_ns(rec.step, h.dt);
    let leader = rec.leader.state();
    rec.agents
        .iter()
        .map(|a| {
            let e = errors(&a.state(), &leader, h.has_observer);
            AgentErrors {
                timestamp: Some(timestamp(ns)),
                att_err: e.att,
                angvel_err: e.angvel,
                observer: e.observer.map(|(att_err, angvel_err)| ObserverErrors {
                    att_err,
                    angvel_err,
                }),
            }
        })
        .collect()
}

/// The torque messages of one record, one per agent in header order: its
/// `tau` and `‖tau‖` (NaN at the run's last record).
#[must_use]
pub fn agent_torques(h: &Header, rec: &Record) -> Vec<AgentTorque> {
    let ns = time_ns(rec.step, h.dt);
    (rec.agents.iter())
        .map(|a| {
            let [x, y, z] = a.tau;
            AgentTorque {
                timestamp: Some(timestamp(ns)),
                x,
                y,
                z,
                norm: a.torque().norm(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_are_whole_nanoseconds_of_simulated_time() {
        assert_eq!(time_ns(0, 0.001), 0);
        assert_eq!(time_ns(10, 0.001), 10_000_000);
        assert_eq!(time_ns(40_000, 0.001), 40_000_000_000);
        let t = timestamp(40_000_000_123);
        assert_eq!((t.seconds, t.nanos), (40, 123));
    }

    #[test]
    fn agents_are_spaced_on_a_circle_and_estimates_above_them() {
        let n = 7;
        for k in 0..n {
            let (p, q) = (agent_position(k, n), agent_position((k + 1) % n, n));
            let gap = ((p.x - q.x).powi(2) + (p.y - q.y).powi(2)).sqrt();
            assert!(gap > 0.9 * SPACING && gap < 1.1 * SPACING, "gap {gap}");
            let e = estimate_position(k, n);
            assert_eq!((e.x, e.y, e.z), (p.x, p.y, SPACING));
        }
    }

    #[test]
    fn the_quaternion_rotates_like_the_matrix() {
        let r = attitude::so3::rot(
            0.8 * std::f64::consts::PI,
            &nalgebra::Vector3::new(1.0, 4.0, 2.0).normalize(),
        );
        let q = quaternion(&msgs::to_rows(&r));
        let back = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q.w, q.x, q.y, q.z,
        ));
        assert!((back.to_rotation_matrix().matrix() - r).norm() < 1e-12);
    }
}
