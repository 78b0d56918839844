//! The linearisation against independent results: Lambert's W for the
//! scalar delay equation, closed-form margins, the nonlinear model's own
//! vector field (finite differences), nalgebra's eigenvalues, the
//! characteristic determinant at the returned roots.

use super::roots::{self, rightmost};
use super::*;
use crate::body::Inertia;
use crate::control::{ControlGains, tau_districontrol};
use crate::link::{LinkModel, Loss};
use crate::network::{AgentModel, AgentSpec, AgentState, Coupling, Exchanged, Neighbour, Network};
use crate::observer::{LeaderInput, ObserverGains, omega_hat_dot_16b};
use crate::reference::LeaderState;
use crate::so3::{exp, rot};
use nalgebra::{Complex, DMatrix, Matrix3, Vector3};

pub(super) const DT: f64 = 0.001;

fn c(re: f64, im: f64) -> Complex<f64> {
    Complex::new(re, im)
}

pub(super) fn diag(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(a, b, c))
}

fn scalar(a0: f64, delayed: &[(f64, f64)]) -> Dde {
    Dde::new(
        DMatrix::from_element(1, 1, a0),
        delayed
            .iter()
            .map(|&(t, a)| (t, DMatrix::from_element(1, 1, a)))
            .collect(),
    )
}

// ------------------------------------------------------------- Lambert W

/// The principal branch `W₀(z)` (`w e^w = z`) by Halley's iteration from
/// the branch-point series `−1 + p − p²/3 + 11p³/72`, `p = √(2(e z + 1))`.
fn lambert_w0(z: Complex<f64>) -> Complex<f64> {
    let p = ((z * std::f64::consts::E + 1.0) * 2.0).sqrt();
    let mut w = p * (p * (p * (11.0 / 72.0) - 1.0 / 3.0) + 1.0) - 1.0;
    for _ in 0..100 {
        let ew = w.exp();
        let f = w * ew - z;
        let w1 = w + 1.0;
        if f.norm() == 0.0 || w1.norm() == 0.0 {
            break;
        }
        let step = f / (ew * w1 - (w + 2.0) * f / (w1 * 2.0));
        w -= step;
        if step.norm() <= 1e-16 * (1.0 + w.norm()) {
            break;
        }
    }
    assert!(
        (w * w.exp() - z).norm() < 1e-13 * (1.0 + z.norm()),
        "W({z}) = {w}"
    );
    w
}

#[test]
fn lambert_w_is_what_it_should_be() {
    // W₀(−1/e) = −1; W₀(e) = 1; W₀(−π/2) = iπ/2.
    assert!((lambert_w0(c(-(-1f64).exp(), 0.0)) - c(-1.0, 0.0)).norm() < 1e-7);
    assert!((lambert_w0(c(std::f64::consts::E, 0.0)) - c(1.0, 0.0)).norm() < 1e-14);
    let w = lambert_w0(c(-std::f64::consts::FRAC_PI_2, 0.0));
    assert!(
        (w - c(0.0, std::f64::consts::FRAC_PI_2)).norm() < 1e-14,
        "{w}"
    );
}

/// `x' = −a x(t − τ)`: `s + a e^{−sτ} = 0`, `sτ e^{sτ} = −aτ`: the rightmost
/// root is `W₀(−aτ)/τ`.
#[test]
fn the_scalar_delay_equation_has_the_lambert_w_roots() {
    let a = 2.0;
    // No delay: −a.
    let f = rightmost(&scalar(0.0, &[(0.0, -a)]), 10_000);
    assert_eq!(f.root, c(-a, 0.0));
    for at in [0.05, 0.1, 0.25, 0.5, 0.8, 1.0, 1.5, 1.6, 3.0] {
        let tau = at / a;
        let want = lambert_w0(c(-at, 0.0)) / tau;
        let f = rightmost(&scalar(0.0, &[(tau, -a)]), 10_000);
        assert!(f.converged, "{at}: {f:?}");
        let got = f.root;
        assert!(
            (got.re - want.re).abs() <= 1e-10 * want.norm()
                && (got.im - want.im.abs()).abs() <= 1e-10 * want.norm(),
            "aτ = {at}: {got} vs W₀ {want}"
        );
        // Unstable exactly beyond aτ = π/2.
        assert_eq!(
            got.re > 0.0,
            at > std::f64::consts::FRAC_PI_2,
            "{at}: {got}"
        );
    }
    // At aτ = 1/e the rightmost root is the double real root −1/τ.
    let tau = 1.0 / (std::f64::consts::E * a);
    let f = rightmost(&scalar(0.0, &[(tau, -a)]), 10_000);
    assert!(
        (f.root.re + 1.0 / tau).abs() <= 1e-6 / tau && f.root.im.abs() <= 1e-6 / tau,
        "{f:?} vs {}",
        -1.0 / tau
    );
}

