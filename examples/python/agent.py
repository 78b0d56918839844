#!/usr/bin/env python3
"""An attsync agent in pure Python: a plug-in that takes the place of one
built-in `attsync-agent` process (PROTOCOL.md, protocol version 3).

How to run it
-------------
    python3 -m pip install -r examples/python/requirements.txt   # iceoryx2==0.10.0
    cargo build --release --workspace
    ./target/release/attsync run scenarios/plugin/python-observerless.toml
    ./target/release/attsync run scenarios/plugin/python-timevarying.toml
    ./target/release/attsync run scenarios/plugin/python-observerless.toml --realtime
    ./target/release/attsync conform -- python3 examples/python/agent.py

In a scenario, `command = ["python3", "../../examples/python/agent.py"]` in an
`[[agent]]` makes that agent this program. The orchestrator starts it as
`<command...> --config FILE` (the file also in env ATTSYNC_CONFIG), in the
scenario's directory, with stdout and stderr going to logs/agent-<id>.log.

What it computes
----------------
All three schemes of the paper, bit-identical to the built-in agent:
  1. observer-time-varying: observer eqs. 7a-7c, control law `control`;
  2. observer-constant:     observer eqs. 16a-16b, law `controlconstantestimate`;
  3. observerless:          law `districontrol`;
on the rigid body J_i dw_i/dt = -w_i x J_i w_i + tau_i, dR_i/dt = R_i hat(w_i)
(eq. `followeri`), integrated with RKMK4 stage by stage. Every function
below is one equation or one building block of PROTOCOL.md § 10 ("The
arithmetic, to the bit"), with the same floating-point operations in the
same order: plain Python floats are IEEE binary64 with no fused
multiply-add, and math.sin/cos are glibc's, as in the Rust agent.

How it runs
-----------
Lockstep (the default, § 6) or real time (`attsync run --realtime`, § 7),
coupling "continuous" or "sampled", unimpaired links. Anything else
(impaired links, the leader's role, a malformed configuration, another
protocol version) is refused at start-up with exit code 2. Protocol
violations, timeouts and the loss of the parent process exit with code 1;
a clean run exits 0, after releasing every iceoryx2 resource it made.
"""

import ctypes
import gc
import json
import math
import os
import struct
import sys
import time

PROTOCOL_VERSION = 3
ROTATION_TOLERANCE = 1e-6  # largest ||R^T R - I||_F accepted from a peer (§ 8)
STOP_TIMEOUT = 600.0  # s, longest wait for Stop after Done (§ 6.9)
# sched_yield()s before sleeping on the wake event (wait = "adaptive");
# env ATTSYNC_PY_YIELDS overrides it.
ADAPTIVE_YIELDS = int(os.environ.get("ATTSYNC_PY_YIELDS", "20"))
BLOCK_SLICE_MS = 1  # longest single sleep on the wake event

SCHEMES = ("observer-time-varying", "observer-constant", "observerless")
PROG = "attsync python agent"


class NodeError(Exception):
    """Ends the node with a message on stderr and exit code `code`.
    `failed` is the telemetry Failed (reason, input id) to report first,
    when the node gives up while stepping (§ 5)."""

    def __init__(self, msg, code=1, failed=None):
        super().__init__(msg)
        self.code = code
        self.failed = failed


def log(msg):
    """One line on stderr (the orchestrator writes it to logs/agent-<id>.log)."""
    sys.stderr.write(f"{time.strftime('%H:%M:%S')} {PROG}: {msg}\n")
    sys.stderr.flush()


# ==========================================================================
# Payloads (PROTOCOL.md § 5): little-endian, #[repr(C)], no padding.
# ==========================================================================

# StateMsg, 152 bytes: version u32, sender u32, step u64, stage u32,
# reserved u32, sent_unix_ns u64, r f64[9] (row-major), w f64[3], s f64[3].
STATE = struct.Struct("<IIQIIQ15d")
# ControlMsg, 16 bytes: version u32, command u32, start_unix_ns u64.
CONTROL = struct.Struct("<IIQ")
START, STOP = 1, 2

# TelemetryMsg, 248 bytes: a 16-byte header (version, sender, kind,
# reserved: u32) and a 232-byte body laid out per kind; unused bytes are 0.
TELEMETRY_SIZE = 248
TELEMETRY_HEADER = struct.Struct("<IIII")
READY, SAMPLE, DONE, LINK_STATS, FAILED, TORQUE = 1, 2, 3, 4, 5, 7
# Bodies, all starting at offset 16:
SAMPLE_BODY = struct.Struct("<Q9d3d9d3d3dd")  # step, r, w, r_hat, w_hat, s_hat, peak_torque
TORQUE_BODY = struct.Struct("<Q3d")  # step, tau (applied at stage 0 of the step)
DONE_BODY = struct.Struct("<QdQQQQd")  # steps, peak_torque, peak_rss_kb, started_unix_ns,
#                                        done_unix_ns, late_stages, max_lateness
LINK_STATS_BODY = struct.Struct("<I4xQQQQQdd")  # from, sent, delivered, lost, rejected,
#                                                 evaluations, age_sum, age_max
FAILED_BODY = struct.Struct("<II")  # reason, from
FAIL_TIMEOUT, FAIL_BAD_INPUT, FAIL_OTHER = 1, 2, 3


def _c_struct(name, type_name, fields):
    """A ctypes structure: iceoryx2 matches services by type name, size and
    alignment, which must equal the Rust `#[type_name]`, size_of, align_of."""
    cls = type(name, (ctypes.Structure,), {"_fields_": fields})
    cls.type_name = staticmethod(lambda: type_name)
    return cls


U8, U32, U64, F64 = ctypes.c_uint8, ctypes.c_uint32, ctypes.c_uint64, ctypes.c_double
StateMsg = _c_struct("StateMsg", "attsync::StateMsg", [
    ("version", U32), ("sender", U32), ("step", U64), ("stage", U32),
    ("reserved", U32), ("sent_unix_ns", U64), ("r", F64 * 9), ("w", F64 * 3),
    ("s", F64 * 3)])
TelemetryMsg = _c_struct("TelemetryMsg", "attsync::TelemetryMsg", [
    ("version", U32), ("sender", U32), ("kind", U32), ("reserved", U32),
    ("body", U8 * 232)])
ControlMsg = _c_struct("ControlMsg", "attsync::ControlMsg", [
    ("version", U32), ("command", U32), ("start_unix_ns", U64)])
assert (ctypes.sizeof(StateMsg), ctypes.alignment(StateMsg)) == (STATE.size, 8) == (152, 8)
assert (ctypes.sizeof(TelemetryMsg), ctypes.alignment(TelemetryMsg)) == (TELEMETRY_SIZE, 4)
assert (ctypes.sizeof(ControlMsg), ctypes.alignment(ControlMsg)) == (CONTROL.size, 8) == (16, 8)
assert 16 + SAMPLE_BODY.size == TELEMETRY_SIZE


