#!/usr/bin/env python3
"""An attsync plug-in agent written from PROTOCOL.md alone (issue 9).

    python3 agent.py --config node-<id>.json      (or ATTSYNC_CONFIG=…)

All three schemes, lockstep, continuous and sampled coupling, impaired
links (§ 10.9). Not done (refused with a message and exit code 2):
real-time mode (§ 7), the leader role. Needs PyPI `iceoryx2==0.10.0`.
"""

import gc
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import arith  # noqa: E402
import wire  # noqa: E402
from link import C_STAGE, Link  # noqa: E402
from model import Agent, ConfigRefused  # noqa: E402

EXIT_REFUSED = 2
STOP_WAIT_S = 600.0


def log(msg):
    print(f"independent-agent: {msg}", file=sys.stderr, flush=True)


class Exit(Exception):
    """Leave with ``code`` after releasing the ports."""

    def __init__(self, code, msg, failed=None):
        super().__init__(msg)
        self.code, self.failed = code, failed


def read_config(argv):
    path = None
    if "--config" in argv:
        k = argv.index("--config")
        path = argv[k + 1] if k + 1 < len(argv) else None
    path = path or os.environ.get("ATTSYNC_CONFIG")
    if not path:
        log("usage: agent.py --config FILE")
        sys.exit(EXIT_REFUSED)
    with open(path) as f:
        cfg = json.load(f)
    got = cfg.get("protocol_version")
    if got != wire.PROTOCOL_VERSION:
        log(f"protocol version mismatch: configuration has {got}, this agent speaks {wire.PROTOCOL_VERSION}")
        sys.exit(EXIT_REFUSED)
    return cfg


def refuse_unsupported(cfg):
    """What this agent does not implement, refused before opening anything."""
    role = cfg["role"]
    if role["kind"] != "agent":
        raise ConfigRefused(f"role {role['kind']!r}: only agents are implemented")
    if cfg.get("realtime") is not None:
        raise ConfigRefused("real-time mode (PROTOCOL.md § 7) is not implemented")
    mode = cfg["coupling"]["mode"]
    if mode not in ("continuous", "sampled"):
        raise ConfigRefused(f"coupling mode {mode!r}")


# § 10.9: what an input with outages but a null ``link`` runs.
IDEAL_LINK = {"delay": 0, "jitter": 0, "loss": {"kind": "none"}, "period": None, "seed": 0}


def input_links(cfg):
    """A :class:`Link` per impaired input (inputs order), None if ideal;
    an input with outages (§ 10.10) is impaired."""
    model = cfg["role"]["model"]
    down = {d["from"]: d["outages"] for d in model.get("timeline", {}).get("down", [])}
    specs = [(n.get("link"), n["id"]) for n in model["neighbours"]]
    if model.get("leader_gain") is not None:
        specs.append((model.get("leader_link"), 0))
    links = []
    for spec, sender in specs:
        outages = down.get(sender, [])
        if spec is None and outages:
            spec = IDEAL_LINK
        links.append(Link(spec, outages) if spec is not None else None)
    return links


def is_exchange(coupling, n, s):
    if coupling["mode"] == "continuous":
        return True
    return s == 0 and n % int(coupling["every"]) == 0


def peak_rss_kb():
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


