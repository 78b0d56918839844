//! The decimated trajectory the page plays: attitudes as quaternions in
//! fixed point, errors as log-scale integers, at most [`FRAME_RATE`] frames
//! per simulated second and [`MAX_NUMBERS`] numbers in all.

use attitude::engine::Snapshot;
use attitude::metrics::errors;
use attitude::network::{AgentState, Network};
use attitude::reference::LeaderState;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
use serde::Serialize;

/// Most frames per simulated second.
pub const FRAME_RATE: f64 = 25.0;
/// Most numbers (quaternion components and errors) in a view: about 3 MB
/// of JSON at ≤ 6 characters each.
pub const MAX_NUMBERS: u64 = 500_000;
/// Quaternion components are stored as `round(q · QUAT_SCALE)`.
pub const QUAT_SCALE: f64 = 10_000.0;
/// Errors are stored as `round(ERR_SCALE · log10 e)`, `e` at least [`ERR_FLOOR`].
pub const ERR_SCALE: f64 = 100.0;
/// The smallest error stored (an exact zero becomes it).
pub const ERR_FLOOR: f64 = 1e-16;

/// One error curve per agent (`null`: not finite).
pub type Curves = Vec<Vec<Option<i32>>>;

/// The recorded frames (serialised into the page's data).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Frames {
    /// Frame times, s.
    pub t: Vec<f64>,
    /// Per body (leader first, then agents in network order), 4 numbers per
    /// frame: `w, x, y, z` of the attitude (body → inertial) × [`QUAT_SCALE`].
    pub q: Vec<Vec<Option<i32>>>,
    /// Per agent, the observer's `R̂ᵢ` likewise (empty without an observer).
    pub q_hat: Vec<Vec<Option<i32>>>,
    /// `|Rᵢ R₀ᵀ|_I`, per agent per frame.
    pub att: Curves,
    /// `‖ωᵢ − ω₀‖`.
    pub angvel: Curves,
    /// `|R̂ᵢ R₀ᵀ|_I` (empty without an observer).
    pub obs_att: Curves,
    /// `‖ω̂ᵢ − ω₀‖` (empty without an observer).
    pub obs_angvel: Curves,
}

/// Collects [`Frames`] from the snapshots of a run, one in every `stride`,
/// and always the last.
#[derive(Debug, Clone)]
pub struct Collector {
    dt: f64,
    stride: u64,
    seen: u64,
    observer: bool,
    frames: Frames,
    /// The last snapshot if it was not taken (its buffers reused).
    last: Option<(u64, LeaderState, Vec<AgentState>)>,
    last_taken: bool,
}

/// Snapshots between frames for a run of `net`: enough that there are at
/// most [`FRAME_RATE`] frames per simulated second and [`MAX_NUMBERS`] numbers.
#[must_use]
pub fn stride(net: &Network) -> u64 {
    let sample = net.sample_every.max(1);
    let period = sample as f64 * net.dt;
    let by_rate = (1.0 / (FRAME_RATE * period)).ceil().max(1.0) as u64;
    let n = net.agents.len() as u64;
    let per_frame = 4 * (n + 1) + 2 * n + if has_observer(net) { 6 * n } else { 0 };
    let samples = net.steps / sample + 1;
    let by_size = (samples * per_frame).div_ceil(MAX_NUMBERS).max(1);
    by_rate.max(by_size)
}

fn has_observer(net: &Network) -> bool {
    net.agents
        .first()
        .is_some_and(|a| a.model.scheme.has_observer())
}

impl Collector {
    /// A collector for the snapshots of a run of `net`.
    #[must_use]
    pub fn new(net: &Network) -> Self {
        let n = net.agents.len();
        let observer = has_observer(net);
        let per_agent = |on: bool| vec![Vec::new(); if on { n } else { 0 }];
        let frames = Frames {
            t: Vec::new(),
            q: vec![Vec::new(); n + 1],
            q_hat: per_agent(observer),
            att: per_agent(true),
            angvel: per_agent(true),
            obs_att: per_agent(observer),
            obs_angvel: per_agent(observer),
        };
        Self {
            dt: net.dt,
            stride: stride(net),
            seen: 0,
            observer,
            frames,
            last: None,
            last_taken: true,
        }
    }