def telemetry(node_id, kind, body=None, *fields):
    """A TelemetryMsg's bytes: the header, then `fields` packed with `body`."""
    buf = bytearray(TELEMETRY_SIZE)
    TELEMETRY_HEADER.pack_into(buf, 0, PROTOCOL_VERSION, node_id, kind, 0)
    if body is not None:
        body.pack_into(buf, 16, *fields)
    return bytes(buf)


def unix_ns():
    """Wall-clock time, ns since the Unix epoch."""
    return time.time_ns()


def peak_rss_kb():
    """Peak resident set size of this process (VmHWM), kB; 0 if unknown."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except (OSError, ValueError, IndexError):
        pass
    return 0


# ==========================================================================
# § 10.1 Building blocks. Vectors are 3-tuples, matrices row-major 9-tuples
# (M[row][col] = m[3*row + col]); each operation is nalgebra's, in its order.
# ==========================================================================

ZERO = (0.0, 0.0, 0.0)
IDENTITY = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(a, k):
    """a·k."""
    return (a[0] * k, a[1] * k, a[2] * k)


def neg(a):
    return (-a[0], -a[1], -a[2])


def madd(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3], a[4] + b[4],
            a[5] + b[5], a[6] + b[6], a[7] + b[7], a[8] + b[8])


def msub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3], a[4] - b[4],
            a[5] - b[5], a[6] - b[6], a[7] - b[7], a[8] - b[8])


def mneg(a):
    return (-a[0], -a[1], -a[2], -a[3], -a[4], -a[5], -a[6], -a[7], -a[8])


def mscale(a, k):
    """M·k, per entry."""
    return (a[0] * k, a[1] * k, a[2] * k, a[3] * k, a[4] * k, a[5] * k, a[6] * k,
            a[7] * k, a[8] * k)


def tr(a):
    """The transpose."""
    return (a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8])


def mm(a, b):
    """A·B: entry (i, j) = (a_i0 b_0j + a_i1 b_1j) + a_i2 b_2j."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7,
            a0 * b2 + a1 * b5 + a2 * b8,
            a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7,
            a3 * b2 + a4 * b5 + a5 * b8,
            a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7,
            a6 * b2 + a7 * b5 + a8 * b8)


def mv(a, x):
    """A·x."""
    x0, x1, x2 = x
    return (a[0] * x0 + a[1] * x1 + a[2] * x2, a[3] * x0 + a[4] * x1 + a[5] * x2,
            a[6] * x0 + a[7] * x1 + a[8] * x2)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0])


def norm2(a):
    return a[0] * a[0] + a[1] * a[1] + a[2] * a[2]


def norm(a):
    return math.sqrt(norm2(a))


def hat(a):
    """The skew-symmetric matrix a^x (a^x b = a x b)."""
    return (0.0, -a[2], a[1], a[2], 0.0, -a[0], -a[1], a[0], 0.0)


def psi(m):
    """psi = vex o Pa: the vector of the skew-symmetric part of M."""
    return (0.5 * (m[7] - m[5]), 0.5 * (m[2] - m[6]), 0.5 * (m[3] - m[1]))


def psi_mm(a, b):
    """psi(A·B), computing only the off-diagonal entries of A·B that psi
    reads (each exactly as `mm` computes it)."""
    m01 = a[0] * b[1] + a[1] * b[4] + a[2] * b[7]
    m02 = a[0] * b[2] + a[1] * b[5] + a[2] * b[8]
    m10 = a[3] * b[0] + a[4] * b[3] + a[5] * b[6]
    m12 = a[3] * b[2] + a[4] * b[5] + a[5] * b[8]
    m20 = a[6] * b[0] + a[7] * b[3] + a[8] * b[6]
    m21 = a[6] * b[1] + a[7] * b[4] + a[8] * b[7]
    return (0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01))


# ==========================================================================
# § 10.2 exp and dexp^-1 on SO(3)
# ==========================================================================

def exp_so3(u):
    """exp(hat(u)), Rodrigues' formula (a Taylor series near 0)."""
    t2 = norm2(u)
    if t2 < 1e-8:
        a = 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0)
        b = 0.5 - t2 / 24.0 * (1.0 - t2 / 30.0)
    else:
        t = math.sqrt(t2)
        a = math.sin(t) / t
        b = (1.0 - math.cos(t)) / t2
    k = hat(u)
    kk = mm(k, k)
    # (I + K·a) + (K·K)·b, entry by entry
    return (1.0 + k[0] * a + kk[0] * b, 0.0 + k[1] * a + kk[1] * b,
            0.0 + k[2] * a + kk[2] * b, 0.0 + k[3] * a + kk[3] * b,
            1.0 + k[4] * a + kk[4] * b, 0.0 + k[5] * a + kk[5] * b,
            0.0 + k[6] * a + kk[6] * b, 0.0 + k[7] * a + kk[7] * b,
            1.0 + k[8] * a + kk[8] * b)


def dexp_inv(u, w):
    """The inverse of the left-trivialised differential of exp:
    w + 1/2 u x w + c u x (u x w)."""
    t2 = norm2(u)
    if t2 < 1e-6:
        c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    else:
        t = math.sqrt(t2)
        h = 0.5 * t
        c = (1.0 - h * math.cos(h) / math.sin(h)) / t2
    uw = cross(u, w)
    return add(add(w, scale(uw, 0.5)), scale(cross(u, uw), c))


# ==========================================================================
# § 10.3 RKMK4, one stage at a time
# ==========================================================================

RK_A = (0.5, 0.5, 1.0)  # a of stages 2-4 (c = [0, 1/2, 1/2, 1])
RK_WEIGHT = (1.0, 2.0, 2.0, 1.0)


