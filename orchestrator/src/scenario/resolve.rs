//! Scenario → [`Network`]: converts units and representations, and checks
//! everything the paper assumes before anything runs. Every problem is an
//! [`Issue`] naming the field (TOML path, 0-based array index) and the reason.

use super::schema::LossSpec;
use super::schema::{CouplingKind, MatrixSpec, ReferenceKind, RotationSpec, Scenario, SchemeKind};
use attitude::body::Inertia;
use attitude::checks::{
    appendix_d_min_eigenvalue, has_distinct_eigenvalues, is_spd, p_is_admissible, sym_eigenvalues,
    xi_plus_laplacian,
};
use attitude::control::ControlGains;
use attitude::link::{LinkModel, Loss, link_seed};
use attitude::network::{AgentModel, AgentSpec, AgentState, Coupling, Neighbour, Network, Scheme};
use attitude::observer::ObserverGains;
use attitude::reference::LeaderState;
use attitude::so3::{orthogonality_defect, rot};
use nalgebra::{DMatrix, Matrix3, Quaternion, UnitQuaternion, Vector3};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;

/// One problem in a scenario: the field and what is wrong with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Issue {
    /// TOML path, e.g. `edge[2].gain` (arrays 0-based, in file order).
    pub field: String,
    /// Why it is wrong.
    pub reason: String,
}

impl fmt::Display for Issue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.reason)
    }
}

/// A validated scenario, ready to run.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The network every engine runs.
    pub network: Network,
    /// Problems that do not stop a run (e.g. the gain condition of Appendix D).
    pub warnings: Vec<Issue>,
    /// Follower edges as agent-id pairs (smaller id first), in file order.
    pub edges: Vec<(u32, u32)>,
    /// Agents that hear the leader, ascending.
    pub leader_links: Vec<u32>,
    /// Eigenvalues of `Ξ + LLᵀ`, ascending.
    pub spectrum: Vec<f64>,
    /// Smallest eigenvalue of Appendix D's `F` (scheme 1 only).
    pub appendix_d_min_eig: Option<f64>,
    /// Agents run by the user's own programs.
    pub plugins: Vec<super::plugin::Plugin>,
}

#[derive(Default)]
struct Ctx {
    errors: Vec<Issue>,
    warnings: Vec<Issue>,
}

impl Ctx {
    fn err(&mut self, field: impl Into<String>, reason: impl Into<String>) {
        self.errors.push(Issue {
            field: field.into(),
            reason: reason.into(),
        });
    }

    fn warn(&mut self, field: impl Into<String>, reason: impl Into<String>) {
        self.warnings.push(Issue {
            field: field.into(),
            reason: reason.into(),
        });
    }

    fn finite(&mut self, field: &str, x: f64) -> bool {
        if x.is_finite() {
            true
        } else {
            self.err(field, format!("must be a finite number, got {x}"));
            false
        }
    }

    fn positive(&mut self, field: &str, x: f64) -> f64 {
        if self.finite(field, x) && x <= 0.0 {
            self.err(field, format!("must be > 0, got {x}"));
        }
        x
    }

    fn vec3(&mut self, field: &str, v: &[f64; 3]) -> Vector3<f64> {
        if v.iter().any(|x| !x.is_finite()) {
            self.err(field, format!("must hold finite numbers, got {v:?}"));
        }
        Vector3::from(*v)
    }

    fn matrix(&mut self, field: &str, m: &MatrixSpec) -> Option<Matrix3<f64>> {
        let m = match m {
            MatrixSpec::Diagonal(d) => Matrix3::from_diagonal(&Vector3::from(*d)),
            MatrixSpec::Rows(r) => rows(r),
        };
        if m.iter().any(|x| !x.is_finite()) {
            self.err(field, "must hold finite numbers");
            return None;
        }
        Some(m)
    }

