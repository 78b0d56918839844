#!/usr/bin/env python3
"""An attsync agent written in Python: a plug-in that replaces one built-in
`attsync-agent` process.

It runs scheme 3 of the paper, the observerless law `districontrol`

    tau_i = -k_R psi(A_i0 R_0^T R_i) - k_R sum_j psi(A_ij R_j^T R_i) - k_w w_i

on the rigid body J_i dw_i/dt = -w_i x J_i w_i + tau_i, dR_i/dt = R_i hat(w_i),
integrated with RKMK4 stage by stage exactly as attitude/src/integrate.rs does
(same operations in the same order, pure Python floats: IEEE binary64, no
fused multiply-add), so its trajectory matches the built-in agent's bit for
bit.

It speaks attsync's node protocol (version 2) over iceoryx2 shared memory
(PyPI `iceoryx2==0.10.0`): started as `<command...> --config FILE` (also in
env ATTSYNC_CONFIG), it reads the node's JSON configuration, opens every
service with the limits of msgs/src/open.rs in the run's iceoryx2 namespace
(prefix `as<run>_`, root path `iox_root`), waits until every edge is
connected, reports Ready, waits for Start, steps in deterministic lockstep,
reports telemetry samples, then Done, and waits for Stop.

Supported: lockstep only (`realtime` = null), coupling "continuous" and
"sampled", unimpaired links, the observerless scheme. Anything else is
refused at start-up with exit code 2. Protocol violations, timeouts and the
loss of the parent process exit with code 1; a clean run exits 0.
"""

import ctypes
import json
import math
import os
import resource
import struct
import sys
import time

PROTOCOL_VERSION = 2
ROTATION_TOLERANCE = 1e-6  # largest ||R^T R - I||_F accepted from a peer
STOP_TIMEOUT = 600.0  # s, longest wait for Stop after Done
# sched_yield()s before sleeping on the wake event (wait = "adaptive");
# env ATTSYNC_PY_YIELDS overrides it.
ADAPTIVE_YIELDS = int(os.environ.get("ATTSYNC_PY_YIELDS", "20"))
BLOCK_SLICE_MS = 1  # longest single sleep on the wake event

# Telemetry kinds and control commands (msgs/src/payload.rs).
READY, SAMPLE, DONE, LINK_STATS, FAILED = 1, 2, 3, 4, 5
START, STOP = 1, 2

PROG = "attsync python agent"


class NodeError(Exception):
    """Ends the node with a message on stderr and exit code `code`."""

    def __init__(self, msg, code=1):
        super().__init__(msg)
        self.code = code


def log(msg):
    """One line on stderr (the orchestrator writes it to logs/<node>.log)."""
    sys.stderr.write(f"{time.strftime('%H:%M:%S')} {PROG}: {msg}\n")
    sys.stderr.flush()


# --------------------------------------------------------------------------
# Wire contract: msgs/src/payload.rs. Little-endian, #[repr(C)], no padding.
# --------------------------------------------------------------------------

# StateMsg, 152 bytes: version u32, sender u32, step u64, stage u32,
# reserved u32, sent_unix_ns u64, r [f64; 9] (row-major), w [f64; 3], s [f64; 3].
STATE = struct.Struct("<IIQIIQ15d")
# TelemetryMsg, 248 bytes: version u32, sender u32, step u64, kind u32,
# reserved u32, r [9], w [3], r_hat [9], w_hat [3], s_hat [3], peak_torque f64.
TELEMETRY = struct.Struct("<IIQII28d")
# ControlMsg, 16 bytes: version u32, command u32, start_unix_ns u64.
CONTROL = struct.Struct("<IIQ")


def _c_struct(name, type_name, fields):
    """A ctypes structure: iceoryx2 matches services by type name, size and
    alignment, which must equal the Rust `#[type_name]`, size_of, align_of."""
    cls = type(name, (ctypes.Structure,), {"_fields_": fields})
    cls.type_name = staticmethod(lambda: type_name)
    return cls


