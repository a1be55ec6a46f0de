"""The rclpy runtime in-process: imports, message classes, parameters; the ROS-free core stays so."""

from __future__ import annotations

import json
import subprocess
import sys
from typing import Any

import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.nodes.talker import Talker
from tdcm_ros.runtime.errors import RuntimePortError
from test.support.graph import REPO, private_domain_id, require_rclpy
from test.support.waiting import eventually

CORE = ("model", "metrics", "mocap", "device", "bagio", "scenes")


def test_the_ros_free_core_imports_neither_rclpy_nor_zenoh() -> None:
    code = ("import json, sys\n"
            + "".join(f"import tdcm_ros.{name}\n" for name in CORE)
            + "import tdcm_ros.runtime.rclpy_runtime\n"
            + "print(json.dumps(sorted(m for m in sys.modules "
              "if m.split('.')[0] in ('rclpy', 'zenoh', 'rosidl_runtime_py'))))")
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True,
                         check=True, timeout=60).stdout
    assert json.loads(out) == []


@pytest.fixture
def rclpy_context(monkeypatch: pytest.MonkeyPatch) -> Any:
    require_rclpy()
    monkeypatch.setenv("ROS_DOMAIN_ID", str(private_domain_id()))
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from tdcm_ros.runtime.rclpy_runtime import RclpyContext

    context = RclpyContext()
    yield context
    context.close()


@pytest.mark.rclpy
def test_message_classes_come_from_the_installed_interfaces(rclpy_context: Any) -> None:
    from nav_msgs.msg import Path

    from tdcm_ros.runtime.rclpy_runtime import message_class

    assert message_class("nav_msgs/msg/Path") is Path
    assert message_class("nav_msgs/Path") is Path
    # In the Jazzy typestore, but its interface package is not installed with these wheels.
    with pytest.raises(RuntimePortError, match="stereo_msgs/msg/DisparityImage is not importable"):
        message_class("stereo_msgs/msg/DisparityImage")


@pytest.mark.rclpy
def test_talker_publishes_and_parameters_are_typed_ranged_and_checked(rclpy_context) -> None:
    from rclpy.parameter import Parameter

    ctx = rclpy_context
    port = ctx.create_port("talker", "/tdcm_test", overrides={"period": 1, "prefix": "yaml"})
    logic = Talker(port)
    texts: list[str] = []
    listener = ctx.create_port("listener", "/tdcm_test")
    listener.create_subscription("chatter", "std_msgs/msg/String", lambda m: texts.append(m.data))
    eventually(lambda: texts, 10.0, "the talker's first message", spin=ctx)
    assert texts[0].startswith("yaml ")

    node = port.node
    assert logic.port.get_parameter("period") == 1.0  # a YAML int widened to the float parameter
    assert node.get_parameter("period").type_ == Parameter.Type.DOUBLE
    descriptor = node.describe_parameter("period")
    assert descriptor.floating_point_range[0].to_value == 60.0
    bad = node.set_parameters([Parameter("period", value=-1.0)])[0]
    assert not bad.successful and "period" in bad.reason and "out of range" in bad.reason
    assert node.get_parameter("period").value == 1.0 and logic.port.get_parameter("period") == 1.0
    widened = node.set_parameters([Parameter("period", value=2)])[0]
    assert widened.successful and node.get_parameter("period").value == 2.0
    assert logic.port.get_parameter("period") == 2.0
    wrong = node.set_parameters([Parameter("prefix", value=3.0)])[0]
    assert not wrong.successful and logic.port.get_parameter("prefix") == "yaml"
    good = node.set_parameters([Parameter("prefix", value="bye")])[0]
    assert good.successful and logic.port.get_parameter("prefix") == "bye"


@pytest.mark.rclpy
def test_a_bad_override_is_an_input_error_naming_the_parameter(rclpy_context: Any) -> None:
    port = rclpy_context.create_port("talker", overrides={"period": -2.0})
    with pytest.raises(InputError, match="period"):
        Talker(port)


@pytest.mark.rclpy
def test_params_files_in_ros_args_apply_by_the_remapped_name(monkeypatch, tmp_path) -> None:
    """As ``ros2 launch`` starts a node: ``--ros-args -r __node:=... --params-file F``."""
    require_rclpy()
    monkeypatch.setenv("ROS_DOMAIN_ID", str(private_domain_id()))
    from tdcm_ros.runtime.rclpy_runtime import RclpyContext

    path = tmp_path / "launch.yaml"
    path.write_text("/lab/chatty:\n  ros__parameters:\n    period: 3\n    prefix: launched\n"
                    "talker:\n  ros__parameters:\n    prefix: wrong_name\n")
    context = RclpyContext(["--ros-args", "-r", "__node:=chatty", "-r", "__ns:=/lab",
                            "--params-file", str(path)])
    try:
        port = context.create_port("talker")
        Talker(port)
        assert port.node.get_fully_qualified_name() == "/lab/chatty"
        assert port.get_parameter("period") == 3.0 and port.get_parameter("prefix") == "launched"
    finally:
        context.close()


@pytest.mark.rclpy
def test_a_busy_timer_does_not_starve_the_entities_after_it(rclpy_context: Any) -> None:
    """Every entity ready at one wake-up runs before the next wait, however ``spin_for`` is cut.

    The first timer's callback outlasts its period, so it is ready at every wait; before the
    fix each ``spin_once`` (a new timeout each time) ran only the first ready entity and the
    second timer never ran (the CI symptom: a probe's ``/diagnostics`` subscription, behind two
    400 Hz marker subscriptions, saw nothing for 10 s)."""
    import time

    port = rclpy_context.create_port("busy")
    runs = {"busy": 0, "starved": 0}

    def busy() -> None:
        runs["busy"] += 1
        time.sleep(0.002)  # a callback longer than the 1 ms period: ready again at once

    port.create_timer(0.001, busy)
    port.create_timer(0.001, lambda: runs.__setitem__("starved", runs["starved"] + 1))
    eventually(lambda: runs["starved"] >= 5, 10.0, "the second timer to run",
               spin=rclpy_context, detail=lambda: runs)
    assert runs["busy"] >= 5