#[test]
fn the_pure_delay_margin_is_pi_over_2a_and_is_where_the_root_crosses() {
    let a = 2.0;
    let Margin::Crossing { delay, omega, .. } = margin::common_delay(
        &DMatrix::from_element(1, 1, 0.0),
        &DMatrix::from_element(1, 1, -a),
    ) else {
        panic!("a crossing")
    };
    assert!((delay - std::f64::consts::PI / (2.0 * a)).abs() < 1e-14);
    assert!((omega - a).abs() < 1e-13);
    let at = |d: f64| rightmost(&scalar(0.0, &[(d, -a)]), 10_000).root;
    assert!(at(0.98 * delay).re < 0.0 && at(1.02 * delay).re > 0.0);
    let on = at(delay);
    assert!(on.re.abs() < 1e-12 && (on.im - a).abs() < 1e-12, "{on}");
}

// ------------------------------------------------------------- networks

pub(super) fn delay(steps: u64) -> Option<LinkModel> {
    Some(LinkModel {
        delay: steps,
        jitter: 0,
        loss: Loss::None,
        period: None,
        seed: 0,
    })
}

/// One agent: id, inertia, a_bar, neighbours, leader gain.
pub(super) fn agent(
    id: u32,
    j: Matrix3<f64>,
    scheme: Scheme,
    nbrs: Vec<Neighbour>,
    lead: Option<Matrix3<f64>>,
) -> AgentSpec {
    let i = f64::from(id);
    AgentSpec {
        model: AgentModel {
            id,
            inertia: Inertia::new(j),
            a_bar: diag(10.0 + i, 11.0 + i, 12.0 + i),
            neighbours: nbrs,
            leader_gain: lead,
            leader_link: delay(7),
            scheme,
            p: Matrix3::zeros(),
            law: Default::default(),
            timeline: Default::default(),
            effects: None,
        },
        initial: AgentState {
            r: Matrix3::identity(),
            w: Vector3::zeros(),
            r_hat: Matrix3::identity(),
            w_hat: Vector3::zeros(),
            s_hat: Vector3::zeros(),
        },
    }
}

use crate::network::Scheme;

pub(super) fn observerless(k_r: f64, k_w: f64) -> Scheme {
    Scheme::Observerless {
        control: ControlGains { k_r, k_w },
    }
}

pub(super) fn observer(k_r: f64, k_w: f64, kc_r: f64, kc_w: f64) -> Scheme {
    Scheme::ObserverConstant {
        observer: ObserverGains {
            k_r,
            k_w,
            k_sigma: 12.0,
        },
        control: ControlGains {
            k_r: kc_r,
            k_w: kc_w,
        },
    }
}

/// Per-link delays in steps: 2→1, 1→2, 3→2, 2→3.
pub(super) type Delays = [u64; 4];

/// A path 1 — 2 — 3, the leader on 1; the paper's inertias and gains
/// (`Jᵢ = diag(i, i+2, 2i)/10`, `Ǎ_{i,j} = diag(10−m, 9−m, 8−m)`); `rotate`
/// turns every inertia and gain by a fixed rotation (no longer diagonal).
pub(super) fn path3(scheme: Scheme, d: Delays, rotate: bool) -> Network {
    let q = if rotate {
        rot(0.7, &Vector3::new(1.0, -2.0, 0.5).normalize())
    } else {
        Matrix3::identity()
    };
    let t = |m: Matrix3<f64>| q * m * q.transpose();
    let j = |i: f64| t(diag(i / 10.0, (i + 2.0) / 10.0, 2.0 * i / 10.0));
    let a12 = t(diag(9.0, 8.0, 7.0));
    let a23 = t(diag(8.0, 7.0, 6.0));
    let nb = |id, a, link: u64| Neighbour {
        id,
        a,
        link: if link == 0 { None } else { delay(link) },
    };
    let mut agents = vec![
        agent(
            1,
            j(1.0),
            scheme,
            vec![nb(2, a12, d[0])],
            Some(t(diag(6.0, 7.0, 8.0))),
        ),
        agent(
            2,
            j(2.0),
            scheme,
            vec![nb(1, a12, d[1]), nb(3, a23, d[2])],
            None,
        ),
        agent(3, j(3.0), scheme, vec![nb(2, a23, d[3])], None),
    ];
    for a in &mut agents {
        a.model.a_bar = t(a.model.a_bar);
    }
    Network {
        agents,
        p: Matrix3::zeros(),
        leader: LeaderState::constant(rot(
            0.8 * std::f64::consts::PI,
            &Vector3::new(1.0, 4.0, 2.0).normalize(),
        )),
        dt: DT,
        steps: 1000,
        coupling: Coupling::Continuous,
        sample_every: 1,
        guard: Default::default(),
        repoint: Vec::new(),
    }
}

