use attitude::body::*;
use attitude::integrate::*;
use attitude::so3::*;
use nalgebra::{Matrix3, Vector3};

fn exp_half(u: &Vector3<f64>) -> Matrix3<f64> {
    let t2 = u.norm_squared();
    let (a, b) = if t2 < 1e-8 {
        (1.0 - t2 / 6.0 * (1.0 - t2 / 20.0), 0.5 - t2 / 24.0 * (1.0 - t2 / 30.0))
    } else {
        let t = t2.sqrt();
        let s = (0.5 * t).sin() / (0.5 * t);
        (t.sin() / t, 0.5 * s * s)
    };
    let k = hat(u);
    Matrix3::identity() + k * a + k * k * b
}

fn step(y: &LieState<1,1>, h: f64, j: &Inertia, e: fn(&Vector3<f64>) -> Matrix3<f64>) -> LieState<1,1> {
    let a = [0.5, 0.5, 1.0];
    let mut u = Vector3::zeros();
    let mut su = Vector3::zeros();
    let mut sk = Vector3::zeros();
    let mut x = y.vec[0];
    for s in 0..4 {
        let r = if s == 0 { y.rot[0] } else { y.rot[0] * e(&u) };
        let st = LieState { rot: [r], vec: [x] };
        let k = body_field(j, &st, &Vector3::zeros());
        let wgt = if s == 0 || s == 3 { 1.0 } else { 2.0 };
        let bu = dexp_inv(&u, &k.omega[0]);
        su += bu * wgt;
        sk += k.vec[0] * wgt;
        if s < 3 { u = bu * (h * a[s]); x = y.vec[0] + k.vec[0] * (h * a[s]); }
    }
    let mut out = *y;
    out.rot[0] = y.rot[0] * e(&(su * (h / 6.0)));
    out.vec[0] = y.vec[0] + sk * (h / 6.0);
    out
}

#[test]
fn measure() {
    let j = Inertia::new(Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)));
    let y0 = LieState { rot: [rot(0.3, &Vector3::new(1.0, -1.0, 2.0).normalize())], vec: [Vector3::new(1.0, 0.1, 2.0)] };
    let mut a = y0; let mut b = y0; let mut c = y0;
    for n in 0..1_000_000 {
        a = rkmk4_step(&a, 0.0, 1e-3, |_, y| body_field(&j, y, &Vector3::zeros()));
        b = step(&b, 1e-3, &j, exp);
        c = step(&c, 1e-3, &j, exp_half);
        if n % 200000 == 199999 {
            println!("{} crate {:e} replica {:e} half {:e}  det {:e} {:e}", n+1, orthogonality_defect(&a.rot[0]), orthogonality_defect(&b.rot[0]), orthogonality_defect(&c.rot[0]), a.rot[0].determinant()-1.0, c.rot[0].determinant()-1.0);
        }
    }
    assert_eq!(a, b);
    // identity start
    let y1 = LieState { rot: [Matrix3::identity()], vec: [Vector3::new(1.0, 0.1, 2.0)] };
    let mut a = y1; let mut c = y1;
    for _ in 0..1_000_000 { a = step(&a, 1e-3, &j, exp); c = step(&c, 1e-3, &j, exp_half); }
    println!("identity start: crate {:e} half {:e}", orthogonality_defect(&a.rot[0]), orthogonality_defect(&c.rot[0]));
}