    /// SPD (inertia).
    fn spd(&mut self, field: &str, m: &MatrixSpec, what: &str) -> Option<Matrix3<f64>> {
        let m = self.matrix(field, m)?;
        if !is_spd(&m) {
            self.err(
                field,
                format!("{what} must be symmetric positive definite; eigenvalues of its symmetric part are {:?}", sym_eigenvalues(&((m + m.transpose()) * 0.5))),
            );
            return None;
        }
        Some(m)
    }

    /// SPD with three distinct eigenvalues (every gain matrix A of the paper).
    fn gain(&mut self, field: &str, m: &MatrixSpec) -> Option<Matrix3<f64>> {
        let m = self.spd(field, m, "a gain matrix A")?;
        if !has_distinct_eigenvalues(&m) {
            self.err(
                field,
                format!(
                    "a gain matrix A must have three distinct eigenvalues (the paper's assumption), got {:?}",
                    sym_eigenvalues(&m)
                ),
            );
            return None;
        }
        Some(m)
    }

    fn rotation(&mut self, field: &str, r: &RotationSpec) -> Option<Matrix3<f64>> {
        let angles = [
            r.angle_rad.map(|a| ("angle_rad", a)),
            r.angle_deg.map(|a| ("angle_deg", a.to_radians())),
            r.angle_pi.map(|a| ("angle_pi", a * std::f64::consts::PI)),
        ];
        let angles: Vec<_> = angles.into_iter().flatten().collect();
        let forms = usize::from(r.axis.is_some() || !angles.is_empty())
            + usize::from(r.quaternion.is_some())
            + usize::from(r.matrix.is_some());
        if forms != 1 {
            self.err(
                field,
                "give exactly one of: axis with one of angle_rad/angle_deg/angle_pi; quaternion = [w, x, y, z]; matrix = [[..], [..], [..]]",
            );
            return None;
        }
        if let Some(q) = r.quaternion {
            if q.iter().any(|x| !x.is_finite()) || q.iter().all(|&x| x == 0.0) {
                self.err(format!("{field}.quaternion"), "must be finite and non-zero");
                return None;
            }
            // Scale by the largest component first so that tiny or huge
            // inputs normalise without underflow or overflow.
            let m = q.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            let q = UnitQuaternion::from_quaternion(Quaternion::new(
                q[0] / m,
                q[1] / m,
                q[2] / m,
                q[3] / m,
            ));
            return Some(*q.to_rotation_matrix().matrix());
        }
        if let Some(m) = r.matrix {
            let m = rows(&m);
            if m.iter().any(|x| !x.is_finite()) {
                self.err(format!("{field}.matrix"), "must hold finite numbers");
                return None;
            }
            if orthogonality_defect(&m) > 1e-9 || (m.determinant() - 1.0).abs() > 1e-9 {
                self.err(
                    format!("{field}.matrix"),
                    format!(
                        "is not a rotation: ‖RᵀR − I‖ = {:.3e}, det = {} (need orthogonal, det +1, to 1e-9)",
                        orthogonality_defect(&m),
                        m.determinant()
                    ),
                );
                return None;
            }
            return Some(m);
        }
        let Some(axis) = r.axis else {
            self.err(format!("{field}.axis"), "an angle needs an axis");
            return None;
        };
        if angles.len() != 1 {
            self.err(field, "give exactly one of angle_rad, angle_deg, angle_pi");
            return None;
        }
        let (name, angle) = angles[0];
        if !self.finite(&format!("{field}.{name}"), angle) {
            return None;
        }
        let u = Vector3::from(axis);
        if u.iter().any(|x| !x.is_finite()) || u.amax() == 0.0 {
            self.err(
                format!("{field}.axis"),
                format!("must be finite and non-zero, got {axis:?}"),
            );
            return None;
        }
        Some(rot(angle, &(u / u.amax()).normalize()))
    }