class Rkmk4:
    """Runge-Kutta-Munthe-Kaas of order 4 on SO(3)^NR x R^3NV. `point` is
    the current stage's evaluation point (rotations, vectors); `push` takes
    the field there (a body rate per rotation, a derivative per vector)."""

    def __init__(self, rotations, vectors, h):
        self.h = h
        self.begin(list(rotations), list(vectors))

    def begin(self, rotations, vectors):
        """The start of a step at (R^0, x^0)."""
        self.r0, self.x0 = rotations, vectors
        self.stage = 0
        self.u = [ZERO] * len(rotations)
        self.sum_u = [ZERO] * len(rotations)
        self.sum_k = [ZERO] * len(vectors)
        self.point = (rotations, vectors)

    def push(self, omegas, ks):
        """Moves to the next stage; True when the step is complete."""
        s, h = self.stage, self.h
        weight = RK_WEIGHT[s]
        xs = []
        for i, omega in enumerate(omegas):
            big_u = dexp_inv(self.u[i], omega)
            self.sum_u[i] = add(self.sum_u[i], scale(big_u, weight))
            if s < 3:
                self.u[i] = scale(big_u, h * RK_A[s])
        for i, k in enumerate(ks):
            self.sum_k[i] = add(self.sum_k[i], scale(k, weight))
            if s < 3:
                xs.append(add(self.x0[i], scale(k, h * RK_A[s])))
        if s < 3:
            self.stage = s + 1
            self.point = ([mm(r, exp_so3(u)) for r, u in zip(self.r0, self.u)], xs)
            return False
        h6 = h / 6.0
        self.begin([mm(r, exp_so3(scale(su, h6))) for r, su in zip(self.r0, self.sum_u)],
                   [add(x, scale(sk, h6)) for x, sk in zip(self.x0, self.sum_k)])
        return True


# ==========================================================================
# § 10.6 The observers. `own` = (R_hat_i, w_hat_i, s_hat_i); `nbrs` = the held
# (R_hat_j, w_hat_j, s_hat_j) with their gains A_j; `leader` = (A_0, (R_0,
# w_0, s_0)) or None.
# ==========================================================================

def omega_hat_dot_7b(g, own, gains, nbrs, leader):
    """(7b) dw_hat_i/dt = s_hat_i - k_R R_0^T psi(A_0 R_hat_i R_0^T) - k_w (w_hat_i - w_0)
    - k_R sum_j R_hat_j^T psi(A_j R_hat_i R_hat_j^T) - k_w sum_j (w_hat_i - w_hat_j)."""
    r_i, w_i, s_i = own
    d = s_i
    if leader is not None:
        a0, (r0, w0, _) = leader
        d = sub(d, scale(mv(tr(r0), psi_mm(mm(a0, r_i), tr(r0))), g["k_r"]))
        d = sub(d, scale(sub(w_i, w0), g["k_w"]))
    for a, (r_j, w_j, _) in zip(gains, nbrs):
        d = sub(d, scale(mv(tr(r_j), psi_mm(mm(a, r_i), tr(r_j))), g["k_r"]))
        d = sub(d, scale(sub(w_i, w_j), g["k_w"]))
    return d


def sigma_hat_dot_7c(g, p, own, nbrs, leader):
    """(7c) ds_hat_i/dt = P s_hat_i - k_sigma sum_j (s_hat_i - s_hat_j)
    - k_sigma (s_hat_i - s_0)."""
    s_i = own[2]
    e = mv(p, s_i)
    for (_, _, s_j) in nbrs:
        e = sub(e, scale(sub(s_i, s_j), g["k_sigma"]))
    if leader is not None:
        e = sub(e, scale(sub(s_i, leader[1][2]), g["k_sigma"]))
    return e


def omega_hat_dot_16b(g, own, gains, nbrs, leader):
    """(16b) dw_hat_i/dt = -k_R sum_j psi(A_j R_hat_j^T R_hat_i) - k_w sum_j (w_hat_i - w_hat_j)
    - k_R psi(A_0 R_0^T R_hat_i) - k_w w_hat_i."""
    r_i, w_i, _ = own
    d = ZERO
    for a, (r_j, w_j, _) in zip(gains, nbrs):
        d = sub(d, scale(psi_mm(mm(a, tr(r_j)), r_i), g["k_r"]))
        d = sub(d, scale(sub(w_i, w_j), g["k_w"]))
    if leader is not None:
        a0, (r0, _, _) = leader
        d = sub(d, scale(psi_mm(mm(a0, tr(r0)), r_i), g["k_r"]))
        d = sub(d, scale(w_i, g["k_w"]))
    return d


# ==========================================================================
# § 10.7 The control laws (signs as corrected in docs/paper.md, erratum 1)
# ==========================================================================

def tracking_error(r, w, r_hat, w_hat):
    """R_bar = R_hat^T R, v = R_bar^T w_hat, w_bar = w - v (Section timevarying)."""
    r_bar = mm(tr(r_hat), r)
    v = mv(tr(r_bar), w_hat)
    return r_bar, v, sub(w, v)


def sigma_i(j, v, w_bar):
    """(sigmai, corrected) Sigma_i = (J w_bar)^x + (J v)^x - v^x J - J v^x."""
    hv = hat(v)
    return msub(msub(madd(hat(mv(j, w_bar)), hat(mv(j, v))), mm(hv, j)), mm(j, hv))


def gamma_i(j, r_bar, v, w_hat_dot):
    """(gammai, corrected) Gamma_i = -v x J v - J R_bar^T dw_hat/dt."""
    return sub(neg(cross(v, mv(j, v))), mv(j, mv(tr(r_bar), w_hat_dot)))


def pd(g, a_bar, r_bar, w_bar):
    """k_R psi(A_bar R_bar) + k_w w_bar, shared by both observer-based laws."""
    return add(scale(psi_mm(a_bar, r_bar), g["k_r"]), scale(w_bar, g["k_w"]))


def tau_control(g, j, a_bar, error, w_hat_dot):
    """(control) tau_i = -Sigma_i w_bar - Gamma_i - k_R psi(A_bar R_bar) - k_w w_bar."""
    r_bar, v, w_bar = error
    return sub(sub(mv(mneg(sigma_i(j, v, w_bar)), w_bar), gamma_i(j, r_bar, v, w_hat_dot)),
               pd(g, a_bar, r_bar, w_bar))


def tau_control_constant_estimate(g, j, a_bar, error, w_hat_dot):
    """(controlconstantestimate) tau_i = -Gamma_i - k_R psi(A_bar R_bar) - k_w w_bar."""
    r_bar, v, w_bar = error
    return sub(neg(gamma_i(j, r_bar, v, w_hat_dot)), pd(g, a_bar, r_bar, w_bar))


def tau_districontrol(g, r, w, gains, nbrs, leader):
    """(districontrol) tau_i = -k_w w_i - k_R psi(A_0 R_0^T R_i) - k_R sum_j psi(A_j R_j^T R_i)."""
    tau = scale(neg(w), g["k_w"])
    if leader is not None:
        a0, (r0, _, _) = leader
        tau = sub(tau, scale(psi_mm(mm(a0, tr(r0)), r), g["k_r"]))
    for a, (r_j, _, _) in zip(gains, nbrs):
        tau = sub(tau, scale(psi_mm(mm(a, tr(r_j)), r), g["k_r"]))
    return tau


def omega_dot(j, j_inv, w, tau):
    """(followeri) dw_i/dt = J^-1 (tau_i - w_i x J w_i)."""
    return mv(j_inv, sub(tau, cross(w, mv(j, w))))