    /// Takes `snap` if it is on the stride, else keeps a copy in case it is
    /// the last.
    pub fn push(&mut self, snap: &Snapshot<'_>) {
        let on = self.seen % self.stride == 0;
        self.seen += 1;
        self.last_taken = on;
        if on {
            self.take(snap.step, snap.leader, snap.agents);
            return;
        }
        match &mut self.last {
            Some((step, leader, agents)) if agents.len() == snap.agents.len() => {
                (*step, *leader) = (snap.step, *snap.leader);
                agents.copy_from_slice(snap.agents);
            }
            last => *last = Some((snap.step, *snap.leader, snap.agents.to_vec())),
        }
    }

    /// The frames, the last snapshot included.
    #[must_use]
    pub fn finish(mut self) -> Frames {
        if let (false, Some((step, leader, agents))) = (self.last_taken, self.last.take()) {
            self.take(step, &leader, &agents);
        }
        self.frames
    }

    /// Appends the frame of one snapshot.
    fn take(&mut self, step: u64, leader: &LeaderState, agents: &[AgentState]) {
        let f = &mut self.frames;
        let t = crate::results::sample_time(step, self.dt);
        f.t.push(t);
        f.q[0].extend(quaternion(&leader.r0));
        for (k, x) in agents.iter().enumerate() {
            f.q[k + 1].extend(quaternion(&x.r));
            let e = errors(x, leader, self.observer);
            f.att[k].push(log_scaled(e.att));
            f.angvel[k].push(log_scaled(e.angvel));
            if let Some((oa, ow)) = e.observer {
                f.q_hat[k].extend(quaternion(&x.r_hat));
                f.obs_att[k].push(log_scaled(oa));
                f.obs_angvel[k].push(log_scaled(ow));
            }
        }
    }
}

/// `w, x, y, z` of rotation `r` × [`QUAT_SCALE`], rounded (`null`s if `r`
/// is not finite). The sign is the one with `w ≥ 0`; the page flips signs
/// between frames where it interpolates.
fn quaternion(r: &Matrix3<f64>) -> [Option<i32>; 4] {
    if !r.iter().all(|v| v.is_finite()) {
        return [None; 4];
    }
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [q.w, q.i, q.j, q.k].map(|c| Some((s * c * QUAT_SCALE).round() as i32))
}

/// `round(ERR_SCALE · log10 max(e, ERR_FLOOR))`, `None` if `e` is not finite.
fn log_scaled(e: f64) -> Option<i32> {
    e.is_finite()
        .then(|| (ERR_SCALE * e.max(ERR_FLOOR).log10()).round() as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attitudes_and_errors_are_stored_in_fixed_point() {
        assert_eq!(
            quaternion(&Matrix3::identity()),
            [Some(10_000), Some(0), Some(0), Some(0)]
        );
        let half_turn_z = Matrix3::from_diagonal(&[-1.0, -1.0, 1.0].into());
        let q = quaternion(&half_turn_z);
        assert_eq!(q[..3], [Some(0); 3]);
        assert_eq!(q[3].map(i32::abs), Some(10_000));
        assert_eq!(quaternion(&Matrix3::from_element(f64::NAN)), [None; 4]);
        assert_eq!(log_scaled(1e-3), Some(-300));
        assert_eq!(log_scaled(0.0), Some(-1600));
        assert_eq!(log_scaled(f64::NAN), None);
    }

    /// The paper's run for `duration` s, collected.
    fn collected(duration: &str) -> (u64, Frames) {
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenarios/paper/timevarying.toml");
        let set = format!("simulation.duration={duration}");
        let loaded = crate::scenario::load(&file, &[set]).expect("valid");
        let net = &loaded.resolved.network;
        let mut c = Collector::new(net);
        let mut engine = attitude::engine::InProcess::new(net);
        let diverged = engine.run(|snap| {
            c.push(snap);
            true
        });
        assert!(diverged.is_none());
        (stride(net), c.finish())
    }

    #[test]
    fn frames_are_decimated_to_the_frame_rate_and_keep_the_last_sample() {
        // Samples every 10 ms: one in 4 makes 25 frames per second.
        let (k, f) = collected("1");
        assert_eq!(k, 4);
        assert_eq!(f.t.len(), 26);
        assert_eq!((f.t[1], f.t[25]), (0.04, 1.0));
        let (_, f) = collected("1.01");
        assert_eq!(f.t.len(), 27, "the last sample (off the stride) is kept");
        assert_eq!(f.t.last(), Some(&1.01));
        assert_eq!(f.q.len(), 8);
        assert!(f.q.iter().all(|q| q.len() == 4 * 27));
        assert!(f.q_hat.iter().all(|q| q.len() == 4 * 27) && f.q_hat.len() == 7);
        assert!(f.obs_att.iter().all(|e| e.len() == 27));
    }
}
