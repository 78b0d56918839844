"""PROTOCOL.md § 3-4: the iceoryx2 node, services and ports of one node."""

import time

import iceoryx2 as iox2

import wire

# § 6.2: an open is retried while another process may still be creating the
# service, until the start timeout; first pause 2 ms, doubling up to 50 ms.
FIRST_PAUSE, MAX_PAUSE = 0.002, 0.05
# Errors that name a settings mismatch: retrying cannot mend them.
LASTING = ("Incompatible", "DoesNotSupport", "VersionMismatch", "ExceedsMax", "TypeDefinition")


def retried(what, make, deadline):
    """`make()` (an open_or_create), retried until `deadline` (monotonic)."""
    start, pause = time.monotonic(), FIRST_PAUSE
    while True:
        try:
            return make()
        except Exception as e:
            text = f"{type(e).__name__} {e!r}"
            if any(w in text for w in LASTING) or time.monotonic() + pause > deadline:
                waited = time.monotonic() - start
                raise RuntimeError(f"cannot open {what} (tried {waited:.1f} s): {e!r}") from e
            time.sleep(pause)
            pause = min(2 * pause, MAX_PAUSE)


def service_name(run, rest):
    return iox2.ServiceName.new(f"attsync/{run}/{rest}")


def open_node(run, iox_root, me):
    """§ 3: the default configuration with the run's prefix and root."""
    c = iox2.config.default()
    c.global_cfg.prefix = iox2.FileName.new(f"as{run}_")
    c.global_cfg.root_path = iox2.Path.new(iox_root + "/")
    return (
        iox2.NodeBuilder.new()
        .name(iox2.NodeName.new(f"independent_{me}"))
        .config(c)
        .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
        .create(iox2.ServiceType.Ipc)
    )


class Ports:
    """Every port of § 4, opened with exactly the settings of the table."""

    def __init__(self, cfg):
        run, me = cfg["run"], int(cfg["id"])
        lim = cfg["limits"]
        self.run, self.lim = run, lim
        self.deadline = time.monotonic() + float(cfg["start_timeout"])
        self.fanout, self.nodes = int(lim["max_fanout"]), int(lim["nodes"])
        self.node = open_node(run, cfg["iox_root"], me)
        self.millisecond = iox2.Duration.from_millis(1)
        retry = iox2.BackpressureStrategy.RetryUntilDelivered
        self.state_service = self.state_svc(me)
        self.state = self.state_service.publisher_builder().backpressure_strategy(retry).create()
        self.wake_service = self.wake_svc(me)
        self.wake = self.wake_service.listener_builder().create()
        self.input_services = [self.state_svc(i) for i in cfg["inputs"]]
        self.inputs = [
            svc.subscriber_builder().buffer_size(int(lim["state_buffer"])).create()
            for svc in self.input_services
        ]
        self.output_services = [self.wake_svc(i) for i in cfg["outputs"]]
        self.outputs = [svc.notifier_builder().create() for svc in self.output_services]
        self.telemetry_service = self.telemetry_svc(me)
        self.telemetry = (
            self.telemetry_service.publisher_builder().backpressure_strategy(retry).create()
        )
        self.orchestrator_service = self.open(
            "orchestrator/wake",
            lambda: self.node.service_builder(service_name(run, "orchestrator/wake"))
            .event()
            .max_listeners(1)
            .max_notifiers(self.nodes + 1)
            .max_nodes(self.nodes + 2)
            .open_or_create(),
        )
        self.orchestrator = self.orchestrator_service.notifier_builder().create()
        # Safe overflow and borrowed samples: iceoryx2's defaults (§ 4).
        self.control_service = self.open(
            "control",
            lambda: self.node.service_builder(service_name(self.run, "control"))
            .publish_subscribe(wire.ControlMsg)
            .max_publishers(1)
            .max_subscribers(self.nodes + 1)
            .max_nodes(self.nodes + 2)
            .history_size(2)
            .subscriber_max_buffer_size(4)
            .open_or_create(),
        )
        self.control = self.control_service.subscriber_builder().create()

    def open(self, what, make):
        return retried(what, make, self.deadline)

    def state_svc(self, i):
        return self.open(
            f"node/{i}/state",
            lambda: self.node.service_builder(service_name(self.run, f"node/{i}/state"))
            .publish_subscribe(wire.StateMsg)
            .max_publishers(1)
            .max_subscribers(self.fanout)
            .max_nodes(self.fanout + 2)
            .history_size(0)
            .subscriber_max_buffer_size(int(self.lim["state_buffer"]))
            .subscriber_max_borrowed_samples(2)
            .enable_safe_overflow(False)
            .open_or_create(),
        )

    def wake_svc(self, i):
        return self.open(
            f"node/{i}/wake",
            lambda: self.node.service_builder(service_name(self.run, f"node/{i}/wake"))
            .event()
            .max_listeners(1)
            .max_notifiers(self.fanout + 1)
            .max_nodes(self.fanout + 3)
            .open_or_create(),
        )

    def telemetry_svc(self, me):
        return self.open(
            f"node/{me}/telemetry",
            lambda: self.node.service_builder(service_name(self.run, f"node/{me}/telemetry"))
            .publish_subscribe(wire.TelemetryMsg)
            .max_publishers(1)
            .max_subscribers(2)
            .max_nodes(4)
            .history_size(0)
            .subscriber_max_buffer_size(int(self.lim["telemetry_buffer"]))
            .subscriber_max_borrowed_samples(2)
            .enable_safe_overflow(False)
            .open_or_create(),
        )

    def release(self):
        """Deletes every port, then drops the services and the node."""
        for port in [self.state, self.wake, *self.inputs, *self.outputs, self.telemetry,
                     self.orchestrator, self.control]:
            port.delete()
        self.state = self.wake = self.telemetry = self.orchestrator = self.control = None
        self.inputs = self.outputs = []
        self.state_service = self.wake_service = self.telemetry_service = None
        self.orchestrator_service = self.control_service = None
        self.input_services = self.output_services = []
        self.node = None
