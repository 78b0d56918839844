//! PROTOCOL.md § 10 ("The arithmetic, to the bit") transcribed on plain
//! `f64` arrays, compared bit for bit with the model: the building blocks
//! of § 10.1 (nalgebra's product, cross, norm), `exp` and `dexp⁻¹` of
//! § 10.2 on both sides of their small-angle thresholds, and whole RKMK4
//! steps of the leader (§ 10.3–10.4). If the model's arithmetic changes,
//! this fails and § 10 must be rewritten.

use attitude::reference::{Leader, LeaderState};
use attitude::so3::{dexp_inv, exp, rot};
use nalgebra::{Matrix3, Vector3};

type V = [f64; 3];
type M = [[f64; 3]; 3];

fn mm(a: &M, b: &M) -> M {
    let mut c = [[0.0; 3]; 3];
    for (i, row) in c.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    c
}
fn mv(a: &M, x: &V) -> V {
    [0, 1, 2].map(|i| a[i][0] * x[0] + a[i][1] * x[1] + a[i][2] * x[2])
}
fn add(a: &V, b: &V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: &V, k: f64) -> V {
    [a[0] * k, a[1] * k, a[2] * k]
}
fn cross(a: &V, b: &V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm2(a: &V) -> f64 {
    a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
}
fn hat(a: &V) -> M {
    [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]]
}
fn exp_p(u: &V) -> M {
    let t2 = norm2(u);
    let (a, b) = if t2 < 1e-8 {
        (
            1.0 - t2 / 6.0 * (1.0 - t2 / 20.0),
            0.5 - t2 / 24.0 * (1.0 - t2 / 30.0),
        )
    } else {
        let t = t2.sqrt();
        (t.sin() / t, (1.0 - t.cos()) / t2)
    };
    let k = hat(u);
    let kk = mm(&k, &k);
    let id = Matrix3::<f64>::identity();
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = id[(i, j)] + k[i][j] * a + kk[i][j] * b;
        }
    }
    r
}
fn dexp_inv_p(u: &V, w: &V) -> V {
    let t2 = norm2(u);
    let c = if t2 < 1e-6 {
        1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    } else {
        let h = 0.5 * t2.sqrt();
        (1.0 - h * h.cos() / h.sin()) / t2
    };
    let uw = cross(u, w);
    add(&add(w, &scale(&uw, 0.5)), &scale(&cross(u, &uw), c))
}

fn to_m(m: &Matrix3<f64>) -> M {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[(i, j)]))
}
fn bits_m(m: &M) -> [[u64; 3]; 3] {
    m.map(|r| r.map(f64::to_bits))
}
fn bits_v(v: &V) -> [u64; 3] {
    v.map(f64::to_bits)
}

/// Vectors of every size around the thresholds (θ² = 1e-8, 1e-6) and beyond.
fn samples() -> Vec<V> {
    let mut out = Vec::new();
    let mut s: u64 = 12345;
    for scale in [
        0.0, 1e-9, 5e-5, 9.9e-5, 1.01e-4, 5e-4, 9.9e-4, 1.01e-3, 0.1, 1.0, 3.0,
    ] {
        for _ in 0..20 {
            let mut r = || {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let d = [r(), r(), r()];
            let n = norm2(&d).sqrt();
            out.push(scale_or_zero(&d, scale / n));
        }
    }
    out
}
fn scale_or_zero(d: &V, k: f64) -> V {
    if k.is_finite() { scale(d, k) } else { [0.0; 3] }
}

#[test]
fn building_blocks_exp_and_dexp_inv_match_section_10() {
    let vs = samples();
    for (k, u) in vs.iter().enumerate() {
        let w = vs[(k * 7 + 3) % vs.len()];
        let (un, wn) = (Vector3::from(*u), Vector3::from(w));
        assert_eq!(bits_v(&cross(u, &w)), bits_v(&un.cross(&wn).into()));
        assert_eq!(norm2(u).sqrt().to_bits(), un.norm().to_bits());
        assert_eq!(bits_m(&exp_p(u)), bits_m(&to_m(&exp(&un))), "exp({u:?})");
        assert_eq!(
            bits_v(&dexp_inv_p(u, &w)),
            bits_v(&dexp_inv(&un, &wn).into())
        );
        let (a, b) = (exp(&un), exp(&wn) * 1.5);
        assert_eq!(bits_m(&mm(&to_m(&a), &to_m(&b))), bits_m(&to_m(&(a * b))));
        assert_eq!(bits_v(&mv(&to_m(&b), u)), bits_v(&(b * un).into()));
    }
}

/// § 10.3 with the leader's field of § 10.4, stepped as the pseudocode says.
#[test]
fn leader_steps_match_section_10() {
    let q = 0.75 * std::f64::consts::PI;
    let p = Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, q.cos(), 0.0, q.sin(), 0.0);
    let r0 = rot(
        0.8 * std::f64::consts::PI,
        &Vector3::new(1.0, 4.0, 2.0).normalize(),
    );
    let (h, pm) = (0.001, to_m(&p));
    let mut leader = Leader::new(
        p,
        LeaderState {
            r0,
            w0: Vector3::new(1.0, 2.0, 0.0),
            s0: Vector3::new(1.0, 0.0, 0.0),
        },
        h,
    );
    let (mut rn, mut xn): (M, [V; 2]) = (to_m(&r0), [[1.0, 2.0, 0.0], [1.0, 0.0, 0.0]]);
    let (a, weight) = ([0.5, 0.5, 1.0], [1.0, 2.0, 2.0, 1.0]);
    for _ in 0..1000 {
        let (mut u, mut sum_u, mut sum_k, mut xs) = ([0.0; 3], [0.0; 3], [[0.0; 3]; 2], xn);
        for s in 0..4 {
            let (_, x) = if s == 0 {
                (rn, xn)
            } else {
                (mm(&rn, &exp_p(&u)), xs)
            };
            let (om, k) = (x[0], [x[1], mv(&pm, &x[1])]);
            let big_u = dexp_inv_p(&u, &om);
            sum_u = add(&sum_u, &scale(&big_u, weight[s]));
            if s < 3 {
                u = scale(&big_u, h * a[s]);
            }
            for v in 0..2 {
                sum_k[v] = add(&sum_k[v], &scale(&k[v], weight[s]));
                if s < 3 {
                    xs[v] = add(&xn[v], &scale(&k[v], h * a[s]));
                }
            }
            leader.advance();
        }
        let h6 = h / 6.0;
        rn = mm(&rn, &exp_p(&scale(&sum_u, h6)));
        xn = [0, 1].map(|v| add(&xn[v], &scale(&sum_k[v], h6)));
        let st = leader.state();
        assert_eq!(bits_m(&rn), bits_m(&to_m(&st.r0)));
        assert_eq!(bits_v(&xn[0]), bits_v(&st.w0.into()));
        assert_eq!(bits_v(&xn[1]), bits_v(&st.s0.into()));
    }
}