U32, U64, F64 = ctypes.c_uint32, ctypes.c_uint64, ctypes.c_double
StateMsg = _c_struct("StateMsg", "attsync::StateMsg", [
    ("version", U32), ("sender", U32), ("step", U64), ("stage", U32),
    ("reserved", U32), ("sent_unix_ns", U64), ("r", F64 * 9), ("w", F64 * 3),
    ("s", F64 * 3)])
TelemetryMsg = _c_struct("TelemetryMsg", "attsync::TelemetryMsg", [
    ("version", U32), ("sender", U32), ("step", U64), ("kind", U32),
    ("reserved", U32), ("r", F64 * 9), ("w", F64 * 3), ("r_hat", F64 * 9),
    ("w_hat", F64 * 3), ("s_hat", F64 * 3), ("peak_torque", F64)])
ControlMsg = _c_struct("ControlMsg", "attsync::ControlMsg", [
    ("version", U32), ("command", U32), ("start_unix_ns", U64)])
for _cls, _size in ((StateMsg, STATE.size), (TelemetryMsg, TELEMETRY.size),
                    (ControlMsg, CONTROL.size)):
    assert ctypes.sizeof(_cls) == _size == {StateMsg: 152, TelemetryMsg: 248,
                                            ControlMsg: 16}[_cls]
    assert ctypes.alignment(_cls) == 8


# --------------------------------------------------------------------------
# SO(3) and RKMK4, operation for operation as attitude/src/{so3,integrate}.rs
# with nalgebra's evaluation order: a matrix product entry is
# (a_i0 b_0j + a_i1 b_1j) + a_i2 b_2j. Matrices are row-major 9-tuples.
# --------------------------------------------------------------------------

def mm(a, b):
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7,
            a0 * b2 + a1 * b5 + a2 * b8,
            a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7,
            a3 * b2 + a4 * b5 + a5 * b8,
            a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7,
            a6 * b2 + a7 * b5 + a8 * b8)


def mm_transposed(a, b):
    """a * b^T."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b3, b6, b1, b4, b7, b2, b5, b8 = b
    return (a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7,
            a0 * b2 + a1 * b5 + a2 * b8,
            a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7,
            a3 * b2 + a4 * b5 + a5 * b8,
            a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7,
            a6 * b2 + a7 * b5 + a8 * b8)


def psi_of_product(a, b):
    """psi(a * b) = 1/2 [m32 - m23, m13 - m31, m21 - m12], computing only the
    off-diagonal entries of m = a b (each entry as in the full product)."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    m01 = a0 * b1 + a1 * b4 + a2 * b7
    m02 = a0 * b2 + a1 * b5 + a2 * b8
    m10 = a3 * b0 + a4 * b3 + a5 * b6
    m12 = a3 * b2 + a4 * b5 + a5 * b8
    m20 = a6 * b0 + a7 * b3 + a8 * b6
    m21 = a6 * b1 + a7 * b4 + a8 * b7
    return (0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01))


def mv(a, v):
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    v0, v1, v2 = v
    return (a0 * v0 + a1 * v1 + a2 * v2, a3 * v0 + a4 * v1 + a5 * v2,
            a6 * v0 + a7 * v1 + a8 * v2)


def cross(a, b):
    ax, ay, az = a
    bx, by, bz = b
    return (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)


def exp_so3(u):
    """so3::exp: Rodrigues, Taylor series below theta^2 = 1e-8."""
    x, y, z = u
    t2 = x * x + y * y + z * z
    if t2 < 1e-8:
        a = 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0)
        b = 0.5 - t2 / 24.0 * (1.0 - t2 / 30.0)
    else:
        t = math.sqrt(t2)
        a = math.sin(t) / t
        b = (1.0 - math.cos(t)) / t2
    k = (0.0, -z, y, z, 0.0, -x, -y, x, 0.0)
    kk = mm(k, k)
    return (1.0 + k[0] * a + kk[0] * b, 0.0 + k[1] * a + kk[1] * b,
            0.0 + k[2] * a + kk[2] * b, 0.0 + k[3] * a + kk[3] * b,
            1.0 + k[4] * a + kk[4] * b, 0.0 + k[5] * a + kk[5] * b,
            0.0 + k[6] * a + kk[6] * b, 0.0 + k[7] * a + kk[7] * b,
            1.0 + k[8] * a + kk[8] * b)


