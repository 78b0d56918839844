"""PROTOCOL.md § 10, transcribed: the arithmetic of an attsync agent.

Written from PROTOCOL.md alone (issue 9). Every function follows the
pseudocode of § 10 operation by operation, left to right, in plain Python
floats (IEEE-754 binary64, no fused multiply-add). Vectors are 3-tuples,
matrices 9-tuples in row-major order (``m[3*row + col]``).
"""

import math

I3 = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
Z3 = (0.0, 0.0, 0.0)


# --- § 10.1 building blocks ------------------------------------------------


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(a, k):
    return (a[0] * k, a[1] * k, a[2] * k)


def neg(a):
    return (-a[0], -a[1], -a[2])


def madd(a, b):
    return tuple(a[i] + b[i] for i in range(9))


def msub(a, b):
    return tuple(a[i] - b[i] for i in range(9))


def mscale(a, k):
    return tuple(a[i] * k for i in range(9))


def mneg(a):
    return tuple(-a[i] for i in range(9))


def tr(a):
    return (a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8])


def mm(a, b):
    out = []
    for i in range(3):
        a0, a1, a2 = a[3 * i], a[3 * i + 1], a[3 * i + 2]
        for j in range(3):
            out.append(a0 * b[j] + a1 * b[3 + j] + a2 * b[6 + j])
    return tuple(out)


def mv(a, x):
    x0, x1, x2 = x
    return (
        a[0] * x0 + a[1] * x1 + a[2] * x2,
        a[3] * x0 + a[4] * x1 + a[5] * x2,
        a[6] * x0 + a[7] * x1 + a[8] * x2,
    )


def cross(a, b):
    return (
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    )


def norm2(a):
    return a[0] * a[0] + a[1] * a[1] + a[2] * a[2]


def norm(a):
    return math.sqrt(norm2(a))


def hat(a):
    return (0.0, -a[2], a[1], a[2], 0.0, -a[0], -a[1], a[0], 0.0)


def psi(m):
    return (
        0.5 * (m[7] - m[5]),
        0.5 * (m[2] - m[6]),
        0.5 * (m[3] - m[1]),
    )


def from_config(cfg):
    """A matrix of the configuration file (column-major) as row-major."""
    return tuple(float(cfg[3 * c + r]) for r in range(3) for c in range(3))


def vec(cfg):
    return (float(cfg[0]), float(cfg[1]), float(cfg[2]))


# --- § 10.2 exp and dexp⁻¹ -------------------------------------------------


def exp(u):
    t2 = norm2(u)
    if t2 < 1e-8:
        a = 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0)
        b = 0.5 - t2 / 24.0 * (1.0 - t2 / 30.0)
    else:
        t = math.sqrt(t2)
        a = math.sin(t) / t
        b = (1.0 - math.cos(t)) / t2
    k = hat(u)
    return madd(madd(I3, mscale(k, a)), mscale(mm(k, k), b))


def dexp_inv(u, w):
    t2 = norm2(u)
    if t2 < 1e-6:
        c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    else:
        t = math.sqrt(t2)
        h = 0.5 * t
        c = (1.0 - h * math.cos(h) / math.sin(h)) / t2
    uw = cross(u, w)
    return add(add(w, scale(uw, 0.5)), scale(cross(u, uw), c))


# --- § 10.3 RKMK4, stage by stage --------------------------------------------

A_RK = (0.5, 0.5, 1.0)
WEIGHT = (1.0, 2.0, 2.0, 1.0)


class Rkmk4:
    """One step of RKMK4 over rotations ``rots`` and vectors ``vecs``."""

    def __init__(self, rots, vecs, h):
        self.h = h
        self.r0 = list(rots)
        self.x0 = list(vecs)
        self.begin()

    def begin(self):
        self.u = [Z3 for _ in self.r0]
        self.sum_u = [Z3 for _ in self.r0]
        self.sum_k = [Z3 for _ in self.x0]
        self.xs = list(self.x0)

    def point(self, s):
        """The stage point of stage ``s``: (rotations, vectors)."""
        if s == 0:
            return list(self.r0), list(self.x0)
        return [mm(r, exp(u)) for r, u in zip(self.r0, self.u)], list(self.xs)

    def update(self, s, omegas, ks):
        """After evaluating the field (Ω, k) at stage ``s``'s point."""
        h = self.h
        for r in range(len(self.r0)):
            big_u = dexp_inv(self.u[r], omegas[r])
            self.sum_u[r] = add(self.sum_u[r], scale(big_u, WEIGHT[s]))
            if s < 3:
                self.u[r] = scale(big_u, h * A_RK[s])
        for v in range(len(self.x0)):
            self.sum_k[v] = add(self.sum_k[v], scale(ks[v], WEIGHT[s]))
            if s < 3:
                self.xs[v] = add(self.x0[v], scale(ks[v], h * A_RK[s]))
        if s == 3:
            h6 = h / 6.0
            self.r0 = [mm(r, exp(scale(su, h6))) for r, su in zip(self.r0, self.sum_u)]
            self.x0 = [add(x, scale(sk, h6)) for x, sk in zip(self.x0, self.sum_k)]
            self.begin()