/// The paper's 7-agent graph (edges 1–3, 2–7, 3–5, 3–6, 4–5, leader on 1
/// and 2), every follower link delayed by `steps`.
pub(super) fn paper7(scheme: Scheme, steps: u64) -> Network {
    let edges = [(1u32, 3u32), (2, 7), (3, 5), (3, 6), (4, 5)];
    let mut agents: Vec<AgentSpec> = (1..=7u32)
        .map(|id| {
            let i = f64::from(id);
            let lead = (id <= 2).then(|| diag(5.0 + i, 6.0 + i, 7.0 + i));
            agent(
                id,
                diag(i / 10.0, (i + 2.0) / 10.0, 2.0 * i / 10.0),
                scheme,
                Vec::new(),
                lead,
            )
        })
        .collect();
    for (a, b) in edges {
        let m = f64::from(a.min(b));
        let g = diag(10.0 - m, 9.0 - m, 8.0 - m);
        let link = if steps == 0 { None } else { delay(steps) };
        agents[a as usize - 1]
            .model
            .neighbours
            .push(Neighbour { id: b, a: g, link });
        agents[b as usize - 1]
            .model
            .neighbours
            .push(Neighbour { id: a, a: g, link });
    }
    for a in &mut agents {
        a.model.neighbours.sort_by_key(|n| n.id);
    }
    Network {
        agents,
        p: Matrix3::zeros(),
        leader: LeaderState::constant(Matrix3::identity()),
        dt: DT,
        steps: 1000,
        coupling: Coupling::Continuous,
        sample_every: 1,
        guard: Default::default(),
        repoint: Vec::new(),
    }
}