def dexp_inv(u, w):
    """so3::dexp_inv: w + 1/2 u x w + c u x (u x w)."""
    u0, u1, u2 = u
    t2 = u0 * u0 + u1 * u1 + u2 * u2
    if t2 < 1e-6:
        c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    else:
        t = math.sqrt(t2)
        half = 0.5 * t
        c = (1.0 - half * math.cos(half) / math.sin(half)) / t2
    uw = cross(u, w)
    uuw = cross(u, uw)
    return (w[0] + uw[0] * 0.5 + uuw[0] * c, w[1] + uw[1] * 0.5 + uuw[1] * c,
            w[2] + uw[2] * 0.5 + uuw[2] * c)


def orthogonality_defect(r):
    """||R^T R - I||_F."""
    m = mm(tuple(r[i] for i in (0, 3, 6, 1, 4, 7, 2, 5, 8)), r)
    return math.sqrt(sum((m[i] - (1.0 if i in (0, 4, 8) else 0.0)) ** 2
                         for i in range(9)))


def det3(r):
    return (r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6])
            + r[2] * (r[3] * r[7] - r[4] * r[6]))


H_FRACTION = (0.5, 0.5, 1.0)  # integrate.rs `A`: c of stages 2-4
ZERO3 = (0.0, 0.0, 0.0)