# ==========================================================================
# § 10.5, § 10.8 The agent
# ==========================================================================

class Agent:
    """One follower, stage by stage, as the node loop drives it: `exchanged`
    (what to publish), `receive` (a validated input), `advance` (evaluate the
    stage with the held values and move on)."""

    def __init__(self, model, initial, dt):
        self.scheme = model["scheme"]["kind"]
        self.control = gains_of(model["scheme"]["control"])
        self.observer = (gains_of(model["scheme"]["observer"])
                         if self.scheme != "observerless" else None)
        self.j = matrix(model["inertia"]["j"])
        self.j_inv = matrix(model["inertia"]["j_inv"])  # as given: never invert J (§ 10)
        self.a_bar = matrix(model["a_bar"]) if self.observer else None
        self.p = matrix(model["p"]) if self.scheme == "observer-time-varying" else None
        self.gains = [matrix(n["a"]) for n in model["neighbours"]]
        self.leader_gain = (None if model.get("leader_gain") is None
                            else matrix(model["leader_gain"]))
        # Held values (R, w, s) per neighbour, then the leader: (I, 0, 0)
        # until something valid arrives (§ 8).
        self.held = [(IDENTITY, ZERO, ZERO)] * (len(self.gains) + (self.leader_gain is not None))
        self.peak_torque = 0.0
        self.tau0 = ZERO  # the torque applied at stage 0 of the current step
        r, w = matrix(initial["r"]), vec3(initial["w"])
        r_hat = matrix(initial["r_hat"])
        w_hat, s_hat = vec3(initial["w_hat"]), vec3(initial["s_hat"])
        if self.observer:
            self.rk = Rkmk4([r, r_hat], [w, w_hat, s_hat], dt)
        else:
            # The observerless scheme integrates R_hat, w_hat, s_hat with
            # zero rates: they stay the configured values (§ 10.8).
            self.rk = Rkmk4([r], [w], dt)
            self.constant_hat = (r_hat, w_hat, s_hat)

    def state(self):
        """(R_i, w_i, R_hat_i, w_hat_i, s_hat_i) at the current stage point."""
        rots, vecs = self.rk.point
        if self.observer:
            return rots[0], vecs[0], rots[1], vecs[1], vecs[2]
        r_hat, w_hat, s_hat = self.constant_hat
        return rots[0], vecs[0], r_hat, w_hat, s_hat

    def exchanged(self):
        """What the agent publishes at this stage: (R_hat, w_hat, s_hat) with
        an observer, (R, w, 0) without (§ 10.5)."""
        r, w, r_hat, w_hat, s_hat = self.state()
        return (r_hat, w_hat, s_hat) if self.observer else (r, w, ZERO)

    def receive(self, k, value):
        """Holds the valid value (R, w, s) of input k (the order of `inputs`)."""
        self.held[k] = value

    def advance(self):
        """§ 10.8: evaluates the stage and pushes it into RKMK4; True when a
        step is complete."""
        r, w, r_hat, w_hat, s_hat = self.state()
        n = len(self.gains)
        nbrs = self.held[:n]
        leader = (self.leader_gain, self.held[n]) if self.leader_gain is not None else None
        own = (r_hat, w_hat, s_hat)
        if self.scheme == "observer-time-varying":
            w_hat_dot = omega_hat_dot_7b(self.observer, own, self.gains, nbrs, leader)
            s_hat_dot = sigma_hat_dot_7c(self.observer, self.p, own, nbrs, leader)
            error = tracking_error(r, w, r_hat, w_hat)
            tau = tau_control(self.control, self.j, self.a_bar, error, w_hat_dot)
        elif self.scheme == "observer-constant":
            w_hat_dot = omega_hat_dot_16b(self.observer, own, self.gains, nbrs, leader)
            s_hat_dot = ZERO
            error = tracking_error(r, w, r_hat, w_hat)
            tau = tau_control_constant_estimate(self.control, self.j, self.a_bar, error,
                                                w_hat_dot)
        else:
            tau = tau_districontrol(self.control, r, w, self.gains, nbrs, leader)
        if self.rk.stage == 0:  # only the torque at a step's start counts
            self.peak_torque = max(self.peak_torque, norm(tau))
            self.tau0 = tau
        w_dot = omega_dot(self.j, self.j_inv, w, tau)
        if self.observer:
            return self.rk.push([w, w_hat], [w_dot, w_hat_dot, s_hat_dot])
        return self.rk.push([w], [w_dot])

    def sample(self, node_id, step):
        """Telemetry Sample: the state at the start of the current step."""
        r, w, r_hat, w_hat, s_hat = self.state()
        return telemetry(node_id, SAMPLE, SAMPLE_BODY, step, *r, *w, *r_hat, *w_hat,
                         *s_hat, self.peak_torque)

    def torque(self, node_id, step):
        """Telemetry Torque (kind 7): the torque applied at stage 0 of the
        current step, which is step `step`."""
        return telemetry(node_id, TORQUE, TORQUE_BODY, step, *self.tau0)


def gains_of(g):
    return {key: float(g[key]) for key in ("k_r", "k_w", "k_sigma") if key in g}


def matrix(x):
    """A matrix of the configuration: 9 numbers, column-major (§ 2)."""
    if len(x) != 9:
        raise NodeError(f"invalid node config: a matrix has {len(x)} entries, not 9", 2)
    m = [float(v) for v in x]
    return (m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8])


def vec3(x):
    if len(x) != 3:
        raise NodeError(f"invalid node config: a vector has {len(x)} entries, not 3", 2)
    return tuple(float(v) for v in x)


# ==========================================================================
# § 8 Values from other processes are not trusted
# ==========================================================================

def rotation_defect(r):
    """||R^T R - I||_F, column by column."""
    m = msub(mm(tr(r), r), IDENTITY)
    n = [m[c] * m[c] + m[3 + c] * m[3 + c] + m[6 + c] * m[6 + c] for c in range(3)]
    return math.sqrt(n[0] + n[1] + n[2])


def det(r):
    return (r[0] * (r[4] * r[8] - r[7] * r[5]) - r[1] * (r[3] * r[8] - r[6] * r[5])
            + r[2] * (r[3] * r[7] - r[6] * r[4]))


def validated(m):
    """The (R, w, s) of an unpacked StateMsg if all 15 numbers are finite and
    R is a rotation, else None."""
    values = m[6:]
    if not all(map(math.isfinite, values)):
        return None
    r = values[:9]
    if rotation_defect(r) > ROTATION_TOLERANCE or det(r) <= 0.0:
        return None
    return r, values[9:12], values[12:15]