def alive(pid):
    """Whether process `pid` exists and is not a zombie (/proc/<pid>/stat)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] not in ("Z", "X")
    except (OSError, IndexError):
        return False


class Node:
    """The ports of § 4 and the waits of § 6 around one :class:`Agent`."""

    def __init__(self, cfg):
        import ports  # the iceoryx2 part; imported late so that refusals need no binding

        self.cfg = cfg
        self.id = int(cfg["id"])
        self.ppid = os.getppid()
        # § 1, § 6: orphaned before we could look if ATTSYNC_PARENT_PID is not
        # our parent and is gone (or a zombie).
        expected = os.environ.get("ATTSYNC_PARENT_PID", "")
        if expected.isdigit() and int(expected) != self.ppid and not alive(int(expected)):
            raise Exit(1, f"the parent process {expected} is gone")
        self.polling = cfg.get("wait") in ("spin", "yield")
        self.ports = ports.Ports(cfg)

    def parent_alive(self):
        return os.getppid() == self.ppid

    def telemetry(self, msg):
        self.ports.telemetry.send_copy(msg)
        self.ports.orchestrator.notify()

    def pause(self, spins):
        """One pause of a bounded wait: yield first, then sleep on the wake
        listener for at most 1 ms (a notification may be lost)."""
        if not self.parent_alive():
            raise Exit(1, "the parent process is gone")
        if self.polling or spins < 200:
            os.sched_yield()
        else:
            self.ports.wake.timed_wait(self.ports.millisecond)

    def barrier(self):
        """§ 6.3: every connection there, within start_timeout."""
        p, deadline = self.ports, time.monotonic() + float(self.cfg["start_timeout"])
        need = len(self.cfg["outputs"])
        while True:
            missing = []
            if p.state_service.dynamic_config.number_of_subscribers < need:
                missing.append("subscribers of the own state")
            if p.telemetry_service.dynamic_config.number_of_subscribers < 1:
                missing.append("the telemetry subscriber")
            for i, svc in zip(self.cfg["inputs"], p.input_services):
                if svc.dynamic_config.number_of_publishers < 1:
                    missing.append(f"the publisher of input {i}")
            if not missing:
                break
            if time.monotonic() > deadline or not self.parent_alive():
                raise Exit(1, "not connected within start_timeout: " + ", ".join(missing))
            time.sleep(0.001)
        for sub in p.inputs:
            sub.has_samples()  # the binding's update_connections()

    def control(self, want, timeout):
        """Waits for control command ``want``; a wrong version is an error."""
        deadline = time.monotonic() + timeout
        while True:
            sample = self.ports.control.receive()
            if sample is not None:
                c = sample.payload().contents
                version, command = c.version, c.command
                sample.delete()
                if version != wire.PROTOCOL_VERSION:
                    raise Exit(1, f"ControlMsg version {version}, expected {wire.PROTOCOL_VERSION}")
                if command == want:
                    return
                if command == wire.STOP:
                    raise Exit(1, "Stop before Start")
                continue
            if time.monotonic() > deadline or not self.parent_alive():
                raise Exit(1, f"no control command {want} within {timeout} s")
            time.sleep(0.001)

    def receive(self, k, n, s):
        """§ 6.7.3: exactly one message of input ``k`` stamped (n, s)."""
        frm = self.cfg["inputs"][k]
        sub = self.ports.inputs[k]
        deadline = time.monotonic() + float(self.cfg["stage_timeout"])
        spins = 0
        while True:
            sample = sub.receive()
            if sample is not None:
                msg = wire.StateMsg.from_buffer_copy(sample.payload().contents)
                sample.delete()
                break
            if time.monotonic() > deadline:
                raise Exit(1, f"input {frm}: no state ({n}, {s}) within stage_timeout",
                           (wire.TIMED_OUT, frm))
            self.pause(spins)
            spins += 1
        if msg.version != wire.PROTOCOL_VERSION or msg.sender != frm or (msg.step, msg.stage) != (n, s):
            raise Exit(1, f"input {frm} broke the protocol: version {msg.version}, sender "
                       f"{msg.sender}, stamp ({msg.step}, {msg.stage}) at ({n}, {s})",
                       (wire.BROKE_PROTOCOL, frm))
        return tuple(msg.r), tuple(msg.w), tuple(msg.s)

    def run(self):
        cfg, p = self.cfg, self.ports
        agent = Agent(cfg)
        coupling, steps, every = cfg["coupling"], int(cfg["steps"]), int(cfg["sample_every"])
        rejected = [0] * len(cfg["inputs"])
        links = input_links(cfg)
        ages = [[0.0, 0.0] for _ in links]  # age_sum, age_max per input
        dt = float(cfg["dt"])
        exchanges = 0
        self.barrier()
        self.telemetry(wire.telemetry(self.id, wire.READY))
        self.control(wire.START, float(cfg["start_timeout"]))
        started = time.time_ns()
        self.report_sample(agent, 0)
        for n in range(steps):
            agent.step_start(n, [link is not None and link.forgotten_at(n) for link in links])
            for s in range(4):
                out = agent.stage_point(s)
                if is_exchange(coupling, n, s):
                    exchanges += 1
                    p.state.send_copy(wire.state(self.id, n, s, *out))
                    for notifier in p.outputs:
                        notifier.notify()
                    for k in range(len(cfg["inputs"])):
                        value = self.receive(k, n, s)
                        if not arith.is_valid_state(*value):
                            rejected[k] += 1
                        elif links[k] is not None:
                            links[k].offer(n, s, value)
                        else:
                            agent.held[k] = value
                for k, link in enumerate(links):
                    if link is not None:
                        value = link.value_at(n, s)
                        if value is not None:
                            agent.held[k] = value
                            (m, c) = link.held[0]
                            age = ((n + C_STAGE[s]) - (m + C_STAGE[c])) * dt
                            ages[k][0] += age
                            ages[k][1] = max(ages[k][1], age)
                agent.evaluate(s)
                if s == 0 and n % every == 0:
                    self.telemetry(wire.torque(self.id, n, agent.torque))
            if (n + 1) % every == 0 or n + 1 == steps:
                self.report_sample(agent, n + 1)
        done = time.time_ns()
        for k, frm in enumerate(cfg["inputs"]):
            if links[k] is not None:
                link = links[k]
                self.telemetry(wire.link_stats(self.id, frm, link.sent, link.delivered, link.lost,
                                               rejected[k], 4 * steps, *ages[k]))
            elif rejected[k]:
                self.telemetry(wire.link_stats(self.id, frm, exchanges, exchanges, 0, rejected[k],
                                               4 * steps, 0.0, 0.0))
        self.telemetry(wire.done(self.id, steps, agent.peak_torque, peak_rss_kb(), started, done))
        self.control(wire.STOP, STOP_WAIT_S)

    def report_sample(self, agent, n):
        self.telemetry(wire.sample(self.id, n, *agent.sample(), agent.peak_torque))


def main():
    cfg = read_config(sys.argv)
    try:
        refuse_unsupported(cfg)
        Agent(cfg)
    except ConfigRefused as e:
        log(f"configuration refused: {e}")
        return EXIT_REFUSED
    node = Node(cfg)
    code = 0
    try:
        node.run()
    except Exit as e:
        log(str(e))
        if e.failed is not None:
            try:
                node.telemetry(wire.failed(node.id, *e.failed))
            except Exception as t:  # noqa: BLE001  best effort, we are failing anyway
                log(f"could not report Failed: {t}")
        code = e.code
    node.ports.release()
    del node
    gc.collect()
    return code


if __name__ == "__main__":
    sys.exit(main())
