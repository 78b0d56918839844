"""PROTOCOL.md § 3-4: the iceoryx2 node, services and ports of one node."""

import iceoryx2 as iox2

import wire


def service_name(run, rest):
    return iox2.ServiceName.new(f"attsync/{run}/{rest}")


class Ports:
    """Every port of § 4, opened with exactly the settings of the table."""

    def __init__(self, cfg):
        run, me = cfg["run"], int(cfg["id"])
        lim = cfg["limits"]
        fanout, nodes = int(lim["max_fanout"]), int(lim["nodes"])
        c = iox2.config.default()
        c.global_cfg.prefix = iox2.FileName.new(f"as{run}_")
        c.global_cfg.root_path = iox2.Path.new(cfg["iox_root"] + "/")
        self.node = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new(f"independent_{me}"))
            .config(c)
            .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
            .create(iox2.ServiceType.Ipc)
        )
        self.millisecond = iox2.Duration.from_millis(1)
        retry = iox2.BackpressureStrategy.RetryUntilDelivered

        def state_service(i):
            return (
                self.node.service_builder(service_name(run, f"node/{i}/state"))
                .publish_subscribe(wire.StateMsg)
                .max_publishers(1)
                .max_subscribers(fanout)
                .max_nodes(fanout + 2)
                .history_size(0)
                .subscriber_max_buffer_size(int(lim["state_buffer"]))
                .subscriber_max_borrowed_samples(2)
                .enable_safe_overflow(False)
                .open_or_create()
            )

        def wake_service(i):
            return (
                self.node.service_builder(service_name(run, f"node/{i}/wake"))
                .event()
                .max_listeners(1)
                .max_notifiers(fanout + 1)
                .max_nodes(fanout + 3)
                .open_or_create()
            )

        self.state_service = state_service(me)
        self.state = self.state_service.publisher_builder().backpressure_strategy(retry).create()
        self.wake_service = wake_service(me)
        self.wake = self.wake_service.listener_builder().create()
        self.input_services = [state_service(i) for i in cfg["inputs"]]
        self.inputs = [
            svc.subscriber_builder().buffer_size(int(lim["state_buffer"])).create()
            for svc in self.input_services
        ]
        self.output_services = [wake_service(i) for i in cfg["outputs"]]
        self.outputs = [svc.notifier_builder().create() for svc in self.output_services]
        self.telemetry_service = (
            self.node.service_builder(service_name(run, f"node/{me}/telemetry"))
            .publish_subscribe(wire.TelemetryMsg)
            .max_publishers(1)
            .max_subscribers(2)
            .max_nodes(4)
            .history_size(0)
            .subscriber_max_buffer_size(int(lim["telemetry_buffer"]))
            .subscriber_max_borrowed_samples(2)
            .enable_safe_overflow(False)
            .open_or_create()
        )
        self.telemetry = (
            self.telemetry_service.publisher_builder().backpressure_strategy(retry).create()
        )
        self.orchestrator_service = (
            self.node.service_builder(service_name(run, "orchestrator/wake"))
            .event()
            .max_listeners(1)
            .max_notifiers(nodes + 1)
            .max_nodes(nodes + 2)
            .open_or_create()
        )
        self.orchestrator = self.orchestrator_service.notifier_builder().create()
        self.control_service = (
            self.node.service_builder(service_name(run, "control"))
            .publish_subscribe(wire.ControlMsg)
            .max_publishers(1)
            .max_subscribers(nodes + 1)
            .max_nodes(nodes + 2)
            .history_size(2)
            .subscriber_max_buffer_size(4)
            .open_or_create()
        )
        self.control = self.control_service.subscriber_builder().create()

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