class ObserverlessAgent:
    """attitude::agent::Agent for Scheme::Observerless, one stage at a time:
    `stage_exchange`, `receive`, `advance`, as the node loop drives it."""

    def __init__(self, model, initial, dt):
        self.k_r = float(model["scheme"]["control"]["k_r"])
        self.k_w = float(model["scheme"]["control"]["k_w"])
        self.j = matrix(model["inertia"]["j"])
        self.j_inv = matrix(model["inertia"]["j_inv"])
        self.gains = [matrix(n["a"]) for n in model["neighbours"]]
        self.leader_gain = (None if model.get("leader_gain") is None
                            else matrix(model["leader_gain"]))
        identity = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
        self.held_nbrs = [identity] * len(self.gains)  # neighbours' R_j
        self.held_leader = identity  # R_0, if linked
        self.dt = dt
        self.h6 = dt / 6.0
        self.h_a = tuple(dt * a for a in H_FRACTION)
        self.peak_torque = 0.0
        # The observer part of the state is constant in this scheme
        # (identity, 0, 0 from the orchestrator); reported as is.
        self.r_hat = matrix(initial["r_hat"])
        self.w_hat = vec3(initial["w_hat"])
        self.s_hat = vec3(initial["s_hat"])
        self._begin_step(matrix(initial["r"]), vec3(initial["w"]))

    def _begin_step(self, r, w):
        """Rkmk4::new(y0, h): the state at the start of a step."""
        self.r0, self.w0 = r, w
        self.stage = 0
        self.u = ZERO3  # Lie-algebra increment of the current stage
        self.sum_u = ZERO3
        self.sum_k = ZERO3
        self.r_stage, self.w_stage = r, w  # Rkmk4::stage_state

    def stage_exchange(self):
        """What the agent publishes at the current stage: (R, w, 0)."""
        return self.r_stage, self.w_stage

    def receive(self, k, r):
        if k < len(self.held_nbrs):
            self.held_nbrs[k] = r
        elif self.leader_gain is not None:
            self.held_leader = r

    def advance(self):
        """Evaluates the field at the stage state with the held inputs
        (agent_field / tau_districontrol / omega_dot) and pushes it into
        RKMK4 (Rkmk4::push_derivative)."""
        r, w = self.r_stage, self.w_stage
        k_r = self.k_r
        k_w = self.k_w
        # tau = -w k_w - k_R psi(A_i0 R0^T R) - k_R sum_j psi(A_ij Rj^T R)
        t0, t1, t2 = -w[0] * k_w, -w[1] * k_w, -w[2] * k_w
        if self.leader_gain is not None:
            p0, p1, p2 = psi_of_product(mm_transposed(self.leader_gain, self.held_leader), r)
            t0, t1, t2 = t0 - p0 * k_r, t1 - p1 * k_r, t2 - p2 * k_r
        for a, rj in zip(self.gains, self.held_nbrs):
            p0, p1, p2 = psi_of_product(mm_transposed(a, rj), r)
            t0, t1, t2 = t0 - p0 * k_r, t1 - p1 * k_r, t2 - p2 * k_r
        s = self.stage
        if s == 0:
            norm = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
            if norm > self.peak_torque:
                self.peak_torque = norm
        # J w_dot = -w x J w + tau
        c = cross(w, mv(self.j, w))
        w_dot = mv(self.j_inv, (t0 - c[0], t1 - c[1], t2 - c[2]))
        # RKMK4, rotation part: U = dexp_inv(u, w); vector part: k = w_dot.
        big_u = dexp_inv(self.u, w)
        weight = 1.0 if s == 0 or s == 3 else 2.0
        su, sk = self.sum_u, self.sum_k
        self.sum_u = (su[0] + big_u[0] * weight, su[1] + big_u[1] * weight,
                      su[2] + big_u[2] * weight)
        self.sum_k = (sk[0] + w_dot[0] * weight, sk[1] + w_dot[1] * weight,
                      sk[2] + w_dot[2] * weight)
        if s < 3:
            ha = self.h_a[s]
            self.u = (big_u[0] * ha, big_u[1] * ha, big_u[2] * ha)
            w0 = self.w0
            self.w_stage = (w0[0] + w_dot[0] * ha, w0[1] + w_dot[1] * ha,
                            w0[2] + w_dot[2] * ha)
            self.r_stage = mm(self.r0, exp_so3(self.u))
            self.stage = s + 1
            return False
        h6 = self.h6
        su, sk, w0 = self.sum_u, self.sum_k, self.w0
        r_next = mm(self.r0, exp_so3((su[0] * h6, su[1] * h6, su[2] * h6)))
        w_next = (w0[0] + sk[0] * h6, w0[1] + sk[1] * h6, w0[2] + sk[2] * h6)
        self._begin_step(r_next, w_next)
        return True

    def sample(self, node_id, step):
        """TelemetryMsg::agent: the state at the start of the current step."""
        return TELEMETRY.pack(PROTOCOL_VERSION, node_id, step, SAMPLE, 0,
                              *self.r0, *self.w0, *self.r_hat, *self.w_hat,
                              *self.s_hat, self.peak_torque)


def matrix(x):
    """A nalgebra Matrix3 from its serde form: 9 numbers, column-major."""
    if len(x) != 9:
        raise NodeError(f"invalid node config: a matrix has {len(x)} entries, not 9", 2)
    m = [float(v) for v in x]
    return (m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8])


def vec3(x):
    if len(x) != 3:
        raise NodeError(f"invalid node config: a vector has {len(x)} entries, not 3", 2)
    return tuple(float(v) for v in x)


# --------------------------------------------------------------------------
# Configuration (msgs/src/config.rs)
# --------------------------------------------------------------------------

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
        return _read_config(path)
    except (KeyError, TypeError, ValueError, AttributeError) as e:
        raise NodeError(f"{path}: invalid node config: {e!r}", 2) from e


