//! The tree path ([`super::tree`], [`super::tree_roots`],
//! [`super::tree_margin`]) against the dense one on networks small enough
//! for both, and on a generated-like tree of 1000 agents.

use super::tests::{agent, chain, delay, diag, observer, observerless, paper7, path3};
use super::*;
use crate::network::{Neighbour, Network, Scheme};
use nalgebra::{Complex, DMatrix};

/// SplitMix64: a few reproducible draws without a dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[a, b)`.
    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `0..n`.
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// A random recursive tree like `attsync gen tree`'s: agent `k` hangs on a
/// uniform earlier agent; inertias `diag(U(0.1, 1))`; edge gains
/// `diag(c + m, c + 1 + m, c + 2 + m)`, `m ~ U(0, 5)`, `c` = 3 (scheme 3) or
/// 10 (scheme 2); `leaders` distinct agents hear the leader with `c` = 5 or
/// 14; each direction of each link delayed by `steps(rng)` steps.
fn random_tree(
    n: u32,
    leaders: u32,
    scheme: Scheme,
    seed: u64,
    mut steps: impl FnMut(&mut Rng) -> u64,
) -> Network {
    let mut rng = Rng(seed);
    let obs = scheme.has_observer();
    let (c_edge, c_link) = if obs { (10.0, 14.0) } else { (3.0, 5.0) };
    let g = |rng: &mut Rng, c: f64| {
        let m = rng.uniform(0.0, 5.0);
        diag(c + m, c + 1.0 + m, c + 2.0 + m)
    };
    let mut agents: Vec<_> = (1..=n)
        .map(|id| {
            let j = diag(
                rng.uniform(0.1, 1.0),
                rng.uniform(0.1, 1.0),
                rng.uniform(0.1, 1.0),
            );
            let mut a = agent(id, j, scheme, Vec::new(), None);
            a.model.a_bar = g(&mut rng, 10.0);
            a
        })
        .collect();
    for k in 2..=n {
        let p = 1 + rng.below(u64::from(k - 1)) as u32;
        let a = g(&mut rng, c_edge);
        for (from, to) in [(p, k), (k, p)] {
            let s = steps(&mut rng);
            let link = if s == 0 { None } else { delay(s) };
            agents[to as usize - 1]
                .model
                .neighbours
                .push(Neighbour { id: from, a, link });
        }
    }
    let mut ids: Vec<u32> = (1..=n).collect();
    for i in 0..leaders as usize {
        let j = i + rng.below((ids.len() - i) as u64) as usize;
        ids.swap(i, j);
        agents[ids[i] as usize - 1].model.leader_gain = Some(g(&mut rng, c_link));
    }
    let mut net = paper7(scheme, 0);
    net.agents = agents;
    net
}

fn s3() -> Scheme {
    observerless(1.9, 1.9)
}

fn s2() -> Scheme {
    observer(14.0, 12.0, 13.0, 11.0)
}

/// The networks both paths take, by name.
fn small_networks() -> Vec<(&'static str, Network)> {
    vec![
        ("paper s3 20", paper7(s3(), 20)),
        ("paper s2 20", paper7(observer(9.0, 14.0, 8.0, 13.0), 20)),
        ("paper s3 0", paper7(s3(), 0)),
        (
            "path s2 delay-independent",
            path3(observer(9.0, 14.0, 8.0, 13.0), [5, 10, 20, 0], false),
        ),
        ("paper s3 unstable", paper7(observerless(1.9, -0.3), 20)),
        ("path s3 per-link", path3(s3(), [5, 10, 20, 0], false)),
        ("path s2 per-link", path3(s2(), [5, 10, 20, 0], false)),
        ("chain 20 s3", chain(20, s3(), 20)),
        ("chain 40 s3", chain(40, s3(), 20)),
        ("chain 20 s2", chain(20, s2(), 10)),
        ("tree 40 s3", random_tree(40, 3, s3(), 7, |_| 20)),
        (
            "tree 40 s3 per-link",
            random_tree(40, 2, s3(), 8, |r| r.below(40)),
        ),
        (
            "tree 25 s2 per-link",
            random_tree(25, 2, s2(), 9, |r| 5 + r.below(30)),
        ),
    ]
}

/// `|a − b| ≤ tol · |b|` (complex).
fn close(a: Root, b: Root, tol: f64) -> bool {
    let (a, b) = (Complex::from(a), Complex::from(b));
    (a - b).norm() <= tol * b.norm()
}

/// `ln det Δ` and its derivative from the tree against the dense
/// characteristic matrix of the same system (`det` of the first-order
/// form is `det Δ / Π a_i`).
#[test]
fn the_tree_determinant_is_the_dense_one() {
    let net = random_tree(9, 2, s3(), 3, |r| r.below(30));
    let lin = Linearisation::of_tree(&net).expect("tree");
    let sys = lin.systems();
    for (k, t) in tree_systems(&net).iter().enumerate() {
        let taus: Vec<f64> = lin.delays();
        let dde = t.to_dde(&taus);
        assert_eq!(dde.a0(), sys[k].a0());
        for s in [Complex::new(0.3, 1.7), Complex::new(-2.0, 11.0)] {
            let got = t.eval(s, &taus).expect("regular");
            let (d, dp) = dde.characteristic(s);
            let want: Complex<f64> = d.clone().lu().solve(&dp).expect("regular").trace();
            assert!(
                (got.slope - want).norm() < 1e-10 * want.norm(),
                "{got:?} {want}"
            );
            let det = d.lu().determinant();
            let scale: f64 = t.diagonal().iter().map(|x| x[0].ln()).sum();
            let diff = got.value - det.ln() - scale;
            let wrapped = diff.im.rem_euclid(2.0 * std::f64::consts::PI);
            assert!(
                diff.re.abs() < 1e-9 && wrapped.min(2.0 * std::f64::consts::PI - wrapped) < 1e-9
            );
        }
    }
}