    fn multiple_of_dt(&mut self, field: &str, x: f64, dt: f64) -> Option<u64> {
        if !(self.finite(field, x) && dt > 0.0 && dt.is_finite()) {
            return None;
        }
        if x <= 0.0 {
            self.err(field, format!("must be > 0, got {x}"));
            return None;
        }
        let n = (x / dt).round();
        if n > MAX_STEPS {
            self.err(
                field,
                format!("{x} s is {n:e} steps of simulation.dt = {dt}; at most {MAX_STEPS:e} are allowed"),
            );
            return None;
        }
        if n < 1.0 || (n * dt - x).abs() > 1e-9 * x.max(dt) {
            self.err(
                field,
                format!("must be a whole multiple of simulation.dt = {dt}, got {x}"),
            );
            return None;
        }
        Some(n as u64)
    }
}

/// Most steps a run (or a period) may have: 2⁴⁰ ≈ 1.1e12, far beyond any
/// useful run, well inside u64 and f64's exact integers.
const MAX_STEPS: f64 = 1_099_511_627_776.0;

fn rows(r: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::new(
        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
    )
}

/// Validates `s` and resolves it into a [`Network`]. Returns every error
/// found (not only the first).
pub fn resolve(s: &Scenario) -> Result<Resolved, Vec<Issue>> {
    let mut c = Ctx::default();

    if let Some(name) = &s.name {
        let mut parts = std::path::Path::new(name).components();
        let plain = matches!(
            (parts.next(), parts.next()),
            (Some(std::path::Component::Normal(_)), None)
        );
        if !plain || name.contains(['/', '\\']) {
            c.err(
                "name",
                format!("{name:?} must be a plain directory name (no separators, not . or ..): it names the results directory"),
            );
        }
    }

    // [simulation], [output]
    let dt = s.simulation.dt;
    if c.finite("simulation.dt", dt) && dt <= 0.0 {
        c.err("simulation.dt", format!("must be > 0, got {dt}"));
    }
    let steps = c.multiple_of_dt("simulation.duration", s.simulation.duration, dt);
    let sample_every = c.multiple_of_dt("output.sample_period", s.output.sample_period, dt);
    let coupling = match (s.simulation.coupling, s.simulation.period) {
        (CouplingKind::Continuous, None) => Some(Coupling::Continuous),
        (CouplingKind::Continuous, Some(_)) => {
            c.err(
                "simulation.period",
                "is only used with coupling = \"sampled\"",
            );
            None
        }
        (CouplingKind::Sampled, None) => {
            c.err(
                "simulation.period",
                "is required with coupling = \"sampled\"",
            );
            None
        }
        (CouplingKind::Sampled, Some(p)) => c
            .multiple_of_dt("simulation.period", p, dt)
            .map(|every| Coupling::Sampled { every }),
    };

    // [scheme]
    let kind = s.scheme.kind;
    let control = ControlGains {
        k_r: c.positive("scheme.control.k_r", s.scheme.control.k_r),
        k_w: c.positive("scheme.control.k_omega", s.scheme.control.k_omega),
    };
    let observer = match (&s.scheme.observer, kind) {
        (None, SchemeKind::Observerless) => None,
        (Some(_), SchemeKind::Observerless) => {
            c.warn(
                "scheme.observer",
                "ignored: the observerless scheme has no observer",
            );
            None
        }
        (None, _) => {
            c.err(
                "scheme.observer",
                format!("is required by scheme {}", kind_name(kind)),
            );
            None
        }
        (Some(o), _) => {
            let k_sigma = match (o.k_sigma, kind) {
                (Some(k), SchemeKind::ObserverTimeVarying) => {
                    c.positive("scheme.observer.k_sigma", k)
                }
                (None, SchemeKind::ObserverTimeVarying) => {
                    c.err(
                        "scheme.observer.k_sigma",
                        "is required by scheme observer-time-varying (eq. 7c)",
                    );
                    0.0
                }
                (Some(_), _) => {
                    c.warn(
                        "scheme.observer.k_sigma",
                        "ignored: observer 16a-16b has no σ̂",
                    );
                    0.0
                }
                (None, _) => 0.0,
            };
            Some(ObserverGains {
                k_r: c.positive("scheme.observer.k_r", o.k_r),
                k_w: c.positive("scheme.observer.k_omega", o.k_omega),
                k_sigma,
            })
        }
    };
    let scheme = match (kind, observer) {
        (SchemeKind::ObserverTimeVarying, Some(observer)) => {
            Some(Scheme::ObserverTimeVarying { observer, control })
        }
        (SchemeKind::ObserverConstant, Some(observer)) => {
            Some(Scheme::ObserverConstant { observer, control })
        }
        (SchemeKind::Observerless, _) => Some(Scheme::Observerless { control }),
        _ => None,
    };

    // [leader]
    let l = &s.leader;
    let p = match l.p {
        Some(p) => {
            let m = rows(&p);
            if m.iter().any(|x| !x.is_finite()) {
                c.err("leader.p", "must hold finite numbers");
            } else if (kind == SchemeKind::ObserverTimeVarying
                || l.reference == ReferenceKind::TimeVarying)
                && !p_is_admissible(&m)
            {
                c.err(
                    "leader.p",
                    format!(
                        "violates the paper's condition on P (eq. leader): eigenvalues on the imaginary axis must be simple and non-zero, all others must have negative real part; eigenvalues are {}",
                        fmt_complex(&m)
                    ),
                );
            }
            m
        }
        None => {
            if kind == SchemeKind::ObserverTimeVarying || l.reference == ReferenceKind::TimeVarying
            {
                c.err("leader.p", "is required by a time-varying reference and by scheme observer-time-varying (eq. 7c)");
            }
            Matrix3::zeros()
        }
    };
    let r0 = c.rotation("leader.attitude", &l.attitude);
    let (w0, s0) = match l.reference {
        ReferenceKind::TimeVarying => {
            let w0 = match &l.omega {
                Some(w) => c.vec3("leader.omega", w),
                None => {
                    c.err(
                        "leader.omega",
                        "is required by reference = \"time-varying\"",
                    );
                    Vector3::zeros()
                }
            };
            let s0 = match &l.sigma {
                Some(w) => c.vec3("leader.sigma", w),
                None => {
                    c.err(
                        "leader.sigma",
                        "is required by reference = \"time-varying\"",
                    );
                    Vector3::zeros()
                }
            };
            if kind != SchemeKind::ObserverTimeVarying {
                c.warn(
                    "leader.reference",
                    format!("scheme {} is designed for a constant reference; a time-varying one is not covered by the paper's theorems", kind_name(kind)),
                );
            }
            (w0, s0)
        }
        ReferenceKind::Constant => {
            for (f, v) in [("leader.omega", &l.omega), ("leader.sigma", &l.sigma)] {
                if v.is_some() {
                    c.err(
                        f,
                        "must be absent for reference = \"constant\" (ω₀ = σ₀ = 0)",
                    );
                }
            }
            (Vector3::zeros(), Vector3::zeros())
        }
    };

    // [[agent]]
    let mut ids: BTreeMap<u32, usize> = BTreeMap::new();
    for (k, a) in s.agents.iter().enumerate() {
        if a.id == 0 {
            c.err(format!("agent[{k}].id"), "must be ≥ 1 (id 0 is the leader)");
        } else if let Some(first) = ids.insert(a.id, k) {
            c.err(
                format!("agent[{k}].id"),
                format!("duplicate id {} (also agent[{first}])", a.id),
            );
            ids.insert(a.id, first);
        }
    }
    if s.agents.is_empty() {
        c.err("agent", "at least one [[agent]] is required");
    }
    let mut bodies: BTreeMap<u32, (Inertia, Matrix3<f64>, AgentState)> = BTreeMap::new();
    for (k, a) in s.agents.iter().enumerate() {
        let f = format!("agent[{k}]");
        let j = c.spd(&format!("{f}.inertia"), &a.inertia, "the inertia J");
        let r = c.rotation(&format!("{f}.attitude"), &a.attitude);
        let w = c.vec3(&format!("{f}.omega"), &a.omega);
        let (a_bar, obs) = if kind == SchemeKind::Observerless {
            if a.control_gain.is_some() {
                c.warn(
                    format!("{f}.control_gain"),
                    "ignored by the observerless scheme",
                );
            }
            if a.observer.is_some() {
                c.warn(
                    format!("{f}.observer"),
                    "ignored by the observerless scheme",
                );
            }
            (
                Some(Matrix3::identity()),
                Some((Matrix3::identity(), Vector3::zeros(), Vector3::zeros())),
            )
        } else {
            let a_bar = match &a.control_gain {
                Some(m) => c.gain(&format!("{f}.control_gain"), m),
                None => {
                    c.err(
                        format!("{f}.control_gain"),
                        format!("Āᵢ is required by scheme {}", kind_name(kind)),
                    );
                    None
                }
            };
            let obs = match &a.observer {
                Some(o) => {
                    let rh = c.rotation(&format!("{f}.observer.attitude"), &o.attitude);
                    let wh = c.vec3(&format!("{f}.observer.omega"), &o.omega);
                    let sh = match (&o.sigma, kind) {
                        (Some(sg), SchemeKind::ObserverTimeVarying) => {
                            c.vec3(&format!("{f}.observer.sigma"), sg)
                        }
                        (None, SchemeKind::ObserverTimeVarying) => {
                            c.err(
                                format!("{f}.observer.sigma"),
                                "σ̂ᵢ(0) is required by scheme observer-time-varying",
                            );
                            Vector3::zeros()
                        }
                        (Some(_), _) => {
                            c.warn(
                                format!("{f}.observer.sigma"),
                                "ignored: observer 16a-16b has no σ̂",
                            );
                            Vector3::zeros()
                        }
                        (None, _) => Vector3::zeros(),
                    };
                    rh.map(|rh| (rh, wh, sh))
                }
                None => {
                    c.err(
                        format!("{f}.observer"),
                        format!(
                            "the observer's initial state is required by scheme {}",
                            kind_name(kind)
                        ),
                    );
                    None
                }
            };
            (a_bar, obs)
        };
        if let (Some(j), Some(r), Some(a_bar), Some((r_hat, w_hat, s_hat))) = (j, r, a_bar, obs) {
            bodies.insert(
                a.id,
                (
                    Inertia::new(j),
                    a_bar,
                    AgentState {
                        r,
                        w,
                        r_hat,
                        w_hat,
                        s_hat,
                    },
                ),
            );
        }
    }

    // [[edge]]
    let mut edges: Vec<(u32, u32)> = Vec::new();
    let mut edge_gain: BTreeMap<(u32, u32), Matrix3<f64>> = BTreeMap::new();
    let mut first_edge: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    let mut dsu = Dsu::default();
    for (k, e) in s.edges.iter().enumerate() {
        let f = format!("edge[{k}]");
        let [a, b] = e.agents;
        let mut ok = true;
        for x in [a, b] {
            if !ids.contains_key(&x) {
                c.err(
                    format!("{f}.agents"),
                    format!(
                        "unknown agent id {x}{}",
                        if x == 0 {
                            " (the leader is linked with [[leader_link]], not [[edge]])"
                        } else {
                            ""
                        }
                    ),
                );
                ok = false;
            }
        }
        if a == b {
            c.err(format!("{f}.agents"), format!("self-loop {a}–{a}"));
            ok = false;
        }
        let key = (a.min(b), a.max(b));
        if ok {
            if let Some(first) = first_edge.get(&key) {
                c.err(
                    format!("{f}.agents"),
                    format!("duplicate edge {}–{} (also edge[{first}])", key.0, key.1),
                );
                ok = false;
            }
        }
        let g = c.gain(&format!("{f}.gain"), &e.gain);
        if ok {
            first_edge.insert(key, k);
            if !dsu.union(key.0, key.1) {
                c.err(
                    format!("{f}.agents"),
                    format!("edge {}–{} closes a cycle: the follower graph must be a forest (Assumption 1)", key.0, key.1),
                );
            }
            edges.push(key);
            if let Some(g) = g {
                edge_gain.insert(key, g);
            }
        }
    }

    // [[leader_link]]
    let mut links: BTreeMap<u32, Matrix3<f64>> = BTreeMap::new();
    let mut link_seen: BTreeMap<u32, usize> = BTreeMap::new();
    for (k, l) in s.leader_links.iter().enumerate() {
        let f = format!("leader_link[{k}]");
        let g = c.gain(&format!("{f}.gain"), &l.gain);
        if !ids.contains_key(&l.agent) {
            c.err(
                format!("{f}.agent"),
                format!("unknown agent id {}", l.agent),
            );
            continue;
        }
        if let Some(first) = link_seen.insert(l.agent, k) {
            c.err(
                format!("{f}.agent"),
                format!(
                    "duplicate leader link to agent {} (also leader_link[{first}])",
                    l.agent
                ),
            );
            continue;
        }
        if let Some(g) = g {
            links.insert(l.agent, g);
        }
    }
    if s.leader_links.is_empty() {
        c.err(
            "leader_link",
            "at least one [[leader_link]] is required: no agent hears the leader",
        );
    }

    // Reachability from the leader (Assumption 1).
    let mut adj: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for &(a, b) in &edges {
        adj.entry(a).or_default().push(b);
        adj.entry(b).or_default().push(a);
    }
    let mut reached: BTreeSet<u32> = link_seen.keys().copied().collect();
    let mut stack: Vec<u32> = reached.iter().copied().collect();
    while let Some(x) = stack.pop() {
        for &y in adj.get(&x).map(Vec::as_slice).unwrap_or(&[]) {
            if reached.insert(y) {
                stack.push(y);
            }
        }
    }
    if !s.leader_links.is_empty() {
        for (&id, &k) in &ids {
            if !reached.contains(&id) {
                c.err(
                    format!("agent[{k}]"),
                    format!("agent {id} is not reachable from the leader: no [[leader_link]] in its connected component (Assumption 1)"),
                );
            }
        }
    }

    // Spectrum and Appendix D (only meaningful on a consistent graph).
    let index: BTreeMap<u32, usize> = ids.keys().enumerate().map(|(i, &id)| (id, i)).collect();
    let idx_edges: Vec<(usize, usize)> = edges.iter().map(|(a, b)| (index[a], index[b])).collect();
    let xi: Vec<bool> = ids.keys().map(|id| link_seen.contains_key(id)).collect();
    let f1 = xi_plus_laplacian(ids.len(), &idx_edges, &xi);
    let spectrum = sorted_eigs(&f1);
    let mut appendix_d_min_eig = None;
    if let Some(Scheme::ObserverTimeVarying { observer, .. }) = &scheme {
        if c.errors.is_empty() {
            let m = appendix_d_min_eigenvalue(&f1, observer.k_w, observer.k_sigma, &p);
            appendix_d_min_eig = Some(m);
            if m <= 0.0 {
                c.warn(
                    "scheme.observer",
                    format!("the sufficient gain condition of Theorem 1 fails: the matrix F of Appendix D is not positive definite (smallest eigenvalue {m:.3e}); convergence is not guaranteed (raise k_omega or k_sigma)"),
                );
            }
        }
    }

    let impaired = if dt > 0.0 && dt.is_finite() {
        resolve_network(&mut c, s, dt, &edges, &link_seen)
    } else {
        BTreeMap::new()
    };

    if !c.errors.is_empty() {
        return Err(c.errors);
    }
    let scheme = scheme.expect("no errors");
    let agents = bodies
        .into_iter()
        .map(|(id, (inertia, a_bar, initial))| {
            let mut neighbours: Vec<Neighbour> = edges
                .iter()
                .filter_map(|&(a, b)| {
                    let other = if a == id {
                        b
                    } else if b == id {
                        a
                    } else {
                        return None;
                    };
                    Some(Neighbour {
                        link: impaired.get(&(other, id)).copied(),
                        id: other,
                        a: edge_gain[&(a, b)],
                    })
                })
                .collect();
            neighbours.sort_by_key(|n| n.id);
            AgentSpec {
                model: AgentModel {
                    id,
                    inertia,
                    a_bar,
                    neighbours,
                    leader_gain: links.get(&id).copied(),
                    leader_link: impaired.get(&(0, id)).copied(),
                    scheme,
                    p,
                },
                initial,
            }
        })
        .collect();
    let network = Network {
        agents,
        p,
        leader: LeaderState {
            r0: r0.expect("no errors"),
            w0,
            s0,
        },
        dt,
        steps: steps.expect("no errors"),
        coupling: coupling.expect("no errors"),
        sample_every: sample_every.expect("no errors"),
    };
    Ok(Resolved {
        network,
        warnings: c.warnings,
        edges,
        leader_links: links.keys().copied().collect(),
        spectrum,
        appendix_d_min_eig,
        plugins: Vec::new(),
    })
}

