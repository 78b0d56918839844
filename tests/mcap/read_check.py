#!/usr/bin/env python3
"""Checks an `attsync export --mcap` recording with independent readers.

Usage: read_check.py RECORDING.mcap STATES.csv ERRORS.csv

STATES.csv is `attsync export DIR/states.bin --csv` of the same run and
ERRORS.csv the run's errors.csv. The recording is read with PyPI's `mcap`
and every message is decoded by `mcap-protobuf-support` through the schema
embedded in the file (a FileDescriptorSet: nothing of attsync is known
here), then checked against the CSVs:

- the channels: /tf (foxglove.FrameTransforms), /errors/agent-<id>
  (attsync.AgentErrors) and /torque/agent-<id> (attsync.AgentTorque), all
  Protobuf;
- one message per sample on every channel, log time = publish time = the
  sample's simulated time in ns, and the summary's statistics agree;
- every transform: parent `world`, the frames leader, agent-<id> and
  estimate-<id> (observer schemes), stamped with the log time, a unit
  quaternion whose rotation matrix is the CSV's R0 / R_i / R_hat_i;
- every error message: the values of errors.csv, exactly;
- every torque message: the CSV's tau1..tau3 of the agent, exactly, and
  their norm (NaN at the last sample).

Prints one line `mcap ok: ...` and exits 0, or names the first mismatch
and exits 1.
"""

import csv
import sys
from collections import defaultdict
from decimal import Decimal

try:
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory
except ImportError as e:  # the message the Rust test shows
    sys.exit(
        f"read_check.py: {e}: run `python3 -m pip install -r tests/requirements.txt`"
    )

TOLERANCE = 1e-12


def fail(msg):
    sys.exit(f"read_check.py: {msg}")


def ns(t):
    """Simulated time t (the CSVs' decimal string, s) in whole ns."""
    return int(Decimal(t) * 1_000_000_000)


def read_states(path, observer):
    """{time_ns: {frame: row-major matrix}} from the states CSV (estimate
    frames only with an observer: the CSV has R_hat columns either way),
    and {time_ns: {agent: (tau1, tau2, tau3)}}."""
    states = defaultdict(dict)
    torques = defaultdict(dict)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            t, node = ns(row["t"]), int(row["node"])
            r = [float(row[f"r{i}{j}"]) for i in (1, 2, 3) for j in (1, 2, 3)]
            if node == 0:
                states[t]["leader"] = r
                continue
            states[t][f"agent-{node}"] = r
            torques[t][node] = tuple(float(row[f"tau{i}"]) for i in (1, 2, 3))
            if observer:
                rh = [float(row[f"r_hat{i}{j}"]) for i in (1, 2, 3) for j in (1, 2, 3)]
                states[t][f"estimate-{node}"] = rh
    return states, torques


def read_errors(path):
    """{agent: [(time_ns, att, angvel, obs or None)]} from errors.csv."""
    errors = defaultdict(list)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            obs = None
            if row["obs_att_err"] != "":
                obs = (float(row["obs_att_err"]), float(row["obs_angvel_err"]))
            errors[int(row["agent"])].append(
                (ns(row["t"]), float(row["att_err"]), float(row["angvel_err"]), obs)
            )
    return errors


def matrix(q):
    """Row-major rotation matrix of the unit quaternion q (x, y, z, w)."""
    x, y, z, w = q.x, q.y, q.z, q.w
    return [
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ]


def same(a, b):
    """Equal, NaN included (a diverged run's errors are NaN)."""
    return a == b or (a != a and b != b)


def check_channels(summary, agents):
    topics = {c.topic: c for c in summary.channels.values()}
    expected = {"/tf": "foxglove.FrameTransforms"}
    expected.update({f"/errors/agent-{a}": "attsync.AgentErrors" for a in agents})
    expected.update({f"/torque/agent-{a}": "attsync.AgentTorque" for a in agents})
    if set(topics) != set(expected):
        fail(f"topics {sorted(topics)}, expected {sorted(expected)}")
    for topic, name in expected.items():
        c = topics[topic]
        s = summary.schemas[c.schema_id]
        if (c.message_encoding, s.encoding, s.name) != ("protobuf", "protobuf", name):
            fail(f"{topic}: {c.message_encoding} / {s.encoding} {s.name}, expected protobuf / protobuf {name}")
    return topics