def why_invalid(m):
    if not all(math.isfinite(v) for v in m[6:]):
        return "a value is NaN or infinite"
    return (f"the attitude is not a rotation (||R^T R - I|| = "
            f"{rotation_defect(m[6:15]):.3e}, det R = {det(m[6:15]):.3e})")


def check_origin(m, sender):
    """Version and sender of a message on `sender`'s state service."""
    if m[0] != PROTOCOL_VERSION:
        raise NodeError(f"protocol violation: node {sender} speaks protocol version {m[0]}, "
                        f"this node {PROTOCOL_VERSION}", failed=(FAIL_BAD_INPUT, sender))
    if m[1] != sender:
        raise NodeError(f"protocol violation: a message on node {sender}'s state service "
                        f"claims sender {m[1]}", failed=(FAIL_BAD_INPUT, sender))


class Refusals:
    """Messages refused per input (§ 8), with one warning per input."""

    def __init__(self, inputs):
        self.inputs = inputs
        self.count = [0] * len(inputs)

    def accept(self, k, m):
        value = validated(m)
        if value is None:
            if self.count[k] == 0:
                log(f"WARN refused a state from node {self.inputs[k]} at step {m[2]} stage "
                    f"{m[3]}: {why_invalid(m)} (further refusals are only counted)")
            self.count[k] += 1
        return value


# ==========================================================================
# § 2 The configuration
# ==========================================================================

def config_path(argv):
    path = None
    args = argv[1:]
    i = 0
    while i < len(args):
        if args[i] == "--config" and i + 1 < len(args):
            path = args[i + 1]
            i += 2
        elif args[i].startswith("--config="):
            path = args[i].split("=", 1)[1]
            i += 1
        else:
            raise NodeError(f"unexpected argument {args[i]!r} (usage: agent.py --config FILE)", 2)
    path = path or os.environ.get("ATTSYNC_CONFIG")
    if not path:
        raise NodeError("no node configuration (usage: agent.py --config FILE, "
                        "or env ATTSYNC_CONFIG)", 2)
    return path


def read_config(path):
    try:
        with open(path, encoding="utf-8") as f:
            cfg = json.load(f)  # floats: correctly rounded, exact round trip
    except OSError as e:
        raise NodeError(f"{path}: cannot read: {e}", 2) from e
    except ValueError as e:
        raise NodeError(f"{path}: invalid node config: {e}", 2) from e
    version = cfg.get("protocol_version") if isinstance(cfg, dict) else None
    if version != PROTOCOL_VERSION:
        raise NodeError(f"{path}: protocol version {version} but this program "
                        f"speaks {PROTOCOL_VERSION}", 2)
    try:
        check_config(path, cfg)
    except (KeyError, TypeError, ValueError, AttributeError) as e:
        raise NodeError(f"{path}: invalid node config: {e!r}", 2) from e
    return cfg


def check_config(path, cfg):
    """Refuses (exit 2) what this agent does not implement."""
    unsupported = []
    role = cfg["role"]
    if role.get("kind") != "agent":
        unsupported.append(f"role {role.get('kind')!r}: the Python agent is a follower only")
    else:
        model = role["model"]
        kind = model["scheme"]["kind"]
        if kind not in SCHEMES:
            unsupported.append(f"unknown scheme {kind!r}")
        links = [n.get("link") for n in model["neighbours"]] + [model.get("leader_link")]
        if any(link is not None for link in links):
            unsupported.append("impaired links (delay, jitter, loss, period) are not "
                               "supported by the Python agent")
        expected = [n["id"] for n in model["neighbours"]]
        if model.get("leader_gain") is not None:
            expected.append(0)
        if list(cfg["inputs"]) != expected:
            raise NodeError(f"{path}: inputs {cfg['inputs']} do not match the model's "
                            f"neighbours and leader link {expected}", 2)
    mode = cfg["coupling"]["mode"]
    if mode not in ("continuous", "sampled"):
        unsupported.append(f"coupling {mode!r} is not supported")
    elif mode == "sampled" and int(cfg["coupling"]["every"]) < 1:
        raise NodeError(f"{path}: coupling.every must be >= 1", 2)
    if int(cfg["sample_every"]) < 1:
        raise NodeError(f"{path}: sample_every must be >= 1", 2)
    factor = cfg.get("realtime")
    if factor is not None and not float(factor) > 0.0:
        raise NodeError(f"{path}: realtime must be a factor > 0, not {factor}", 2)
    if unsupported:
        raise NodeError(f"{path}: " + "; ".join(unsupported), 2)


def exchanges_at(coupling, step, stage):
    """Whether (step, stage) is an exchange (§ 2, `coupling`)."""
    if coupling["mode"] == "continuous":
        return True
    return stage == 0 and step % coupling["every"] == 0


# ==========================================================================
# § 3, § 4 iceoryx2 ports
# ==========================================================================

# Pauses between two tries of an open (§ 6.2): short at first (two creators
# at once sort it out within milliseconds), doubling up to 50 ms.
FIRST_PAUSE, MAX_PAUSE = 0.002, 0.05
# Words in iceoryx2's errors that retrying cannot mend: the service exists
# with other settings (or another iceoryx2 version).
LASTING = ("Incompatible", "DoesNotSupport", "VersionMismatch", "ExceedsMax",
           "TypeDefinition")


def open_service_until(name, make, deadline):
    """open_or_create, retried until `deadline` (time.monotonic(); the start
    timeout): another process may still be creating the service, and on a
    busy machine iceoryx2's own wait for it (1 s) runs out. An error that
    says the settings differ is not retried."""
    start, pause, tries = time.monotonic(), FIRST_PAUSE, 0
    while True:
        tries += 1
        try:
            return make()
        except Exception as e:  # iceoryx2 raises its own error types
            text = f"{type(e).__name__} {e!r}"
            if any(word in text for word in LASTING):
                raise NodeError(f"cannot open service {name}: {e!r} (not retried)") from e
            if time.monotonic() + pause > deadline:
                waited = time.monotonic() - start
                raise NodeError(f"cannot open service {name}: not ready after {waited:.1f} s "
                                f"({tries} tries); last error: {e!r}") from e
            time.sleep(pause)
            pause = min(2 * pause, MAX_PAUSE)


