"""device_twin publishes its simulated roll servo's true angle on ``sim/joint_states_true``, at
the rate and stamps of ``sim/tension_true``, on both runtimes (the ``runtime`` fixture); the
driver core in this process commands the roll over the twin's pty."""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import yaml

from tdcm_ros.device.driver import DriverConfig, TensionDriver
from test.nodes.tension_probe import TWIN, stamp_ns
from test.support.processes import stop
from test.support.waiting import eventually


def test_twin_node_publishes_the_true_roll(runtime, spawn, context, tmp_path: Path) -> None:
    joints: list[Any] = []
    truth: list[Any] = []
    port = context.create_port("roll_truth_probe")
    port.create_subscription("sim/joint_states_true", "sensor_msgs/msg/JointState", joints.append)
    port.create_subscription("sim/tension_true", "geometry_msgs/msg/WrenchStamped", truth.append)
    link = tmp_path / "twin_link"
    params = tmp_path / "twin.yaml"
    params.write_text(yaml.safe_dump({"device_twin": {"ros__parameters": {
        "link": str(link), "roll_speed": 4.0}}}))
    node = spawn("tdcm_ros.runtime.run_node", TWIN, "--params", str(params))
    eventually(lambda: link.is_symlink(), 30.0, "the twin's link")
    driver = TensionDriver(DriverConfig(port=str(link), roll_rate=1.5), clock=time.monotonic)
    try:
        requested = False
        results: list[Any] = []

        def step() -> None:  # the driver's loop; the probe spins 5 ms between steps
            nonlocal requested
            results.append(driver.step())
            known = results[-1].joints  # the device's roll is known to the driver
            if known and len(joints) >= 5 and not requested:  # and the probe hears the twin
                requested = driver.set_roll(-0.7) is not None

        def detail() -> str:
            status = results[-1].status if results else None
            return f"{joints[-1:]}; roll requested {requested}; driver " + (
                f"{status.link.name}, armed {status.armed}, disarmed for "
                f"{status.disarm_reason!r}" if status is not None else "never stepped")

        eventually(lambda: joints and abs(float(joints[-1].position[0]) + 0.7) < 2e-3, 30.0,
                   "the true roll at -0.7 rad", action=step, every=0.0,
                   spin=SimpleNamespace(spin_for=lambda _: context.spin_for(0.005)),
                   detail=detail)
    finally:
        driver.close()
    assert all(list(m.name) == ["roll"] and len(m.position) == 1 for m in joints)
    angles = [float(m.position[0]) for m in joints]
    stamps = np.array([stamp_ns(m) for m in joints]) / 1e9
    assert angles[0] == 0.0 and min(angles) == pytest.approx(-0.7, abs=2e-3)
    assert np.all(np.diff(stamps) >= 0) and 0.010 <= statistics.median(np.diff(stamps)) <= 0.015
    start = stamps[next(i for i, a in enumerate(angles) if a != 0.0)]
    arrived = stamps[next(i for i, a in enumerate(angles) if abs(a + 0.7) < 2e-3)]
    assert arrived - start >= 0.9 * 0.7 / 1.5  # slewed at the driver's 1.5 rad/s, not a jump
    common = {stamp_ns(m) for m in joints} & {stamp_ns(m) for m in truth}
    assert len(common) >= 0.9 * min(len(joints), len(truth))  # the same samples
    assert stop(node, 20.0) == 0