/// The trees of a network's three axes.
fn tree_systems(net: &Network) -> Vec<tree::Tree> {
    let lin = Linearisation::of_tree(net).expect("tree");
    lin.trees()
}

#[test]
fn the_rightmost_roots_agree_with_the_dense_path() {
    for (name, net) in small_networks() {
        let dense = Linearisation::of_dense(&net).expect("dense");
        assert!(!dense.on_trees(), "{name}");
        let tree = Linearisation::of_tree(&net).expect("tree");
        let pairs = [
            ("own", dense.rightmost(), tree.rightmost()),
            ("0", dense.rightmost_at(0.0), tree.rightmost_at(0.0)),
            ("0.01", dense.rightmost_at(0.01), tree.rightmost_at(0.01)),
            ("0.05", dense.rightmost_at(0.05), tree.rightmost_at(0.05)),
        ];
        for (d, a, b) in pairs {
            let err = (Complex::from(a) - Complex::from(b)).norm() / Complex::from(a).norm();
            println!("{name:>22} d = {d:>4}: dense {a}, tree {b}, relative {err:.1e}");
            assert!(close(b, a, 1e-6), "{name} at {d}: dense {a} vs tree {b}");
        }
    }
}

#[test]
fn the_margins_agree_with_the_dense_path() {
    for (name, net) in small_networks() {
        let dense = Linearisation::of_dense(&net).expect("dense").margin();
        let tree = Linearisation::of_tree(&net).expect("tree").margin();
        println!("{name:>22}: dense {dense:?}\n{:>22}  tree  {tree:?}", "");
        match (dense, tree) {
            (
                Margin::Crossing {
                    delay: d1,
                    omega: w1,
                    ..
                },
                Margin::Crossing {
                    delay: d2,
                    omega: w2,
                    axis_distance,
                },
            ) => {
                assert!((d1 - d2).abs() <= 1e-8 * d1, "{name}: {d1} vs {d2}");
                assert!((w1 - w2).abs() <= 1e-8 * w1, "{name}: {w1} vs {w2}");
                assert!(axis_distance < 1e-8, "{name}: {axis_distance}");
            }
            (
                Margin::UnstableWithoutDelay { rightmost: a },
                Margin::UnstableWithoutDelay { rightmost: b },
            ) => assert!(close(b, a, 1e-6), "{name}"),
            (a, b) => assert_eq!(a, b, "{name}"),
        }
    }
}

/// A tree path's [`Linearisation::systems`] (dense, built from the trees)
/// are the dense path's.
#[test]
fn a_tree_paths_systems_are_the_dense_ones() {
    let net = path3(s2(), [5, 10, 20, 0], false);
    let (a, b) = (
        Linearisation::of_dense(&net).expect("dense"),
        Linearisation::of_tree(&net).expect("tree"),
    );
    assert_eq!(a.delays(), b.delays());
    for (x, y) in a.systems().iter().zip(b.systems()) {
        let diff: DMatrix<f64> = x.a0() - y.a0();
        assert!(diff.abs().max() < 1e-12);
        assert_eq!(x.delayed().len(), y.delayed().len());
        for ((t1, m1), (t2, m2)) in x.delayed().iter().zip(y.delayed()) {
            assert_eq!(t1, t2);
            assert!((m1 - m2).abs().max() < 1e-12);
        }
    }
}

/// A generated-like tree of 1000 agents (10 hear the leader, every link
/// delayed by 20 ms): the tree path is taken, the rightmost root is a root
/// and left of the axis, the margin's crossing is on the axis. Time it
/// from the command line (`time cargo test --release … a_thousand_agents
/// -- --nocapture`).
fn a_thousand_agents(name: &str, scheme: Scheme) {
    let net = random_tree(1000, 10, scheme, 42, |_| 20);
    let lin = Linearisation::of(&net).expect("tree path");
    assert!(lin.on_trees(), "{name}");
    let r = lin.rightmost_detail();
    println!(
        "{name}: rightmost {} ({:?}, axis {:?})",
        r.root, r.part, r.axis
    );
    assert!(r.converged && r.root.re < 0.0, "{name}: {r:?}");
    let m = lin.margin();
    println!("{name}: margin {m:?}");
    let Margin::Crossing { axis_distance, .. } = m else {
        panic!("{name}: {m:?}")
    };
    assert!(axis_distance < 1e-8, "{name}: {m:?}");
}

#[test]
fn a_thousand_agents_scheme_3() {
    a_thousand_agents("scheme 3", s3());
}

#[test]
fn a_thousand_agents_scheme_2() {
    a_thousand_agents("scheme 2", s2());
}
