"""``tension_driver`` as a managed (lifecycle) node, in-process on a device twin and simulated
time: configure opens the port, activate arms, deactivate releases, cleanup closes; its safety
rules hold in every state."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.device.protocol import Mode
from test.nodes.driver_bench import DriverBench

BAND = 0.25  #: N


@pytest.fixture
def bench() -> Iterator[DriverBench]:
    made = DriverBench({"managed": True})
    yield made
    made.close()


def change(bench: DriverBench, label: str) -> bool:
    request = from_dict("lifecycle_msgs/srv/ChangeState_Request",
                        {"transition": {"id": 0, "label": label}})
    return bool(bench.port.call("~/change_state", request).success)


def lifecycle_state(bench: DriverBench) -> str:
    return str(bench.port.call("~/get_state").current_state.label)


def test_unconfigured_the_port_stays_closed_and_nothing_arms(bench: DriverBench) -> None:
    bench.advance(1.0)
    assert lifecycle_state(bench) == "unconfigured"
    assert bench.open_attempts == [] and bench.port.messages("tension") == []
    answer = bench.call("clear_faults")
    assert not answer.success and "lifecycle state unconfigured; activate arms" in answer.message


def test_configure_activate_deactivate_cleanup_drive_the_device(bench: DriverBench) -> None:
    core, plant = bench.twin.core, bench.twin.plant
    assert change(bench, "configure") and lifecycle_state(bench) == "inactive"
    assert bench.open_attempts == [0]
    bench.until(lambda: bench.state().get("link") == "connected", 2.0, "the handshake")
    bench.setpoint(6.0)  # inactive: refused, the tendon stays slack
    bench.advance(1.0)
    assert core.mode is Mode.RELEASE and plant.tension == 0.0
    assert bench.state()["disarm_reason"] == "managed node not active: activate arms"

    assert change(bench, "activate") and lifecycle_state(bench) == "active"
    bench.setpoint(6.0)
    bench.until(lambda: abs(plant.tension - 6.0) < BAND, 5.0, "6 N once active")

    assert change(bench, "deactivate") and lifecycle_state(bench) == "inactive"
    bench.until(lambda: core.mode is Mode.RELEASE, 0.05, "released on deactivate")
    bench.setpoint(6.0)
    bench.advance(1.0)
    assert plant.tension == 0.0 and bench.state()["armed"] == "false"

    link = bench.loop.link
    assert change(bench, "cleanup") and lifecycle_state(bench) == "unconfigured"
    assert link is not None and link.closed and bench.loop.link is None
    published = len(bench.port.messages("tension"))
    bench.advance(1.0)
    assert len(bench.port.messages("tension")) == published  # no link, no telemetry

    assert change(bench, "configure") and change(bench, "shutdown")
    assert lifecycle_state(bench) == "finalized"
    assert core.mode is Mode.RELEASE


def test_activate_before_the_handshake_fails_and_stays_inactive(bench: DriverBench) -> None:
    assert change(bench, "configure")
    assert not change(bench, "activate")
    assert lifecycle_state(bench) == "inactive"
    assert bench.node.lifecycle is not None
    assert "link handshaking" in bench.node.lifecycle.last_failure
    bench.until(lambda: bench.state().get("link") == "connected", 2.0, "the handshake")
    assert change(bench, "activate")


def test_a_port_that_does_not_open_fails_configure_naming_it(bench: DriverBench) -> None:
    bench.loop.unplug()
    assert not change(bench, "configure") and lifecycle_state(bench) == "unconfigured"
    assert bench.node.lifecycle is not None
    assert "cable pulled" in bench.node.lifecycle.last_failure
    bench.advance(2.0)
    assert len(bench.open_attempts) == 1  # no reconnect loop while unconfigured


def test_an_unmanaged_driver_serves_no_lifecycle() -> None:
    plain = DriverBench()
    try:
        assert plain.node.lifecycle is None
        assert "~/change_state" not in plain.port.services
    finally:
        plain.close()