class Ports:
    """Every port of the node, with the settings of § 4."""

    def __init__(self, iox2, cfg):
        self.iox2 = iox2
        run, node_id, lim = cfg["run"], cfg["id"], cfg["limits"]
        fanout, nodes = lim["max_fanout"], lim["nodes"]
        state_buffer, telemetry_buffer = lim["state_buffer"], lim["telemetry_buffer"]
        retry = iox2.BackpressureStrategy.RetryUntilDelivered
        # Lockstep: a full receiver holds the sender back (flow control).
        # Real time: a receiver that falls behind misses messages instead.
        state_strategy = retry if cfg["realtime"] is None else iox2.BackpressureStrategy.DiscardData

        # The run's namespace (§ 3).
        ioxcfg = iox2.config.default()
        root = cfg["iox_root"]
        if not root.endswith("/"):
            root += "/"
        ioxcfg.global_cfg.prefix = iox2.FileName.new(f"as{run}_")
        ioxcfg.global_cfg.root_path = iox2.Path.new(root)
        self.node = (iox2.NodeBuilder.new()
                     .name(iox2.NodeName.new(f"agent_{node_id}"))
                     .config(ioxcfg)
                     .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
                     .create(iox2.ServiceType.Ipc))

        def service(name):
            return self.node.service_builder(iox2.ServiceName.new(f"attsync/{run}/{name}"))

        # Every open is retried within the start timeout (§ 6.2).
        deadline = time.monotonic() + float(cfg["start_timeout"])

        def open_service(name, make):
            return open_service_until(name, make, deadline)

        def state(j):
            return open_service(f"node/{j}/state", lambda: (
                service(f"node/{j}/state").publish_subscribe(StateMsg)
                .max_publishers(1).max_subscribers(fanout).max_nodes(fanout + 2)
                .history_size(0).subscriber_max_buffer_size(state_buffer)
                .subscriber_max_borrowed_samples(2).enable_safe_overflow(False)
                .open_or_create()))

        def wake(j):
            return open_service(f"node/{j}/wake", lambda: (
                service(f"node/{j}/wake").event()
                .max_listeners(1).max_notifiers(fanout + 1).max_nodes(fanout + 3)
                .open_or_create()))

        # NOTE: the Python binding has no backpressure handler, so unlike the
        # Rust node RetryUntilDelivered is not bounded by the stage timeout;
        # an agent's receivers are also its inputs, so it is never more than
        # one exchange ahead of them and their buffer never fills.
        self.own = state(node_id)
        self.publisher = self.own.publisher_builder().backpressure_strategy(state_strategy).create()
        self.own_wake = wake(node_id)
        self.listener = self.own_wake.listener_builder().create()
        self.tele = open_service(f"node/{node_id}/telemetry", lambda: (
            service(f"node/{node_id}/telemetry").publish_subscribe(TelemetryMsg)
            .max_publishers(1).max_subscribers(2).max_nodes(4)
            .history_size(0).subscriber_max_buffer_size(telemetry_buffer)
            .subscriber_max_borrowed_samples(2).enable_safe_overflow(False)
            .open_or_create()))
        self.tele_pub = self.tele.publisher_builder().backpressure_strategy(retry).create()
        self.orch_wake = open_service("orchestrator/wake", lambda: (
            service("orchestrator/wake").event()
            .max_listeners(1).max_notifiers(nodes + 1).max_nodes(nodes + 2)
            .open_or_create()))
        self.orch_notifier = self.orch_wake.notifier_builder().create()
        self.control_svc = open_service("control", lambda: (
            service("control").publish_subscribe(ControlMsg)
            .max_publishers(1).max_subscribers(nodes + 1).max_nodes(nodes + 2)
            .history_size(2).subscriber_max_buffer_size(4)
            .open_or_create()))
        self.control = self.control_svc.subscriber_builder().create()
        self.input_services = [state(j) for j in cfg["inputs"]]
        self.inputs = [s.subscriber_builder().buffer_size(state_buffer).create()
                       for s in self.input_services]
        self.wake_services = [wake(j) for j in cfg["outputs"]]
        self.notifiers = [s.notifier_builder().create() for s in self.wake_services]

    def await_connections(self, cfg, orphan):
        """§ 6.3 Readiness barrier: every receiver of our state, the
        orchestrator's telemetry subscriber and the sender of every input
        are connected."""
        timeout = float(cfg["start_timeout"])
        ready_by = time.monotonic() + timeout
        n_out = len(cfg["outputs"])
        while True:
            subs = self.own.dynamic_config.number_of_subscribers
            orch = self.tele.dynamic_config.number_of_subscribers
            missing = [j for j, s in zip(cfg["inputs"], self.input_services)
                       if s.dynamic_config.number_of_publishers < 1]
            if not missing:
                # The binding has no Subscriber.update_connections();
                # has_samples() runs it (and takes nothing), so our input
                # queues are attached before any sender publishes.
                for sub in self.inputs:
                    sub.has_samples()
            if subs >= n_out and orch >= 1 and not missing:
                return
            orphan.check()
            if time.monotonic() > ready_by:
                raise NodeError(f"timed out after {timeout:.1f} s waiting for connections "
                                f"(receivers {subs}/{n_out}, orchestrator {orch}, inputs "
                                f"without a publisher {missing})")
            time.sleep(0.001)

    def publish(self, payload, notify=True):
        """Sends our state (packed STATE bytes) and wakes every receiver."""
        loan = self.publisher.loan_uninit()
        ctypes.memmove(loan.payload_ptr, payload, STATE.size)
        loan.assume_init().send()
        if notify:
            for nt in self.notifiers:
                try:
                    nt.notify()
                except Exception:  # a lost wake-up only delays a receiver
                    pass

    def take(self, k):
        """One message of input k, unpacked, or None."""
        sample = self.inputs[k].receive()
        if sample is None:
            return None
        m = STATE.unpack(ctypes.string_at(sample.payload_ptr, STATE.size))
        sample.delete()
        return m

    def report(self, payload):
        """Sends a telemetry message (TelemetryMsg bytes) and wakes the orchestrator."""
        loan = self.tele_pub.loan_uninit()
        ctypes.memmove(loan.payload_ptr, payload, TELEMETRY_SIZE)
        loan.assume_init().send()
        try:
            self.orch_notifier.notify()
        except Exception:  # a lost wake-up only delays the orchestrator
            pass

    def release(self):
        """§ 3 Leaving cleanly: delete every port, drop every service and the
        node, and collect, so that nothing of ours is left in iceoryx2."""
        ports = ([self.publisher, self.listener, self.tele_pub, self.orch_notifier,
                  self.control] + self.inputs + self.notifiers)
        for p in ports:
            try:
                p.delete()
            except Exception:
                pass
        self.inputs = self.notifiers = self.input_services = self.wake_services = []
        self.publisher = self.listener = self.tele_pub = self.orch_notifier = None
        self.control = self.control_svc = self.own = self.own_wake = None
        self.tele = self.orch_wake = None
        self.node = None
        gc.collect()