/// Impairments of every directed link (sender, receiver) that has any.
fn resolve_network(
    c: &mut Ctx,
    s: &Scenario,
    dt: f64,
    edges: &[(u32, u32)],
    leader_links: &BTreeMap<u32, usize>,
) -> BTreeMap<(u32, u32), LinkModel> {
    let net = &s.network;
    let mut directed: BTreeSet<(u32, u32)> = BTreeSet::new();
    for &(a, b) in edges {
        directed.insert((a, b));
        directed.insert((b, a));
    }
    for &a in leader_links.keys() {
        directed.insert((0, a));
    }
    let defaults = Impairments::read(
        c,
        "network",
        net.delay,
        net.jitter,
        net.loss.as_ref(),
        net.period,
        dt,
    );
    let mut overrides: BTreeMap<(u32, u32), (usize, Impairments)> = BTreeMap::new();
    for (k, l) in net.links.iter().enumerate() {
        let f = format!("network.link[{k}]");
        if !directed.contains(&(l.from, l.to)) {
            c.err(
                f.clone(),
                format!("{} → {} is not a link of this network (follower edges go both ways; the leader is 0 and only sends to its leader_link agents)", l.from, l.to),
            );
            continue;
        }
        let imp = Impairments::read(c, &f, l.delay, l.jitter, l.loss.as_ref(), l.period, dt);
        if let Some((first, _)) = overrides.insert((l.from, l.to), (k, imp)) {
            c.err(
                f,
                format!(
                    "duplicate override of link {} → {} (also network.link[{first}])",
                    l.from, l.to
                ),
            );
        }
    }
    let mut out = BTreeMap::new();
    for &(from, to) in &directed {
        let o = overrides.get(&(from, to)).map(|(_, i)| i);
        let pick = |f: fn(&Impairments) -> Option<u64>| o.and_then(f).or_else(|| f(&defaults));
        let model = LinkModel {
            delay: pick(|i| i.delay).unwrap_or(0),
            jitter: pick(|i| i.jitter).unwrap_or(0),
            loss: o
                .and_then(|i| i.loss)
                .or(defaults.loss)
                .unwrap_or(Loss::None),
            period: pick(|i| i.period),
            seed: link_seed(net.seed, from, to),
        };
        if model.is_impaired() {
            out.insert((from, to), model);
        }
    }
    out
}

