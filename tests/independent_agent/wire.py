"""PROTOCOL.md § 5: the payloads, as ctypes structures, with their encoders."""

import ctypes
import struct

PROTOCOL_VERSION = 3

# Telemetry kinds (§ 5).
READY, SAMPLE, DONE, LINK_STATS, FAILED, LEADER_SAMPLE, TORQUE = 1, 2, 3, 4, 5, 6, 7
# Failed reasons.
TIMED_OUT, BROKE_PROTOCOL, OTHER = 1, 2, 3
# Control commands.
START, STOP = 1, 2


class StateMsg(ctypes.Structure):
    """`attsync::StateMsg`, 152 bytes."""

    _fields_ = [
        ("version", ctypes.c_uint32),
        ("sender", ctypes.c_uint32),
        ("step", ctypes.c_uint64),
        ("stage", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("sent_unix_ns", ctypes.c_uint64),
        ("r", ctypes.c_double * 9),
        ("w", ctypes.c_double * 3),
        ("s", ctypes.c_double * 3),
    ]

    @staticmethod
    def type_name():
        return "attsync::StateMsg"


class TelemetryMsg(ctypes.Structure):
    """`attsync::TelemetryMsg`, 248 bytes: a 16-byte header and a body."""

    _fields_ = [
        ("version", ctypes.c_uint32),
        ("sender", ctypes.c_uint32),
        ("kind", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("body", ctypes.c_uint8 * 232),
    ]

    @staticmethod
    def type_name():
        return "attsync::TelemetryMsg"


class ControlMsg(ctypes.Structure):
    """`attsync::ControlMsg`, 16 bytes."""

    _fields_ = [
        ("version", ctypes.c_uint32),
        ("command", ctypes.c_uint32),
        ("start_unix_ns", ctypes.c_uint64),
    ]

    @staticmethod
    def type_name():
        return "attsync::ControlMsg"


assert ctypes.sizeof(StateMsg) == 152
assert ctypes.sizeof(TelemetryMsg) == 248
assert ctypes.sizeof(ControlMsg) == 16


def state(sender, n, s, r, w, sv, sent_unix_ns=0):
    """A StateMsg; ``r`` row-major."""
    msg = StateMsg()
    msg.version = PROTOCOL_VERSION
    msg.sender = sender
    msg.step = n
    msg.stage = s
    msg.reserved = 0
    msg.sent_unix_ns = sent_unix_ns
    msg.r[:] = list(r)
    msg.w[:] = list(w)
    msg.s[:] = list(sv)
    return msg


def telemetry(sender, kind, fmt="", *values):
    """A TelemetryMsg whose body (offset 16 on) is ``struct.pack('<'+fmt)``."""
    msg = TelemetryMsg()
    msg.version = PROTOCOL_VERSION
    msg.sender = sender
    msg.kind = kind
    msg.reserved = 0
    if fmt:
        body = struct.pack("<" + fmt, *values)
        ctypes.memmove(ctypes.addressof(msg) + 16, body, len(body))
    return msg


def sample(sender, n, r, w, rh, wh, sh, peak_torque):
    """Kind 2: step u64 @16, r @24, w @96, r_hat @120, w_hat @192,
    s_hat @216, peak_torque @240."""
    return telemetry(sender, SAMPLE, "Q9d3d9d3d3d1d", n, *r, *w, *rh, *wh, *sh, peak_torque)


def torque(sender, n, tau):
    """Kind 7: step u64 @16, tau f64[3] @24 (the torque applied at stage 0
    of step n)."""
    return telemetry(sender, TORQUE, "Q3d", n, *tau)


def done(sender, steps, peak_torque, peak_rss_kb, started_ns, done_ns):
    """Kind 3 (lockstep: late_stages = max_lateness = 0)."""
    return telemetry(
        sender, DONE, "QdQQQQd", steps, peak_torque, peak_rss_kb, started_ns, done_ns, 0, 0.0
    )


def link_stats(sender, frm, sent, delivered, lost, rejected, evaluations, age_sum, age_max):
    """Kind 4: from u32 @16, then u64s from @24."""
    return telemetry(
        sender,
        LINK_STATS,
        "I4xQQQQQdd",
        frm,
        sent,
        delivered,
        lost,
        rejected,
        evaluations,
        age_sum,
        age_max,
    )


def failed(sender, reason, frm):
    """Kind 5: reason u32 @16, from u32 @20."""
    return telemetry(sender, FAILED, "II", reason, frm)