def alive(pid):
    """Whether process `pid` exists and is not a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] not in ("Z", "X")
    except (OSError, IndexError):
        return False


class Orphan:
    """Detects that the process that started us (the orchestrator) is gone
    (§ 1, § 6): the parent to watch is ATTSYNC_PARENT_PID if that is our
    parent, else (a wrapper between us) our parent while that pid lives; if
    it is gone already, we were orphaned before we could look."""

    def __init__(self):
        self.parent = os.getppid()
        expected = os.environ.get("ATTSYNC_PARENT_PID", "")
        if expected.isdigit() and int(expected) != self.parent and not alive(int(expected)):
            raise NodeError(f"the orchestrator (pid {expected}) has exited")

    def check(self):
        if os.getppid() != self.parent:
            raise NodeError(f"the orchestrator (pid {self.parent}) has exited")


def wait_command(ports, timeout, orphan):
    """Polls the control service every millisecond (bounded) for a command:
    (command, start_unix_ns)."""
    deadline = time.monotonic() + timeout
    while True:
        sample = ports.control.receive()
        if sample is not None:
            version, command, start_ns = CONTROL.unpack(
                ctypes.string_at(sample.payload_ptr, CONTROL.size))
            sample.delete()
            if version != PROTOCOL_VERSION:
                raise NodeError(f"protocol violation: orchestrator speaks protocol version "
                                f"{version}, this node {PROTOCOL_VERSION}")
            return command, start_ns
        orphan.check()
        if time.monotonic() > deadline:
            raise NodeError(f"timed out after {timeout:.1f} s waiting for a command "
                            "from the orchestrator")
        time.sleep(0.001)


def state_msg(node_id, n, s, value, sent_ns=0):
    """A StateMsg's bytes: (R, w, s) stamped (n, s)."""
    r, w, sv = value
    return STATE.pack(PROTOCOL_VERSION, node_id, n, s, 0, sent_ns, *r, *w, *sv)


# ==========================================================================
# § 6 Lockstep
# ==========================================================================

class Waiter:
    """How to wait for an input (`wait` of the configuration): a few
    sched_yield()s, then sleeps on our wake event in 1 ms slices."""

    def __init__(self, ports, cfg):
        self.listener = ports.listener
        self.slice = ports.iox2.Duration.from_millis(BLOCK_SLICE_MS)
        # -1 never sleeps (spin and yield both call sched_yield here: a
        # spinning Python process would starve its peers).
        self.yields = {"spin": -1, "yield": -1, "block": 0}.get(cfg.get("wait"), ADAPTIVE_YIELDS)
        self.polls = 0

    def wait(self):
        self.polls += 1
        if self.yields < 0 or self.polls <= self.yields:
            os.sched_yield()
        else:
            self.listener.timed_wait(self.slice)


def await_input(ports, k, cfg, n, s, orphan):
    """§ 6.7.3: one message of input k, waiting at most `stage_timeout`."""
    m = ports.take(k)
    if m is not None:
        return m
    waiter = Waiter(ports, cfg)
    deadline = time.monotonic() + float(cfg["stage_timeout"])
    while True:
        waiter.wait()
        m = ports.take(k)
        if m is not None:
            return m
        if waiter.polls % 64 == 0 or waiter.polls > waiter.yields >= 0:
            if time.monotonic() > deadline:
                sender = cfg["inputs"][k]
                raise NodeError(f"timed out after {cfg['stage_timeout']:.1f} s waiting for "
                                f"node {sender}'s state of step {n} stage {s}",
                                failed=(FAIL_TIMEOUT, sender))
            if waiter.polls % 256 == 0:
                orphan.check()


def lockstep(ports, cfg, agent, refusals, orphan):
    """Steps `steps` steps in lockstep; returns the pacing (0, 0.0)."""
    node_id, steps, sample_every = cfg["id"], int(cfg["steps"]), int(cfg["sample_every"])
    inputs = cfg["inputs"]
    ports.report(agent.sample(node_id, 0))
    for n in range(steps):
        if n % 256 == 0:
            orphan.check()
        for s in range(4):
            if exchanges_at(cfg["coupling"], n, s):
                ports.publish(state_msg(node_id, n, s, agent.exchanged()))
                for k, sender in enumerate(inputs):
                    m = await_input(ports, k, cfg, n, s, orphan)
                    check_origin(m, sender)
                    if (m[2], m[3]) != (n, s):
                        raise NodeError(f"protocol violation: node {sender} sent step {m[2]} "
                                        f"stage {m[3]} where step {n} stage {s} was due",
                                        failed=(FAIL_BAD_INPUT, sender))
                    value = refusals.accept(k, m)
                    if value is not None:  # a refused value is like a lost one
                        agent.receive(k, value)
            agent.advance()
            if s == 0 and n % sample_every == 0:
                ports.report(agent.torque(node_id, n))
        if (n + 1) % sample_every == 0 or n + 1 == steps:
            ports.report(agent.sample(node_id, n + 1))
    return 0, 0.0


# ==========================================================================
# § 7 Real time
# ==========================================================================

STAGE_C = (0.0, 0.5, 0.5, 1.0)


class LinkMeter:
    """The measured counters of one input in real time (LinkStats, § 5)."""

    def __init__(self):
        self.newest = None  # (step, stage) of the newest message seen
        self.held_sent_ns = None  # sent_unix_ns of the value held
        self.delivered = self.evaluations = 0
        self.age_sum = self.age_max = 0.0

    def age(self, factor):
        """Counts the age of information of the held value, simulated s."""
        if self.held_sent_ns is not None:
            age = max(unix_ns() - self.held_sent_ns, 0) * 1e-9 * factor
            self.age_sum += age
            self.age_max = max(self.age_max, age)
            self.evaluations += 1


def drain(ports, k, meter, refusals, sender):
    """Takes everything input k has; the newest valid (value, sent_unix_ns) or None."""
    fresh = None
    while True:
        m = ports.take(k)
        if m is None:
            return fresh
        check_origin(m, sender)
        if meter.newest is not None and meter.newest >= (m[2], m[3]):
            continue  # older than what we have seen
        meter.newest = (m[2], m[3])
        value = refusals.accept(k, m)
        if value is not None:
            meter.delivered += 1
            fresh = (value, m[5])


def first_states(ports, k, meter, refusals, cfg, orphan):
    """At (0, 0) only: waits (bounded) until input k's first state arrives."""
    sender = cfg["inputs"][k]
    deadline = time.monotonic() + float(cfg["stage_timeout"])
    fresh = drain(ports, k, meter, refusals, sender)
    while meter.newest is None:
        if time.monotonic() > deadline:
            raise NodeError(f"timed out after {cfg['stage_timeout']:.1f} s waiting for node "
                            f"{sender}'s state of step 0 stage 0",
                            failed=(FAIL_TIMEOUT, sender))
        orphan.check()
        ports.listener.timed_wait(ports.iox2.Duration.from_millis(BLOCK_SLICE_MS))
        fresh = drain(ports, k, meter, refusals, sender)
    return fresh