/// Impairments as read from one table, in steps.
#[derive(Debug, Clone, Copy, Default)]
struct Impairments {
    delay: Option<u64>,
    jitter: Option<u64>,
    loss: Option<Loss>,
    period: Option<u64>,
}

impl Impairments {
    fn read(
        c: &mut Ctx,
        f: &str,
        delay: Option<f64>,
        jitter: Option<f64>,
        loss: Option<&LossSpec>,
        period: Option<f64>,
        dt: f64,
    ) -> Self {
        let steps = |c: &mut Ctx, name: &str, x: Option<f64>, zero_ok: bool| -> Option<u64> {
            let x = x?;
            let field = format!("{f}.{name}");
            if zero_ok && x == 0.0 {
                return Some(0);
            }
            c.multiple_of_dt(&field, x, dt)
        };
        let prob = |c: &mut Ctx, field: String, p: f64| -> f64 {
            if !(0.0..=1.0).contains(&p) {
                c.err(field, format!("must be a probability in [0, 1], got {p}"));
            }
            p
        };
        let loss = loss.map(|l| match l {
            LossSpec::Probability(p) => Loss::Bernoulli {
                p: prob(c, format!("{f}.loss"), *p),
            },
            LossSpec::Model(m) => match m.model.as_str() {
                "bernoulli" => Loss::Bernoulli {
                    p: prob(c, format!("{f}.loss.p"), m.p.unwrap_or(0.0)),
                },
                "gilbert-elliott" => {
                    let mut g =
                        |name: &str, v: Option<f64>, default: Option<f64>| match v.or(default) {
                            Some(v) => prob(c, format!("{f}.loss.{name}"), v),
                            None => {
                                c.err(
                                    format!("{f}.loss.{name}"),
                                    "is required by the Gilbert–Elliott model",
                                );
                                0.0
                            }
                        };
                    Loss::GilbertElliott {
                        p_gb: g("p_gb", m.p_gb, None),
                        p_bg: g("p_bg", m.p_bg, None),
                        loss_good: g("loss_good", m.loss_good, Some(0.0)),
                        loss_bad: g("loss_bad", m.loss_bad, Some(1.0)),
                    }
                }
                other => {
                    c.err(
                        format!("{f}.loss.model"),
                        format!("unknown loss model {other:?} (bernoulli, gilbert-elliott)"),
                    );
                    Loss::None
                }
            },
        });
        Self {
            delay: steps(c, "delay", delay, true),
            jitter: steps(c, "jitter", jitter, true),
            loss,
            period: steps(c, "period", period, false),
        }
    }
}