# --- § 10.6 the observers, § 10.7 the control laws -------------------------


def observer_time_varying(gains, p, rh, wh, sh, leader, neighbours):
    """Eqs. 7b-7c: (ω̂̇, σ̂̇). ``leader``: (A₀, (R₀, ω₀, σ₀)) or None;
    ``neighbours``: [(A_j, (R̂ⱼ, ω̂ⱼ, σ̂ⱼ))] in inputs order."""
    k_r, k_w, k_s = gains["k_r"], gains["k_w"], gains["k_sigma"]
    d = sh
    if leader is not None:
        a0, (r0, w0, _s0) = leader
        d = sub(d, scale(mv(tr(r0), psi(mm(mm(a0, rh), tr(r0)))), k_r))
        d = sub(d, scale(sub(wh, w0), k_w))
    for aj, (rj, wj, _sj) in neighbours:
        d = sub(d, scale(mv(tr(rj), psi(mm(mm(aj, rh), tr(rj)))), k_r))
        d = sub(d, scale(sub(wh, wj), k_w))
    e = mv(p, sh)
    for _aj, (_rj, _wj, sj) in neighbours:
        e = sub(e, scale(sub(sh, sj), k_s))
    if leader is not None:
        e = sub(e, scale(sub(sh, leader[1][2]), k_s))
    return d, e


def observer_constant(gains, rh, wh, leader, neighbours):
    """Eq. 16b: (ω̂̇, σ̂̇ = 0)."""
    k_r, k_w = gains["k_r"], gains["k_w"]
    d = Z3
    for aj, (rj, wj, _sj) in neighbours:
        d = sub(d, scale(psi(mm(mm(aj, tr(rj)), rh)), k_r))
        d = sub(d, scale(sub(wh, wj), k_w))
    if leader is not None:
        a0, (r0, _w0, _s0) = leader
        d = sub(d, scale(psi(mm(mm(a0, tr(r0)), rh)), k_r))
        d = sub(d, scale(wh, k_w))
    return d, Z3


def control_observer(gains, j, a_bar, r, w, rh, wh, wh_dot, with_sigma):
    """Laws `control` (scheme 1, ``with_sigma``) and
    `controlconstantestimate` (scheme 2): τ."""
    k_r, k_w = gains["k_r"], gains["k_w"]
    r_bar = mm(tr(rh), r)
    v = mv(tr(r_bar), wh)
    w_bar = sub(w, v)
    gamma = sub(neg(cross(v, mv(j, v))), mv(j, mv(tr(r_bar), wh_dot)))
    pd = add(scale(psi(mm(a_bar, r_bar)), k_r), scale(w_bar, k_w))
    if not with_sigma:
        return sub(neg(gamma), pd)
    hv = hat(v)
    sigma = msub(msub(madd(hat(mv(j, w_bar)), hat(mv(j, v))), mm(hv, j)), mm(j, hv))
    return sub(sub(mv(mneg(sigma), w_bar), gamma), pd)


def control_observerless(gains, r, w, leader, neighbours):
    """Law `districontrol`: τ (leader first, then the neighbours)."""
    k_r, k_w = gains["k_r"], gains["k_w"]
    tau = scale(neg(w), k_w)
    if leader is not None:
        a0, (r0, _w0, _s0) = leader
        tau = sub(tau, scale(psi(mm(mm(a0, tr(r0)), r)), k_r))
    for aj, (rj, _wj, _sj) in neighbours:
        tau = sub(tau, scale(psi(mm(mm(aj, tr(rj)), r)), k_r))
    return tau


# --- § 8 validity of a received state ----------------------------------------


def is_valid_state(r, w, s):
    """All 15 numbers finite, ‖rᵀr − I‖_F ≤ 1e-6 and det r > 0."""
    for x in (*r, *w, *s):
        if not math.isfinite(x):
            return False
    m = msub(mm(tr(r), r), I3)
    n = [m[c] * m[c] + m[3 + c] * m[3 + c] + m[6 + c] * m[6 + c] for c in range(3)]
    if not math.sqrt(n[0] + n[1] + n[2]) <= 1e-6:
        return False
    det = (
        r[0] * (r[4] * r[8] - r[7] * r[5])
        - r[1] * (r[3] * r[8] - r[6] * r[5])
        + r[2] * (r[3] * r[7] - r[6] * r[4])
    )
    return det > 0.0