def realtime(ports, cfg, agent, refusals, orphan, start_unix_ns):
    """Steps `steps` steps against the wall clock; returns the pacing
    (late_stages, max_lateness) and the meter of every input."""
    node_id, steps, sample_every = cfg["id"], int(cfg["steps"]), int(cfg["sample_every"])
    factor = float(cfg["realtime"])
    step_wall = float(cfg["dt"]) / factor
    # T0 on the monotonic clock: simulated t = 0 is wall time start_unix_ns.
    t0 = time.monotonic() + (start_unix_ns - unix_ns()) * 1e-9
    meters = [LinkMeter() for _ in cfg["inputs"]]
    late_stages, max_lateness, exchanges = 0, 0.0, 0
    ports.report(agent.sample(node_id, 0))
    for n in range(steps):
        if n % 256 == 0:
            orphan.check()
        for s in range(4):
            lateness = time.monotonic() - (t0 + (n + STAGE_C[s]) * step_wall)
            if lateness < 0.0:
                time.sleep(-lateness)
            else:
                max_lateness = max(max_lateness, lateness)
                if lateness > step_wall:  # more than one step late
                    late_stages += 1
            if exchanges_at(cfg["coupling"], n, s):
                exchanges += 1
                first = n == 0 and s == 0
                ports.publish(state_msg(node_id, n, s, agent.exchanged(), unix_ns()),
                              notify=first)
                for k, meter in enumerate(meters):
                    if first:
                        fresh = first_states(ports, k, meter, refusals, cfg, orphan)
                    else:
                        fresh = drain(ports, k, meter, refusals, cfg["inputs"][k])
                    if fresh is not None:
                        agent.receive(k, fresh[0])
                        meter.held_sent_ns = fresh[1]
                    meter.age(factor)
            agent.advance()
            if s == 0 and n % sample_every == 0:
                ports.report(agent.torque(node_id, n))
        if (n + 1) % sample_every == 0 or n + 1 == steps:
            ports.report(agent.sample(node_id, n + 1))
    return (late_stages, max_lateness), meters, exchanges


# ==========================================================================
# § 6 The life of the node
# ==========================================================================

def link_stats(cfg, refusals, measured):
    """LinkStats to report: every input in real time (measured), in
    lockstep every input on which a message was refused."""
    reports = []
    if measured is not None:
        meters, exchanges = measured
        for k, (sender, m) in enumerate(zip(cfg["inputs"], meters)):
            reports.append(telemetry(cfg["id"], LINK_STATS, LINK_STATS_BODY, sender, exchanges,
                                     m.delivered, max(exchanges - m.delivered, 0),
                                     refusals.count[k], m.evaluations, m.age_sum, m.age_max))
    else:
        for k, sender in enumerate(cfg["inputs"]):
            if refusals.count[k]:
                reports.append(telemetry(cfg["id"], LINK_STATS, LINK_STATS_BODY, sender, 0, 0,
                                         0, refusals.count[k], 0, 0.0, 0.0))
    return reports


def step_all(ports, cfg, agent, orphan):
    """Ready, Start, the steps, LinkStats and Done (§ 6.4-6.8)."""
    node_id = cfg["id"]
    ports.await_connections(cfg, orphan)
    ports.report(telemetry(node_id, READY))
    log(f"ready (id {node_id}, inputs {cfg['inputs']}, outputs {cfg['outputs']}, "
        f"scheme {agent.scheme}, realtime {cfg['realtime']})")
    command, start_ns = wait_command(ports, float(cfg["start_timeout"]), orphan)
    if command != START:
        raise NodeError("stopped before the end (at step 0)")
    started_ns, t_start = unix_ns(), time.monotonic()
    refusals = Refusals(cfg["inputs"])
    try:
        if cfg["realtime"] is None:
            pacing, measured = lockstep(ports, cfg, agent, refusals, orphan), None
        else:
            pacing, meters, exchanges = realtime(ports, cfg, agent, refusals, orphan,
                                                 start_ns or started_ns)
            measured = (meters, exchanges)
    except Exception as e:
        # Tell the orchestrator whom we waited for, or that it was something
        # else (best effort: we are failing anyway).
        reason, sender = getattr(e, "failed", None) or (FAIL_OTHER, 0)
        try:
            ports.report(telemetry(node_id, FAILED, FAILED_BODY, reason, sender))
        except Exception:
            pass
        raise
    done_ns, wall = unix_ns(), time.monotonic() - t_start
    for report in link_stats(cfg, refusals, measured):
        ports.report(report)
    rss = peak_rss_kb()
    ports.report(telemetry(node_id, DONE, DONE_BODY, int(cfg["steps"]), agent.peak_torque,
                           rss, started_ns, done_ns, pacing[0], pacing[1]))
    log(f"done: {cfg['steps']} steps in {wall:.2f} s, peak torque {agent.peak_torque!r}, "
        f"late stages {pacing[0]}, max lateness {pacing[1]:.6f} s, peak_rss_kb={rss}")


def import_iceoryx2():
    """The iceoryx2 binding, version 0.10 (the wire format of the Rust side)."""
    try:
        import iceoryx2 as iox2
    except ImportError as e:
        raise NodeError(f"cannot import the Python package iceoryx2 ({e}): install it with "
                        "`python3 -m pip install -r examples/python/requirements.txt`", 2) from e
    try:
        from importlib.metadata import version
        found = version("iceoryx2")
    except Exception:
        found = None
    if found is not None and not found.startswith("0.10."):
        raise NodeError(f"iceoryx2 {found} is installed, but attsync speaks iceoryx2 0.10 "
                        "(`python3 -m pip install iceoryx2==0.10.0`)", 2)
    return iox2


def run(cfg):
    iox2 = import_iceoryx2()
    iox2.set_log_level(iox2.LogLevel.Error)  # else a "no config file" warning
    role = cfg["role"]
    try:
        agent = Agent(role["model"], role["initial"], float(cfg["dt"]))
    except (KeyError, TypeError, ValueError) as e:
        raise NodeError(f"invalid node config: {e!r}", 2) from e
    orphan = Orphan()
    ports = Ports(iox2, cfg)
    try:
        step_all(ports, cfg, agent, orphan)
        command, _ = wait_command(ports, STOP_TIMEOUT, orphan)  # § 6.9
        if command == START:
            raise NodeError("protocol violation: second Start")
    finally:
        ports.release()


def main(argv):
    try:
        run(read_config(config_path(argv)))
    except NodeError as e:
        log(f"ERROR {e}")
        return e.code
    except KeyboardInterrupt:
        return 130
    except Exception:  # an iceoryx2 error or a bug: say where
        import traceback
        log("ERROR " + traceback.format_exc().rstrip().replace("\n", "\n    "))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