/// The name of a scheme as written in scenario files.
pub fn kind_name(k: SchemeKind) -> &'static str {
    match k {
        SchemeKind::ObserverTimeVarying => "observer-time-varying",
        SchemeKind::ObserverConstant => "observer-constant",
        SchemeKind::Observerless => "observerless",
    }
}

fn sorted_eigs(m: &DMatrix<f64>) -> Vec<f64> {
    if m.nrows() == 0 {
        return Vec::new();
    }
    let mut e: Vec<f64> = m.clone().symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    e
}

fn fmt_complex(m: &Matrix3<f64>) -> String {
    let ev = m.complex_eigenvalues();
    let parts: Vec<String> = ev
        .iter()
        .map(|z| format!("{:.4}{:+.4}i", z.re, z.im))
        .collect();
    parts.join(", ")
}

/// Union–find over agent ids, for the forest check.
#[derive(Default)]
struct Dsu {
    parent: BTreeMap<u32, u32>,
}

impl Dsu {
    fn find(&mut self, x: u32) -> u32 {
        let p = *self.parent.entry(x).or_insert(x);
        if p == x {
            return x;
        }
        let r = self.find(p);
        self.parent.insert(x, r);
        r
    }

    /// Joins the sets of `a` and `b`; `false` if they were already joined.
    fn union(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.parent.insert(ra, rb);
        true
    }
}
