"""The rclpy adapter: imports without ROS; exercised end to end where rclpy is importable."""

from __future__ import annotations

import importlib.util
import sys
import time
from typing import Any

import pytest

from tdcm_ros.nodes.talker import Talker

HAVE_RCLPY = importlib.util.find_spec("rclpy") is not None
NO_RCLPY = "rclpy is not importable (no ROS 2 Jazzy sourced); the adapter test runs on a ROS machine"


def test_adapter_imports_without_ros() -> None:
    import tdcm_ros.runtime.rclpy_runtime as adapter

    assert callable(adapter.RclpyContext)
    if not HAVE_RCLPY:
        assert "rclpy" not in sys.modules
        print(f"SKIP rclpy end-to-end: {NO_RCLPY}")


@pytest.mark.skipif(not HAVE_RCLPY, reason=NO_RCLPY)
def test_talker_on_rclpy_publishes_and_validates_parameters() -> None:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from std_msgs.msg import String

    from tdcm_ros.runtime.rclpy_runtime import RclpyNodePort

    rclpy.init()
    try:
        talker_node = rclpy.create_node("talker", namespace="/tdcm_test")
        listener = rclpy.create_node("listener", namespace="/tdcm_test")
        logic = Talker(RclpyNodePort(talker_node))
        texts: list[str] = []
        listener.create_subscription(String, "chatter", lambda m: texts.append(m.data), 10)
        executor = SingleThreadedExecutor()
        executor.add_node(talker_node)
        executor.add_node(listener)
        deadline = time.monotonic() + 10.0
        while not texts and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1)
        assert texts and texts[0].startswith("hello ")

        descriptor: Any = talker_node.describe_parameter("period")
        assert descriptor.floating_point_range[0].to_value == 60.0
        bad = talker_node.set_parameters([Parameter("period", value=-1.0)])[0]
        assert not bad.successful and "out of range" in bad.reason
        assert talker_node.get_parameter("period").value == 0.5
        assert logic.port.get_parameter("period") == 0.5
        good = talker_node.set_parameters([Parameter("prefix", value="bye")])[0]
        assert good.successful and logic.port.get_parameter("prefix") == "bye"
        executor.shutdown()
        talker_node.destroy_node()
        listener.destroy_node()
    finally:
        rclpy.try_shutdown()