/// The largest real part of the eigenvalues of `a` by nalgebra's Schur
/// iteration (independent of [`eig`]).
fn nalgebra_rightmost(a: &DMatrix<f64>) -> f64 {
    let s =
        nalgebra::Schur::try_new(a.clone(), 1e-15, 100_000).expect("nalgebra's Schur converges");
    s.complex_eigenvalues()
        .iter()
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The vector field of scheme 3 (the model's own `tau_districontrol` and
/// Euler's equation), at `Rᵢ = R₀ exp(xᵢ^×)`, as `[ẋᵢ ≈ ωᵢ, ω̇ᵢ]` per agent
/// with every link undelayed.
fn districontrol_field(net: &Network, z: &[f64]) -> Vec<f64> {
    let r0 = net.leader.r0;
    let v = |k: usize| Vector3::new(z[3 * k], z[3 * k + 1], z[3 * k + 2]);
    let index = net.index_by_id();
    let mut out = vec![0.0; z.len()];
    for (p, a) in net.agents.iter().enumerate() {
        let m = &a.model;
        let Scheme::Observerless { control } = m.scheme else {
            unreachable!()
        };
        let (x, w) = (v(2 * p), v(2 * p + 1));
        let r = r0 * exp(&x);
        let gains: Vec<Matrix3<f64>> = m.neighbours.iter().map(|n| n.a).collect();
        let nbrs: Vec<Exchanged> = m
            .neighbours
            .iter()
            .map(|n| Exchanged {
                r: r0 * exp(&v(2 * index[&n.id])),
                w: Vector3::zeros(),
                s: Vector3::zeros(),
            })
            .collect();
        let lx = Exchanged {
            r: r0,
            w: Vector3::zeros(),
            s: Vector3::zeros(),
        };
        let leader = m.leader_gain.as_ref().map(|g| LeaderInput { a: g, x: &lx });
        let tau = tau_districontrol(&control, &r, &w, &gains, &nbrs, leader);
        let wdot = crate::body::omega_dot(&m.inertia, &w, &tau);
        let xdot = crate::so3::dexp_inv(&x, &w);
        out[6 * p..6 * p + 3].copy_from_slice(xdot.as_slice());
        out[6 * p + 3..6 * p + 6].copy_from_slice(wdot.as_slice());
    }
    out
}

/// The observer `16a`–`16b` (the model's own `omega_hat_dot_16b`) at
/// `R̂ᵢ = R₀ exp(xᵢ^×)`, every link undelayed.
fn observer_field(net: &Network, z: &[f64]) -> Vec<f64> {
    let r0 = net.leader.r0;
    let v = |k: usize| Vector3::new(z[3 * k], z[3 * k + 1], z[3 * k + 2]);
    let index = net.index_by_id();
    let own = |k: usize| Exchanged {
        r: r0 * exp(&v(2 * k)),
        w: v(2 * k + 1),
        s: Vector3::zeros(),
    };
    let mut out = vec![0.0; z.len()];
    for (p, a) in net.agents.iter().enumerate() {
        let m = &a.model;
        let Scheme::ObserverConstant { observer, .. } = m.scheme else {
            unreachable!()
        };
        let gains: Vec<Matrix3<f64>> = m.neighbours.iter().map(|n| n.a).collect();
        let nbrs: Vec<Exchanged> = m.neighbours.iter().map(|n| own(index[&n.id])).collect();
        let lx = Exchanged {
            r: r0,
            w: Vector3::zeros(),
            s: Vector3::zeros(),
        };
        let leader = m.leader_gain.as_ref().map(|g| LeaderInput { a: g, x: &lx });
        let me = own(p);
        let wdot = omega_hat_dot_16b(&observer, &me, &gains, &nbrs, leader);
        let xdot = crate::so3::dexp_inv(&v(2 * p), &me.w);
        out[6 * p..6 * p + 3].copy_from_slice(xdot.as_slice());
        out[6 * p + 3..6 * p + 6].copy_from_slice(wdot.as_slice());
    }
    out
}

/// The Jacobian of `field` at 0 by central differences.
fn jacobian(n: usize, field: impl Fn(&[f64]) -> Vec<f64>) -> DMatrix<f64> {
    let h = 1e-6;
    let mut jac = DMatrix::zeros(n, n);
    for k in 0..n {
        let mut zp = vec![0.0; n];
        let mut zm = vec![0.0; n];
        zp[k] = h;
        zm[k] = -h;
        let (fp, fm) = (field(&zp), field(&zm));
        for i in 0..n {
            jac[(i, k)] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    jac
}

/// The linear system (every delay 0) is the Jacobian of the model's own
/// vector field, with gains and inertias that are not diagonal.
#[test]
fn the_linearisation_is_the_jacobian_of_the_models_vector_field() {
    for scheme in [observerless(1.9, 1.9), observer(9.0, 14.0, 8.0, 13.0)] {
        let net = path3(scheme, [0, 0, 0, 0], true);
        let lin = Linearisation::of(&net).expect("linearises");
        assert!(!lin.per_axis());
        let sys = lin.systems_at(0.0);
        assert_eq!(sys.len(), 1);
        let a = sys[0].a0().clone();
        assert!(sys[0].delayed().is_empty());
        let jac = if matches!(scheme, Scheme::Observerless { .. }) {
            jacobian(18, |z| districontrol_field(&net, z))
        } else {
            jacobian(18, |z| observer_field(&net, z))
        };
        let err = (&a - &jac).abs().max();
        assert!(err < 1e-6 * a.abs().max(), "{err}\n{a}\n{jac}");
        // The coupling is what the delay acts on: with a delay, A₀ loses it.
        let delayed = &lin.systems_at(0.1)[0];
        assert_eq!(delayed.delayed().len(), 1);
        assert!((delayed.a0() + &delayed.delayed()[0].1 - &a).abs().max() < 1e-12);
        assert!((delayed.a0() - &a).abs().max() > 1.0);
    }
}

/// With diagonal inertias and gains the three per-axis systems give the
/// same roots as the full one.
#[test]
fn per_axis_systems_agree_with_the_full_system() {
    for scheme in [observerless(1.9, 1.9), observer(9.0, 14.0, 8.0, 13.0)] {
        let net = path3(scheme, [5, 10, 20, 0], false);
        let split = Linearisation::of(&net).expect("linearises");
        let full = Linearisation::of_full(&net).expect("linearises");
        assert!(split.per_axis() && !full.per_axis());
        assert_eq!(split.states(), full.states());
        for d in [None, Some(0.0), Some(0.05)] {
            let (s, f) = match d {
                None => (split.rightmost(), full.rightmost()),
                Some(d) => (split.rightmost_at(d), full.rightmost_at(d)),
            };
            assert!(
                (s.re - f.re).abs() < 1e-9 * (1.0 + s.re.abs()),
                "{d:?}: {s} vs {f}"
            );
            assert!(
                (s.im - f.im).abs() < 1e-6 * (1.0 + s.im.abs()),
                "{d:?}: {s} vs {f}"
            );
        }
    }
}

/// At `d = 0` the rightmost root is the rightmost eigenvalue of
/// `A₀ + A₁`, computed by nalgebra.
#[test]
fn without_delay_the_rightmost_root_is_the_rightmost_eigenvalue() {
    for rotate in [false, true] {
        let net = path3(observerless(1.9, 1.9), [5, 10, 20, 0], rotate);
        let lin = Linearisation::of(&net).expect("linearises");
        let want = lin
            .systems_at(0.0)
            .iter()
            .map(|s| nalgebra_rightmost(s.a0()))
            .fold(f64::NEG_INFINITY, f64::max);
        let got = lin.rightmost_at(0.0);
        assert!(
            (got.re - want).abs() < 1e-10 * want.abs(),
            "{got} vs {want}"
        );
        assert!(got.re < 0.0);
    }
}

/// Every returned root is a root of the exact characteristic matrix, and
/// growing delays move the rightmost root right (towards instability).
#[test]
fn returned_roots_are_roots_and_delays_destabilise() {
    let net = path3(observerless(1.9, 1.9), [5, 10, 20, 0], false);
    let lin = Linearisation::of(&net).expect("linearises");
    assert_eq!(lin.states(), 18);
    assert_eq!(lin.delays(), vec![0.0, 0.005, 0.01, 0.02]);
    let r = lin.rightmost_detail();
    assert!(
        r.converged && r.order > roots::MIN_ORDER && r.part == Part::Observerless,
        "{r:?}"
    );
    let sys = &lin.systems()[r.axis.expect("per axis")];
    assert_eq!(sys.delayed().len(), 3);
    assert!(
        sys.residual(r.root.into()) < 1e-13,
        "{}",
        sys.residual(r.root.into())
    );
    assert!(sys.residual(c(r.root.re + 0.1, r.root.im)) > 1e-6);
    let mut last = lin.rightmost_at(0.0).re;
    // Continuous at d → 0 (the discretisation is then very stiff).
    let tiny = lin.rightmost_at(1e-6);
    assert!(
        (tiny.re - last).abs() < 1e-4 * last.abs(),
        "{tiny} vs {last}"
    );
    for d in [0.01, 0.03, 0.06, 0.1] {
        let det = lin.rightmost_detail_at(d);
        let sys = &lin.systems_at(d)[det.axis.expect("per axis")];
        assert!(sys.residual(det.root.into()) < 1e-13, "{d}");
        assert!(det.root.re > last, "{d}: {} after {last}", det.root);
        last = det.root.re;
    }
}

/// The margin: stable just below, unstable just above, on the axis at it.
#[test]
fn the_margin_separates_stable_from_unstable() {
    let nets = [
        (
            "path, scheme 3",
            path3(observerless(1.9, 1.9), [5, 10, 20, 0], false),
        ),
        (
            "path, scheme 3, rotated",
            path3(observerless(1.9, 1.9), [5, 10, 20, 0], true),
        ),
        ("paper, scheme 3", paper7(observerless(1.9, 1.9), 20)),
        (
            "paper, scheme 2",
            paper7(observer(9.0, 14.0, 8.0, 13.0), 20),
        ),
        ("paper, scheme 2, rotated", {
            let mut net = paper7(observer(9.0, 14.0, 8.0, 13.0), 20);
            let q = rot(0.4, &Vector3::new(0.3, 1.0, -1.0).normalize());
            for a in &mut net.agents {
                a.model.inertia = Inertia::new(q * a.model.inertia.j * q.transpose());
                for n in &mut a.model.neighbours {
                    n.a = q * n.a * q.transpose();
                }
            }
            net
        }),
    ];
    for (name, net) in nets {
        let lin = Linearisation::of(&net).expect("linearises");
        let Margin::Crossing {
            delay,
            omega,
            axis_distance,
        } = lin.margin()
        else {
            panic!("{name}: {:?}", lin.margin())
        };
        assert!(axis_distance < 1e-8, "{name}: {axis_distance}");
        assert!(lin.rightmost_at(0.98 * delay).re < 0.0, "{name}: {delay}");
        assert!(lin.rightmost_at(1.02 * delay).re > 0.0, "{name}: {delay}");
        let on = lin.rightmost_at(delay);
        assert!(
            on.re.abs() < 1e-8 && (on.im - omega).abs() < 1e-6 * omega,
            "{name}: {on} vs {omega}"
        );
    }
}

/// The observer on the path (scheme 2) is stable for every delay: no
/// crossing, and the rightmost root stays left of the axis, approaching it
/// like 1/d. A long delay needs a high order (roots line up near the axis
/// up to ω ≈ 25 rad/s): at d = 20 s beyond the size limit, so the root
/// returned is not `converged`.
#[test]
fn a_delay_independent_network() {
    let net = path3(observer(9.0, 14.0, 8.0, 13.0), [5, 10, 20, 0], false);
    let lin = Linearisation::of(&net).expect("linearises");
    assert_eq!(lin.margin(), Margin::DelayIndependent);
    let mut last = f64::NEG_INFINITY;
    for d in [0.5, 1.0, 2.0, 3.0, 5.0] {
        let r = lin.rightmost_detail_at(d);
        assert!(
            r.converged && r.root.re < 0.0 && r.root.re > last,
            "{d}: {r:?}"
        );
        assert!(r.root.re * d > -0.05, "{d}: {r:?}");
        last = r.root.re;
    }
    let r = lin.rightmost_detail_at(20.0);
    assert!(!r.converged, "{r:?}");
}

/// One agent, no neighbour: nothing is delayed, every root is a root of
/// `Jₖ s² + k_ω̌ s + k_Ř Eₖ = 0`, and no delay matters.
#[test]
fn a_lone_agent_has_no_delay() {
    let mut net = paper7(observerless(1.9, 1.9), 20);
    net.agents.truncate(1);
    net.agents[0].model.neighbours.clear();
    let lin = Linearisation::of(&net).expect("linearises");
    assert_eq!(lin.margin(), Margin::DelayIndependent);
    let r = lin.rightmost_detail_at(0.7);
    assert_eq!(r.order, 0);
    let m = &net.agents[0].model;
    let k = r.axis.expect("per axis");
    let (j, e) = (
        m.inertia.j[(k, k)],
        crate::stiffness::psi_gain(&m.leader_gain.expect("leader"))[(k, k)],
    );
    let s = Complex::from(r.root);
    assert!((s * s * j + s * 1.9 + 1.9 * e).norm() < 1e-12, "{s}");
    assert_eq!(lin.rightmost(), r.root);
}

/// Scheme 2's tracking loops are part of the closed loop: slow enough, one
/// of them holds the rightmost root; they are delay-free.
#[test]
fn scheme_2s_tracking_roots_count() {
    let net = path3(observer(9.0, 14.0, 0.05, 0.3), [5, 10, 20, 0], false);
    let lin = Linearisation::of(&net).expect("linearises");
    let r = lin.rightmost_detail();
    assert!(matches!(r.part, Part::Tracking { .. }), "{r:?}");
    // J ε̈ + k_ω̄ ε̇ + k_R̄ e ε = 0: the slowest is the heaviest axis's.
    let Part::Tracking { agent } = r.part else {
        unreachable!()
    };
    let m = &net.agents[net.index_of(agent).expect("agent")].model;
    let k = r.axis.expect("per axis");
    let j = m.inertia.j[(k, k)];
    let e = crate::stiffness::psi_gain(&m.a_bar)[(k, k)];
    let s = Complex::from(r.root);
    assert!((s * s * j + s * 0.3 + 0.05 * e).norm() < 1e-12, "{s}");
    assert_eq!(lin.rightmost_at(0.0), r.root);
    assert_eq!(lin.states(), 36);
}

/// The refusals name what to change.
#[test]
fn refusals() {
    let mut net = path3(observerless(1.9, 1.9), [5, 10, 20, 0], false);
    for a in &mut net.agents {
        a.model.scheme = Scheme::ObserverTimeVarying {
            observer: ObserverGains {
                k_r: 9.0,
                k_w: 14.0,
                k_sigma: 12.0,
            },
            control: ControlGains {
                k_r: 8.0,
                k_w: 13.0,
            },
        };
    }
    let e = Linearisation::of(&net).expect_err("scheme 1");
    assert_eq!(e, LinearError::TimeVarying);
    assert_eq!(e.field(), Some("scheme.kind"));

    let mut net = path3(observerless(1.9, 1.9), [5, 10, 20, 0], false);
    net.coupling = Coupling::Sampled { every: 4 };
    let e = Linearisation::of(&net).expect_err("sampled");
    assert_eq!(e, LinearError::Sampled { every: 4 });
    assert_eq!(e.field(), Some("simulation.coupling"));

    let mut net = path3(observerless(1.9, 1.9), [5, 10, 20, 0], false);
    if let Some(l) = net.agents[1].model.neighbours[1].link.as_mut() {
        l.jitter = 3;
    }
    let e = Linearisation::of(&net).expect_err("jitter");
    assert_eq!(
        e,
        LinearError::Impaired {
            from: 3,
            to: 2,
            what: Impairment::Jitter { steps: 3 }
        }
    );
    assert_eq!(e.field(), Some("network.jitter"));
    assert!(e.to_string().contains("3 → 2"), "{e}");

    let mut net = path3(observerless(1.9, 1.9), [5, 10, 20, 0], false);
    if let Some(l) = net.agents[0].model.neighbours[0].link.as_mut() {
        l.loss = Loss::Bernoulli { p: 0.1 };
    }
    let e = Linearisation::of(&net).expect_err("loss");
    assert_eq!(e.field(), Some("network.loss"));
    assert!(
        matches!(e, LinearError::Impaired { from: 2, to: 1, .. }),
        "{e}"
    );

    let mut net = path3(observerless(1.9, 1.9), [5, 10, 20, 0], false);
    if let Some(l) = net.agents[1].model.neighbours[0].link.as_mut() {
        l.period = Some(10);
    }
    let e = Linearisation::of(&net).expect_err("period");
    assert_eq!(e.field(), Some("network.period"));
    assert!(
        matches!(e, LinearError::Impaired { from: 1, to: 2, .. }),
        "{e}"
    );

    // A leader link's impairments do not matter (constant reference).
    let mut net = path3(observerless(1.9, 1.9), [5, 10, 20, 0], false);
    net.agents[0].model.leader_link = Some(LinkModel {
        delay: 3,
        jitter: 5,
        loss: Loss::Bernoulli { p: 0.5 },
        period: Some(4),
        seed: 1,
    });
    assert!(Linearisation::of(&net).is_ok());

    // Dense matrices for small networks: a chain of 10 agents is per axis
    // n = 20 with p = 10 delayed, 20 + 10·18 = 200 ≤ DENSE_PREFERRED; a
    // chain of 40 (80 + 40·18 = 800) would fit but takes the faster tree
    // path; 60 (120 + 1080) does not fit. Closed into a ring (not a
    // forest), or with gains that are not diagonal (no split into axes),
    // it is refused.
    let small = Linearisation::of(&chain(10, observerless(1.9, 1.9), 3)).expect("dense");
    assert!(!small.on_trees());
    let forty = Linearisation::of(&chain(40, observerless(1.9, 1.9), 3)).expect("tree");
    assert!(forty.on_trees());
    let large = Linearisation::of(&chain(60, observerless(1.9, 1.9), 3)).expect("tree");
    assert!(large.on_trees() && large.per_axis());
    let mut ring = chain(60, observerless(1.9, 1.9), 3);
    let g = ring.agents[0].model.neighbours[0].a;
    let link = ring.agents[0].model.neighbours[0].link;
    ring.agents[0]
        .model
        .neighbours
        .push(Neighbour { id: 60, a: g, link });
    ring.agents[59]
        .model
        .neighbours
        .push(Neighbour { id: 1, a: g, link });
    let too_large = LinearError::TooLarge {
        states: 1200,
        limit: model::DENSE_LIMIT,
    };
    assert_eq!(Linearisation::of(&ring).expect_err("ring"), too_large);
    let mut turned = chain(60, observerless(1.9, 1.9), 3);
    let q = rot(0.4, &Vector3::new(0.3, 1.0, -1.0).normalize());
    turned.agents[5].model.inertia =
        Inertia::new(q * turned.agents[5].model.inertia.j * q.transpose());
    assert_eq!(Linearisation::of(&turned).expect_err("not split"), {
        LinearError::TooLarge {
            states: 360 + 180 * 18,
            limit: model::DENSE_LIMIT,
        }
    });
}

/// A chain 1 — 2 — … — n, the leader on 1, every follower link delayed by
/// `steps`, the paper's inertias.
pub(super) fn chain(n: u32, scheme: Scheme, steps: u64) -> Network {
    let mut net = paper7(scheme, steps);
    net.agents = (1..=n)
        .map(|id| {
            let i = f64::from((id - 1) % 7 + 1);
            let link = if steps == 0 { None } else { delay(steps) };
            let g = diag(10.0 - i, 9.0 - i, 8.0 - i);
            let nbrs = [id - 1, id + 1]
                .into_iter()
                .filter(|&k| k >= 1 && k <= n)
                .map(|k| Neighbour { id: k, a: g, link })
                .collect();
            let lead = (id == 1).then(|| diag(6.0, 7.0, 8.0));
            agent(
                id,
                diag(i / 10.0, (i + 2.0) / 10.0, 2.0 * i / 10.0),
                scheme,
                nbrs,
                lead,
            )
        })
        .collect();
    net
}

/// The paper's 7-agent networks, every link delayed by 20 ms: the rightmost
/// root is a root, and the margin separates stability from instability.
#[test]
fn the_paper_networks() {
    for scheme in [observerless(1.9, 1.9), observer(9.0, 14.0, 8.0, 13.0)] {
        let lin = Linearisation::of(&paper7(scheme, 20)).expect("linearises");
        assert!(lin.per_axis());
        let r = lin.rightmost_detail();
        assert!(r.converged && r.root.re < 0.0, "{r:?}");
        assert_eq!(r.part, lin.part());
        let sys = &lin.systems()[r.axis.expect("per axis")];
        assert!(sys.residual(r.root.into()) < 1e-12, "{r:?}");
        let Margin::Crossing { delay, .. } = lin.margin() else {
            panic!("{:?}", lin.margin())
        };
        assert!(delay > 0.02, "{delay}");
    }
}

/// The engine itself (the nonlinear model, RK4 by the method of steps over
/// delayed links) on the paper's scheme-3 network, every follower link
/// delayed by 10 % less and 10 % more than the margin: the attitude errors'
/// envelope decays, then grows, at the rate of the rightmost root.
#[test]
fn the_engine_decays_and_grows_at_the_rightmost_rate() {
    use crate::engine::InProcess;
    use crate::so3::log;
    let lin = Linearisation::of(&paper7(observerless(1.9, 1.9), 20)).expect("linearises");
    let Margin::Crossing { delay, .. } = lin.margin() else {
        panic!("{:?}", lin.margin())
    };
    for f in [0.9, 1.1] {
        let steps = (f * delay / DT).round() as u64;
        let mut net = paper7(observerless(1.9, 1.9), steps);
        let want = Linearisation::of(&net).expect("linearises").rightmost().re;
        assert_eq!(want > 0.0, f > 1.0);
        net.steps = 80_000;
        net.sample_every = 100;
        for (k, a) in net.agents.iter_mut().enumerate() {
            let x = Vector3::new(1e-3 * (k as f64 + 1.0), -7e-4 * k as f64, 5e-4);
            a.initial.r = net.leader.r0 * exp(&x);
            a.initial.w = Vector3::new(1e-3, 0.0, -1e-3 * k as f64);
        }
        let r0 = net.leader.r0;
        let mut envelope = Vec::new();
        let div = InProcess::new(&net).run(|snap| {
            let e = snap
                .agents
                .iter()
                .map(|s| log(&(r0.transpose() * s.r)).norm())
                .fold(0.0, f64::max);
            envelope.push((snap.step as f64 * DT, e));
            true
        });
        assert!(div.is_none(), "{div:?}");
        let window = |a: f64| {
            envelope
                .iter()
                .filter(|x| x.0 >= a && x.0 < a + 5.0)
                .map(|x| x.1)
                .fold(0.0, f64::max)
        };
        let got = (window(75.0) / window(25.0)).ln() / 50.0;
        assert!(
            (got - want).abs() < 0.1 * want.abs(),
            "{f}: {got} vs {want}"
        );
    }
}
