"""``qos_overrides.<topic>.<endpoint>.<policy>`` parameters, as rclpy names them: in-process on
a memory port, then a best-effort tension publisher driving model_node on both runtimes."""

from __future__ import annotations

import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.nodes.metrics_node import MetricsNode
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.port import QoS
from tdcm_ros.runtime.qos_overrides import overridable_qos
from test.nodes.test_model_node import MODEL, Probe

Spawn = Callable[..., subprocess.Popen[bytes]]
MARKERS = "qos_overrides./markers.subscription"


def test_the_default_is_the_nodes_own_qos_and_each_policy_is_a_read_only_parameter() -> None:
    port = MemoryPort({}, name="node", namespace="/lab")
    qos = overridable_qos(port, "markers", QoS(depth=50, durability="transient_local"))
    assert qos == QoS(depth=50, durability="transient_local")
    prefix = "qos_overrides./lab/markers.subscription"
    assert {name: port.get_parameter(name) for name in port.store.specs} == {
        f"{prefix}.reliability": "reliable", f"{prefix}.durability": "transient_local",
        f"{prefix}.depth": 50}
    refused = port.store.set({f"{prefix}.reliability": "best_effort"})
    assert not refused.successful and "read-only" in refused.reason
    assert port.get_parameter(f"{prefix}.reliability") == "reliable"


def test_a_parameter_file_makes_a_sensor_input_best_effort() -> None:
    port = MemoryPort({f"{MARKERS}.reliability": "best_effort", f"{MARKERS}.depth": 7},
                      name="metrics_node")
    node = MetricsNode(port)
    try:
        _, _, markers = port.subscriptions["markers"]
        _, _, tension = port.subscriptions["tension"]
        assert markers.reliability == "best_effort" and markers.depth == 7
        assert tension.reliability == "reliable"
    finally:
        node.close()


@pytest.mark.parametrize(("policy", "value", "allowed"), [
    ("reliability", "sometimes", "reliable | best_effort"),
    ("durability", "forever", "volatile | transient_local"),
    ("depth", 0, "[1, 10000]"),
])
def test_a_bad_override_is_an_input_error_naming_the_parameter(policy: str, value: Any,
                                                              allowed: str) -> None:
    port = MemoryPort({f"{MARKERS}.{policy}": value}, name="metrics_node")
    with pytest.raises(InputError) as caught:
        MetricsNode(port)
    assert caught.value.parameter == f"{MARKERS}.{policy}" and allowed in str(caught.value)


def test_a_best_effort_tension_publisher_drives_model_node_with_the_override(
        runtime: str, context: Any, spawn: Spawn, tmp_path: Path) -> None:
    """On DDS a reliable subscription never matches a best-effort publisher; the override
    makes model_node's one best-effort, and its midline follows the sensor's tension."""
    path = tmp_path / "qos.yaml"
    path.write_text("model_node:\n  ros__parameters:\n    qos_overrides:\n      /tension:\n"
                    "        subscription: {reliability: best_effort, depth: 5}\n")
    spawn("tdcm_ros.runtime.run_node", MODEL, "--params", str(path))
    probe = Probe(context)
    sensor = context.create_port("force_sensor")
    probe.tension = sensor.create_publisher("tension", "geometry_msgs/msg/WrenchStamped",
                                            QoS(depth=5, reliability="best_effort"))
    assert probe.midline_for(8.0, timeout=60.0).header.frame_id == "tdcm_base"
