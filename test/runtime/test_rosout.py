"""``/rosout``: a node's log records reach a peer as ``rcl_interfaces/msg/Log`` on both runtimes
(rcl publishes them on rclpy; :mod:`tdcm_ros.runtime.rosout` on the embedded runtime)."""

from __future__ import annotations

import logging
import math
import time
from pathlib import Path
from typing import Any

import yaml

from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.rosout import (
    LOG_TYPE,
    ROSOUT_QOS,
    ROSOUT_TOPIC,
    RosoutHandler,
    log_level,
    logger_name,
)
from test.support.waiting import eventually

DRIVER = "tdcm_ros.nodes.tension_driver:TensionDriverNode"
WARN = 30
NAN_WARNING = "tension_setpoint = nan N is not finite; ignored"


def level_of(message: Any) -> int:
    """``Log.level`` as an int (rosidl's Python type for ``byte`` is ``bytes``)."""
    raw = message.level
    return int.from_bytes(raw, "little") if isinstance(raw, bytes) else int(raw)


def test_a_node_warning_reaches_a_rosout_subscriber(runtime, spawn, context,
                                                    tmp_path: Path) -> None:
    """The driver (no device: an absent port) warns about a NaN setpoint; a peer subscribed
    to ``/rosout`` gets that record with level WARN, the node's logger name and call site."""
    params = tmp_path / "driver.yaml"
    params.write_text(yaml.safe_dump({"tension_driver": {"ros__parameters": {
        "port": str(tmp_path / "absent")}}}))
    before_ns = time.time_ns()
    node = spawn("tdcm_ros.runtime.run_node", DRIVER, "--params", str(params))
    port = context.create_port("rosout_probe")
    logs: list[Any] = []
    port.create_subscription(ROSOUT_TOPIC, LOG_TYPE, logs.append, ROSOUT_QOS)
    setpoint = port.create_publisher("/tension_setpoint", "std_msgs/msg/Float64")

    def warned() -> list[Any]:
        assert node.poll() is None, node.stderr.read().decode() if node.stderr else ""
        return [m for m in logs if m.msg == NAN_WARNING]

    found = eventually(warned, 30.0, "the NaN warning on /rosout", spin=context,
                       action=lambda: setpoint.publish(from_dict("std_msgs/msg/Float64",
                                                                 {"data": math.nan})),
                       detail=lambda: [m.msg for m in logs])
    record = found[0]
    assert (level_of(record), record.name) == (WARN, "tension_driver")
    assert record.file.endswith("tension_driver.py") and record.function == "_warn"
    # stamped with the system clock, between the node's start and its receipt here
    assert before_ns <= record.stamp.sec * 10**9 + record.stamp.nanosec <= time.time_ns()
    assert any(m.msg.startswith("running on ") and level_of(m) == 20 for m in logs)


class _Recorder:
    """A publisher that records messages and logs while publishing (as a transport might)."""

    def __init__(self, logger: logging.Logger) -> None:
        self.messages: list[Any] = []
        self._logger = logger

    def publish(self, message: Any) -> None:
        self._logger.warning("publishing %s", message.msg)
        self.messages.append(message)


def test_the_handler_maps_levels_and_never_recurses() -> None:
    logger = logging.getLogger("/ns/rosout_unit")
    logger.setLevel(logging.DEBUG)
    recorder = _Recorder(logger)
    handler = RosoutHandler("/ns/rosout_unit", recorder)
    logger.addHandler(handler)
    try:
        logger.debug("d")
        logger.info("i %d", 1)
        logger.warning("w")
        logger.error("e")
        logger.critical("c")
        logger.log(25, "between")
    finally:
        logger.removeHandler(handler)
    logger.warning("after removal")
    assert [(level_of(m), m.msg) for m in recorder.messages] == [
        (10, "d"), (20, "i 1"), (30, "w"), (40, "e"), (50, "c"), (20, "between")]
    assert {m.name for m in recorder.messages} == {"ns.rosout_unit"}
    assert recorder.messages[0].file == __file__
    assert recorder.messages[0].function == "test_the_handler_maps_levels_and_never_recurses"


def test_levels_and_names_follow_rcl() -> None:
    assert [log_level(n) for n in (0, 5, 10, 19, 20, 30, 40, 50, 60)] == [
        10, 10, 10, 10, 20, 30, 40, 50, 50]
    assert logger_name("/talker") == "talker"
    assert logger_name("/robot/arm/driver") == "robot.arm.driver"


def test_a_closed_port_stops_publishing_on_rosout(router: Any) -> None:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    ctx = ZenohContext()
    port = ctx.create_port("closing", "/rosout_test")
    assert sum(isinstance(h, RosoutHandler) for h in port.logger.handlers) == 1
    ctx.close()
    assert not any(isinstance(h, RosoutHandler) for h in port.logger.handlers)
