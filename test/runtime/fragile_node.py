"""A node with bugs on purpose, for the callback-isolation tests (run as ``fragile_node:FragileNode``).

``poke`` (std_msgs/String): ``boom`` raises an untyped error, as a bug would; anything else is
echoed on ``echo``. Parameter ``mode``: ``crash`` makes the node's own check raise ``KeyError``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from tdcm_ros.runtime.port import NodeLogic, NodePort


class FragileNode(NodeLogic):
    """Echoes ``poke`` on ``echo`` unless the text is ``boom``."""

    default_name = "fragile"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        port.declare_parameter("mode", "ok", description="crash: the node's check raises")
        port.add_on_set_parameters(self.check)
        self.echo = port.create_publisher("echo", "std_msgs/msg/String")
        port.create_subscription("poke", "std_msgs/msg/String", self.on_poke)

    def on_poke(self, message: Any) -> None:
        if message.data == "boom":
            raise RuntimeError("boom")
        self.echo.publish(message)

    def check(self, changes: Mapping[str, Any]) -> None:
        if changes.get("mode") == "crash":
            raise KeyError("crash")
