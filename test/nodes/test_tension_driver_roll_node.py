"""tension_driver's roll, in its own process over a real pty to the device twin in this process,
on the embedded runtime and on rclpy (the ``runtime`` fixture): ``roll_setpoint`` in (clamped,
slewed, refused while disarmed), ``joint_states`` out, the servo holding through an e-stop, the
roll limits read-only."""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.device.plant import PlantConfig
from tdcm_ros.device.twin import DeviceTwin, PtyTwin
from test.nodes.tension_probe import DRIVER, Probe, driver_params, stamp_ns, values
from test.support.processes import stop

ROLL_RATE = 0.8  #: rad/s, the driver's slew in these tests


@pytest.fixture
def twin(tmp_path: Path) -> Iterator[PtyTwin]:
    server = PtyTwin(DeviceTwin(PlantConfig(seed=7)), link=str(tmp_path / "tdcm_port")).start()
    yield server
    server.stop()


class RollProbe(Probe):
    """The tension probe plus ``roll_setpoint`` out and ``joint_states`` in."""

    def __init__(self, ctx: Any) -> None:
        super().__init__(ctx)
        port = ctx.create_port("roll_probe")
        self.joints: list[Any] = []
        port.create_subscription("joint_states", "sensor_msgs/msg/JointState", self.joints.append)
        self._roll = port.create_publisher("roll_setpoint", "std_msgs/msg/Float64")

    def roll(self, radians: float) -> None:
        self._roll.publish(from_dict("std_msgs/msg/Float64", {"data": radians}))

    def actuator(self) -> dict[str, str]:
        status = self.component("actuator")
        return values(status) if status is not None else {}


@pytest.fixture
def probe(context: Any) -> RollProbe:
    return RollProbe(context)


def start(spawn: Any, tmp_path: Path, twin: PtyTwin, **params: Any) -> Any:
    path = driver_params(tmp_path / "driver.yaml", **{"port": twin.port, "roll_rate": ROLL_RATE,
                                                      "diagnostics_period_s": 0.2, **params})
    return spawn("tdcm_ros.runtime.run_node", DRIVER, "--name", "tension_driver",
                 "--params", path)


def positions(probe: RollProbe) -> list[tuple[float, float]]:
    return [(stamp_ns(m) / 1e9, float(m.position[0])) for m in probe.joints]


def test_roll_setpoint_is_slewed_clamped_and_published_as_joint_states(
        runtime, spawn, probe, twin, tmp_path) -> None:
    node = start(spawn, tmp_path, twin)
    probe.connected()
    probe.until(lambda: len(probe.joints) > 20, 10.0, "joint_states at the boot position")
    assert all(list(m.name) == ["roll"] and list(m.position) == [0.0] for m in probe.joints)
    assert all(len(m.velocity) == 0 for m in probe.joints)
    first = len(probe.joints)
    probe.until(lambda: probe.joints and float(probe.joints[-1].position[0]) == 0.9, 15.0,
                "roll 0.9 rad", action=lambda: probe.roll(0.9))
    moving = [p for p in positions(probe)[first:] if 0.0 < p[1] < 0.9]
    assert len(moving) >= 40  # ~1.1 s of 50 Hz frames on the way
    slope = (moving[-1][1] - moving[0][1]) / (moving[-1][0] - moving[0][0])
    print(f"\nroll 0 -> 0.9 rad: {slope:.3f} rad/s over {len(moving)} joint_states "
          f"(roll_rate {ROLL_RATE} rad/s)")
    assert slope == pytest.approx(ROLL_RATE, rel=0.1)
    # joint_states reports the servo pulse; the twin's servo follows it at its own speed, so
    # wait for it to arrive (a CI run on rclpy read it 4 mrad short, still turning).
    probe.until(lambda: abs(twin.twin.plant.roll - 0.9) <= 2e-3, 5.0, "the servo at 0.9 rad")
    assert twin.twin.plant.roll == pytest.approx(0.9, abs=2e-3)
    probe.until(lambda: probe.actuator().get("roll_target") == f"{math.pi / 2:.3f}", 10.0,
                "target clamped to pi/2", action=lambda: probe.roll(2.0))
    probe.until(lambda: int(probe.actuator().get("clamped_rolls", 0)) >= 1, 5.0, "counted")
    assert "clamped to 1.5708 rad" in probe.actuator()["last_warning"]
    probe.until(lambda: twin.twin.core.roll_mrad == 1571, 10.0, "the servo at pi/2")
    stamps = [stamp_ns(m) for m in probe.joints]
    assert stamps == sorted(stamps)
    assert stop(node, 20.0) == 0


def test_estop_holds_the_roll_and_refuses_it_until_clear_faults(runtime, spawn, probe, twin,
                                                                tmp_path) -> None:
    start(spawn, tmp_path, twin)
    probe.connected()
    core, plant = twin.twin.core, twin.twin.plant
    probe.until(lambda: core.roll_mrad <= -400, 15.0, "rolling toward -1.2 rad",
                action=lambda: probe.roll(-1.2))
    probe.estop()
    probe.until(lambda: probe.state().get("armed") == "false", 10.0, "disarmed")
    held = core.roll_mrad
    assert -1200 < held <= -400 and core.roll_target_mrad == held  # stopped on the way
    probe.until(lambda: int(probe.actuator().get("rejected_rolls", 0)) >= 1, 10.0,
                "a roll refused while disarmed", action=lambda: probe.roll(1.0))
    count = len(probe.joints)
    end = time.monotonic() + 1.0
    while time.monotonic() < end:
        assert core.roll_mrad == held, "the servo moved while disarmed"
        probe.ctx.spin_for(0.05)
    assert len(probe.joints) - count >= 25  # joint_states go on: the held position
    assert {float(m.position[0]) for m in probe.joints[count:]} == {held / 1000}
    assert plant.roll == pytest.approx(held / 1000, abs=2e-3)
    probe.until(lambda: probe.state().get("armed") == "true", 10.0, "armed",
                action=probe.clear_faults)
    assert core.roll_mrad == held  # arming alone does not move it
    probe.until(lambda: core.roll_mrad == 0, 15.0, "rolled back to 0",
                action=lambda: probe.roll(0.0))


def test_roll_limits_are_read_only_safety_limits(runtime, spawn, probe, twin, tmp_path,
                                                 params) -> None:
    start(spawn, tmp_path, twin)
    probe.connected()
    driver = params("/tension_driver")
    assert driver.get("roll_max") == pytest.approx(math.pi / 2)
    for name, value in (("roll_max", 1.0), ("roll_rate", 2.0)):
        refused = driver.set(name, value)
        assert not refused["successful"], refused
        assert "safety.limits_writable: true" in refused["reason"], refused
    assert driver.get("roll_rate") == ROLL_RATE