def check_tf(k, t, msg, frames):
    if len(msg.transforms) != len(frames):
        fail(f"/tf #{k}: {len(msg.transforms)} transforms, expected {len(frames)}")
    for tr in msg.transforms:
        child = tr.child_frame_id
        if tr.parent_frame_id != "world" or child not in frames:
            fail(f"/tf #{k}: transform {tr.parent_frame_id} -> {child}")
        stamp = tr.timestamp.seconds * 1_000_000_000 + tr.timestamp.nanos
        if stamp != t:
            fail(f"/tf #{k} {child}: timestamp {stamp} ns, log time {t} ns")
        q = tr.rotation
        norm = (q.x**2 + q.y**2 + q.z**2 + q.w**2) ** 0.5
        if abs(norm - 1) > TOLERANCE:
            fail(f"/tf #{k} {child}: |q| = {norm}")
        dev = max(abs(a - b) for a, b in zip(matrix(q), frames[child]))
        if not dev <= TOLERANCE:
            fail(f"/tf #{k} {child}: rotation off states.bin by {dev}")


def check_errors(k, topic, msg, row):
    t, att, angvel, obs = row
    if not (same(msg.att_err, att) and same(msg.angvel_err, angvel)):
        fail(f"{topic} #{k}: ({msg.att_err}, {msg.angvel_err}), errors.csv ({att}, {angvel})")
    if msg.HasField("observer") != (obs is not None):
        fail(f"{topic} #{k}: observer present = {msg.HasField('observer')}, errors.csv {obs}")
    if obs is not None and not (
        same(msg.observer.att_err, obs[0]) and same(msg.observer.angvel_err, obs[1])
    ):
        fail(f"{topic} #{k}: observer ({msg.observer.att_err}, {msg.observer.angvel_err}), errors.csv {obs}")
    stamp = msg.timestamp.seconds * 1_000_000_000 + msg.timestamp.nanos
    if stamp != t:
        fail(f"{topic} #{k}: timestamp {stamp} ns, expected {t} ns")


def check_torque(k, t, topic, msg, tau):
    got = (msg.x, msg.y, msg.z)
    if not all(same(a, b) for a, b in zip(got, tau)):
        fail(f"{topic} #{k}: {got}, states CSV {tau}")
    norm = (tau[0] ** 2 + tau[1] ** 2 + tau[2] ** 2) ** 0.5
    if not (same(msg.norm, norm) or abs(msg.norm - norm) <= TOLERANCE * max(1.0, norm)):
        fail(f"{topic} #{k}: norm {msg.norm}, of the CSV's torque {norm}")
    stamp = msg.timestamp.seconds * 1_000_000_000 + msg.timestamp.nanos
    if stamp != t:
        fail(f"{topic} #{k}: timestamp {stamp} ns, expected {t} ns")


def main(recording, states_csv, errors_csv):
    errors = read_errors(errors_csv)
    observer = any(row[3] is not None for rows in errors.values() for row in rows)
    states, torques = read_states(states_csv, observer)
    times = sorted(states)
    agents = sorted(errors)
    seen = defaultdict(int)
    with open(recording, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        if summary is None:
            fail("no summary section")
        topics = check_channels(summary, agents)
        for _, channel, message, msg in reader.iter_decoded_messages(log_time_order=True):
            topic, k = channel.topic, seen[channel.topic]
            seen[topic] += 1
            if k >= len(times):
                fail(f"{topic}: more than {len(times)} messages")
            t = times[k]
            if (message.log_time, message.publish_time) != (t, t):
                fail(f"{topic} #{k}: log/publish time {message.log_time}/{message.publish_time} ns, sample at {t} ns")
            if topic == "/tf":
                check_tf(k, t, msg, states[t])
            elif topic.startswith("/torque/"):
                check_torque(k, t, topic, msg, torques[t][int(topic.rsplit("-", 1)[1])])
            else:
                check_errors(k, topic, msg, errors[int(topic.rsplit("-", 1)[1])][k])
    for topic, c in topics.items():
        counted = summary.statistics.channel_message_counts.get(c.id)
        if seen[topic] != len(times) or counted != len(times):
            fail(f"{topic}: {seen[topic]} messages read, {counted} in the statistics, {len(times)} samples")
    print(
        f"mcap ok: {len(times)} samples, {len(agents)} agents, {len(topics)} channels, "
        f"{sum(seen.values())} messages, observer {str(observer).lower()}, "
        f"last log time {times[-1]} ns"
    )


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