def _read_config(path):
    try:
        with open(path, encoding="utf-8") as f:
            cfg = json.load(f)  # floats: correctly rounded, exact round trip
    except OSError as e:
        raise NodeError(f"{path}: cannot read: {e}", 2) from e
    except ValueError as e:
        raise NodeError(f"{path}: invalid node config: {e}", 2) from e
    version = cfg.get("protocol_version")
    if version != PROTOCOL_VERSION:
        raise NodeError(f"{path}: protocol version {version} but this program "
                        f"speaks {PROTOCOL_VERSION}", 2)
    unsupported = []
    if cfg.get("realtime") is not None:
        unsupported.append(f"real-time mode (realtime = {cfg['realtime']}) is not "
                           "supported by the Python agent: run in lockstep")
    role = cfg.get("role", {})
    if role.get("kind") != "agent":
        unsupported.append(f"role {role.get('kind')!r}: the Python agent is a follower "
                           "agent only")
    else:
        model = role["model"]
        kind = model["scheme"]["kind"]
        if kind != "observerless":
            unsupported.append(f"scheme {kind!r} is not supported: the Python agent "
                               "implements the observerless scheme (districontrol) only")
        links = [n.get("link") for n in model["neighbours"]] + [model.get("leader_link")]
        if any(link_impaired(l) for l in links):
            unsupported.append("impaired links (delay, jitter, loss, period) are not "
                               "supported by the Python agent")
        expected = [n["id"] for n in model["neighbours"]]
        if model.get("leader_gain") is not None:
            expected.append(0)
        if list(cfg["inputs"]) != expected:
            raise NodeError(f"{path}: inputs {cfg['inputs']} do not match the model's "
                            f"neighbours and leader link {expected}", 2)
    mode = cfg.get("coupling", {}).get("mode")
    if mode not in ("continuous", "sampled"):
        unsupported.append(f"coupling {mode!r} is not supported")
    elif mode == "sampled" and int(cfg["coupling"]["every"]) < 1:
        raise NodeError(f"{path}: coupling.every must be >= 1", 2)
    if int(cfg.get("sample_every", 0)) < 1:
        raise NodeError(f"{path}: sample_every must be >= 1", 2)
    if unsupported:
        raise NodeError(f"{path}: " + "; ".join(unsupported), 2)
    return cfg


def link_impaired(link):
    """LinkModel::is_impaired (None: an ideal link)."""
    if link is None:
        return False
    return (link.get("delay", 0) > 0 or link.get("jitter", 0) > 0
            or link.get("loss", {"kind": "none"}).get("kind", "none") != "none"
            or link.get("period") is not None)


def exchanges_at(coupling, step, stage):
    """Coupling::exchanges_at."""
    if coupling["mode"] == "continuous":
        return True
    return stage == 0 and step % coupling["every"] == 0


# --------------------------------------------------------------------------
# iceoryx2 ports (msgs/src/{namespace,names,open}.rs, agent/src/runtime/ports.rs)
# --------------------------------------------------------------------------

def open_service(name, make):
    """open_or_create, retried for 2 s like msgs::open::retry: two processes
    creating the same service at once make one of them fail transiently."""
    start = time.monotonic()
    while True:
        try:
            return make()
        except Exception as e:  # iceoryx2 raises its own error types
            if time.monotonic() - start > 2.0:
                raise NodeError(f"cannot open service {name}: {e!r}") from e
            time.sleep(0.005)


