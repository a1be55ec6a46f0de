"""Demo node: publishes ``std_msgs/String`` on ``chatter`` and echoes ``~/echo`` on the log.

Parameters: ``period`` (s, 0.001..60), ``prefix`` (text before the counter).
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from typing import Any

from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime import NodeLogic, NodePort, QoS, declare_specs
from tdcm_ros.runtime.run_node import main_for
from tdcm_ros.spec import Spec, by_name

#: Every parameter of the node.
PARAMETERS = by_name(
    Spec("period", "s", "publishing period", 0.5, low=1e-3, high=60.0),
    Spec("prefix", description="text before the counter", default="hello", kind="str"))


class Talker(NodeLogic):
    """Publishes ``"<prefix> <n>"`` every ``period`` seconds."""

    default_name = "talker"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        self.period = float(declare_specs(port, PARAMETERS)["period"])
        port.add_on_set_parameters(self._on_set)
        self.count = 0
        self.publisher = port.create_publisher("chatter", "std_msgs/msg/String", QoS(depth=10))
        port.create_subscription("~/echo", "std_msgs/msg/String", self._on_echo, QoS(depth=10))
        self.timer = port.create_timer(self.period, self.tick)

    def tick(self) -> None:
        """Publish the next message."""
        self.count += 1
        text = f"{self.port.get_parameter('prefix')} {self.count}"
        self.publisher.publish(from_dict("std_msgs/msg/String", {"data": text}))

    def _on_echo(self, message: Any) -> None:
        self.port.logger.info("echo: %s", message.data)

    def _on_set(self, changes: Mapping[str, Any]) -> None:
        if "period" in changes:
            self.timer.cancel()
            self.period = float(changes["period"])
            self.timer = self.port.create_timer(self.period, self.tick)


def main() -> int:
    """``tdcm_talker`` executable."""
    return main_for(Talker)


if __name__ == "__main__":
    sys.exit(main())