class Ports:
    """Every port of the node, opened with the limits of msgs/src/open.rs."""

    def __init__(self, iox2, cfg):
        self.iox2 = iox2
        run, node_id, lim = cfg["run"], cfg["id"], cfg["limits"]
        fanout, nodes = lim["max_fanout"], lim["nodes"]
        state_buffer, telemetry_buffer = lim["state_buffer"], lim["telemetry_buffer"]

        # Per-run namespace (msgs::namespace::config).
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

        def state(j):
            name = f"attsync/{run}/node/{j}/state"
            return open_service(name, lambda: (
                self.node.service_builder(iox2.ServiceName.new(name))
                .publish_subscribe(StateMsg)
                .max_publishers(1).max_subscribers(fanout).max_nodes(fanout + 2)
                .history_size(0).subscriber_max_buffer_size(state_buffer)
                .subscriber_max_borrowed_samples(2).enable_safe_overflow(False)
                .open_or_create()))

        def wake(j):
            name = f"attsync/{run}/node/{j}/wake"
            return open_service(name, lambda: (
                self.node.service_builder(iox2.ServiceName.new(name)).event()
                .max_listeners(1).max_notifiers(fanout + 1).max_nodes(fanout + 3)
                .open_or_create()))

        # Our state: the publisher holds a full receiver back (flow control).
        # NOTE: the Python binding has no backpressure handler, so unlike the
        # Rust node this retry is not bounded by the stage timeout; an agent's
        # receivers are also its inputs, so it is never more than one
        # exchange ahead of them and their buffer (64) never fills.
        self.own = state(node_id)
        self.publisher = (self.own.publisher_builder()
                          .backpressure_strategy(iox2.BackpressureStrategy.RetryUntilDelivered)
                          .create())
        self.listener = wake(node_id).listener_builder().create()
        name = f"attsync/{run}/node/{node_id}/telemetry"
        self.tele = open_service(name, lambda: (
            self.node.service_builder(iox2.ServiceName.new(name))
            .publish_subscribe(TelemetryMsg)
            .max_publishers(1).max_subscribers(2).max_nodes(4)
            .history_size(0).subscriber_max_buffer_size(telemetry_buffer)
            .subscriber_max_borrowed_samples(2).enable_safe_overflow(False)
            .open_or_create()))
        self.tele_pub = (self.tele.publisher_builder()
                         .backpressure_strategy(iox2.BackpressureStrategy.RetryUntilDelivered)
                         .create())
        name = f"attsync/{run}/orchestrator/wake"
        self.orch_wake = open_service(name, lambda: (
            self.node.service_builder(iox2.ServiceName.new(name)).event()
            .max_listeners(1).max_notifiers(nodes + 1).max_nodes(nodes + 2)
            .open_or_create()))
        self.orch_notifier = self.orch_wake.notifier_builder().create()
        name = f"attsync/{run}/control"
        self.control_svc = open_service(name, lambda: (
            self.node.service_builder(iox2.ServiceName.new(name))
            .publish_subscribe(ControlMsg)
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
        """Readiness barrier: every receiver of our state, the orchestrator's
        telemetry subscriber and the sender of every input are connected."""
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

    def report(self, payload):
        """Sends a telemetry message (packed TELEMETRY bytes) and wakes the orchestrator."""
        sample = self.tele_pub.loan_uninit()
        ctypes.memmove(sample.payload_ptr, payload, TELEMETRY.size)
        sample.assume_init().send()
        try:
            self.orch_notifier.notify()
        except Exception:  # a lost wake-up only delays the orchestrator
            pass

    def release(self):
        """Releases every port, then the services and the node."""
        ports = ([self.publisher, self.listener, self.tele_pub, self.orch_notifier,
                  self.control] + self.inputs + self.notifiers)
        for p in ports:
            try:
                p.delete()
            except Exception:
                pass
        self.inputs, self.notifiers, self.input_services, self.wake_services = [], [], [], []
        self.publisher = self.listener = self.tele_pub = self.orch_notifier = None
        self.control = self.own = self.tele = self.orch_wake = self.control_svc = None
        self.node = None


class Orphan:
    """Detects that the process that started us (the orchestrator) is gone."""

    def __init__(self):
        self.parent = os.getppid()

    def check(self):
        if os.getppid() != self.parent:
            raise NodeError(f"the orchestrator (pid {self.parent}) has exited")


def wait_command(ports, timeout, orphan):
    """Polls the control service every millisecond (bounded) for a command."""
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


# --------------------------------------------------------------------------
# The node loop (agent/src/runtime/{mod,lockstep}.rs)
# --------------------------------------------------------------------------

def lockstep(ports, cfg, agent, orphan):
    """Steps `steps` steps in lockstep (agent/src/runtime/lockstep.rs).
    Returns the messages refused per input and waiting statistics."""
    iox2 = ports.iox2
    node_id, steps = cfg["id"], int(cfg["steps"])
    sample_every, coupling = int(cfg["sample_every"]), cfg["coupling"]
    continuous = coupling["mode"] == "continuous"
    inputs_ids = list(cfg["inputs"])
    stage_timeout = float(cfg["stage_timeout"])
    strategy = cfg.get("wait", "adaptive")
    # Polls between sleeps: -1 never sleeps (spin and yield both call
    # sched_yield here: a spinning Python process would starve its peers).
    yields = {"spin": -1, "yield": -1, "block": 0}.get(strategy, ADAPTIVE_YIELDS)
    subs = ports.inputs
    listener, notifiers, publisher = ports.listener, ports.notifiers, ports.publisher
    slice_ = iox2.Duration.from_millis(BLOCK_SLICE_MS)
    rejected = [0] * len(subs)
    n_yields = n_sleeps = 0
    waited = 0.0
    string_at, memmove, monotonic = ctypes.string_at, ctypes.memmove, time.monotonic
    sched_yield, unpack = os.sched_yield, STATE.unpack
    pack_into_bytes = STATE.pack
    ssize = STATE.size

    ports.report(agent.sample(node_id, 0))
    for n in range(steps):
        if n % 256 == 0:
            orphan.check()
        for s in range(4):
            if continuous or (s == 0 and n % coupling["every"] == 0):
                r, w = agent.stage_exchange()
                msg = pack_into_bytes(PROTOCOL_VERSION, node_id, n, s, 0, 0, *r, *w, 0.0,
                                      0.0, 0.0)
                loan = publisher.loan_uninit()
                memmove(loan.payload_ptr, msg, ssize)
                loan.assume_init().send()
                # Wake every receiver (PROTOCOL.md § 6; attsync's own nodes
                # skip it when every node busy-polls, with --wait spin|yield).
                for nt in notifiers:
                    try:
                        nt.notify()
                    except Exception:
                        pass
                deadline = None
                polls = 0
                t_wait = None
                for k, sub in enumerate(subs):
                    while True:
                        sample = sub.receive()
                        if sample is not None:
                            m = unpack(string_at(sample.payload_ptr, ssize))
                            sample.delete()
                            break
                        if deadline is None:
                            t_wait = monotonic()
                            deadline = t_wait + stage_timeout
                        polls += 1
                        if yields < 0 or polls <= yields:
                            sched_yield()
                            n_yields += 1
                        else:
                            listener.timed_wait(slice_)
                            n_sleeps += 1
                        # The clock every poll once sleeping, else every 64 polls.
                        if (0 <= yields < polls or polls % 64 == 0) and monotonic() > deadline:
                            # Failed names the silent input for the orchestrator.
                            try:
                                ports.report(TELEMETRY.pack(PROTOCOL_VERSION, node_id,
                                                            inputs_ids[k], FAILED, 0,
                                                            *([0.0] * 28)))
                            except Exception:
                                pass
                            raise NodeError(
                                f"timed out after {stage_timeout:.1f} s waiting for node "
                                f"{inputs_ids[k]}'s state of step {n} stage {s}")
                        if polls % 256 == 0:
                            orphan.check()
                    check_message(m, inputs_ids[k], n, s)
                    value = validated(m)
                    if value is None:
                        # A refused value is like a lost message: keep what we had.
                        if rejected[k] == 0:
                            log(f"WARN refused a state from node {inputs_ids[k]} at step "
                                f"{n} stage {s}: {why_invalid(m)} (further refusals are "
                                "only counted)")
                        rejected[k] += 1
                    else:
                        agent.receive(k, value)
                if t_wait is not None:
                    waited += monotonic() - t_wait
            agent.advance()
        done = n + 1
        if done % sample_every == 0 or done == steps:
            ports.report(agent.sample(node_id, done))
    return rejected, {"yields": n_yields, "sleeps": n_sleeps, "wait_s": waited}


def check_message(m, sender, n, s):
    """Version, sender and stamp of a message on `sender`'s state service."""
    version, claimed, step, stage = m[0], m[1], m[2], m[3]
    if version != PROTOCOL_VERSION:
        raise NodeError(f"protocol violation: node {sender} speaks protocol version "
                        f"{version}, this node {PROTOCOL_VERSION}")
    if claimed != sender:
        raise NodeError(f"protocol violation: message on node {sender}'s state service "
                        f"claims sender {claimed}")
    if step != n or stage != s:
        raise NodeError(f"protocol violation: node {sender} sent step {step} stage {stage} "
                        f"where step {n} stage {s} was due")


_isfinite = math.isfinite


def validated(m):
    """StateMsg::validated: R if every number is finite and R is a rotation
    (||R^T R - I||_F <= ROTATION_TOLERANCE and det R > 0), else None."""
    values = m[6:]
    if not all(map(_isfinite, values)):
        return None
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = r = values[:9]
    # R^T R - I, symmetric: 3 diagonal and 3 off-diagonal entries.
    d00 = r0 * r0 + r3 * r3 + r6 * r6 - 1.0
    d11 = r1 * r1 + r4 * r4 + r7 * r7 - 1.0
    d22 = r2 * r2 + r5 * r5 + r8 * r8 - 1.0
    d01 = r0 * r1 + r3 * r4 + r6 * r7
    d02 = r0 * r2 + r3 * r5 + r6 * r8
    d12 = r1 * r2 + r4 * r5 + r7 * r8
    defect2 = d00 * d00 + d11 * d11 + d22 * d22 + 2.0 * (d01 * d01 + d02 * d02 + d12 * d12)
    if defect2 > ROTATION_TOLERANCE * ROTATION_TOLERANCE or det3(r) <= 0.0:
        return None
    return r


def why_invalid(m):
    if not all(math.isfinite(v) for v in m[6:]):
        return "a value is NaN or infinite"
    r = m[6:15]
    return (f"the attitude is not a rotation (||R^T R - I|| = "
            f"{orthogonality_defect(r):.3e}, or det R <= 0)")


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
    node_id = cfg["id"]
    role = cfg["role"]
    try:
        agent = ObserverlessAgent(role["model"], role["initial"], float(cfg["dt"]))
    except (KeyError, TypeError, ValueError) as e:
        raise NodeError(f"invalid node config: {e!r}", 2) from e
    orphan = Orphan()
    ports = Ports(iox2, cfg)
    try:
        ports.await_connections(cfg, orphan)
        ports.report(TELEMETRY.pack(PROTOCOL_VERSION, node_id, 0, READY, 0, *([0.0] * 28)))
        log(f"ready (id {node_id}, inputs {cfg['inputs']}, outputs {cfg['outputs']})")
        command, _ = wait_command(ports, float(cfg["start_timeout"]), orphan)
        if command != START:
            raise NodeError("stopped before the end (at step 0)")
        log("started")
        t0 = time.monotonic()
        rejected, stats = lockstep(ports, cfg, agent, orphan)
        wall = time.monotonic() - t0
        # Link counters only for inputs that refused messages (the built-in
        # agent also reports impaired links, which this agent refuses).
        for k, count in enumerate(rejected):
            if count:
                fields = [0.0] * 28
                fields[24] = float(count)  # s_hat[0] (r 0-8, w 9-11, r_hat 12-20, w_hat 21-23)
                ports.report(TELEMETRY.pack(PROTOCOL_VERSION, node_id, cfg["inputs"][k],
                                            LINK_STATS, 0, *fields))
        done = [0.0] * 28
        done[27] = agent.peak_torque
        ports.report(TELEMETRY.pack(PROTOCOL_VERSION, node_id, int(cfg["steps"]), DONE, 0,
                                    *done))
        peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        log(f"done: {cfg['steps']} steps in {wall:.2f} s, peak torque "
            f"{agent.peak_torque!r}; waiting for inputs {stats['wait_s']:.2f} s "
            f"({stats['yields']} yields, {stats['sleeps']} sleeps on the wake event); "
            f"peak_rss_kb={peak_kb}")
        command, _ = wait_command(ports, STOP_TIMEOUT, orphan)
        if command == START:
            raise NodeError("protocol violation: second Start")
    finally:
        ports.release()


def main(argv):
    try:
        cfg = read_config(config_path(argv))
        run(cfg)
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
