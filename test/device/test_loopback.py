"""The in-process cable from a host to the device twin (device.loopback)."""

from __future__ import annotations

import pytest

from tdcm_ros.device import PortError, encode
from tdcm_ros.device.loopback import Loopback
from tdcm_ros.device.protocol import DEVICE_TYPES, Banner, Info, LineDecoder
from tdcm_ros.device.twin import DeviceTwin


def test_bytes_go_both_ways_without_time_passing_for_the_host() -> None:
    twin = DeviceTwin()
    loop = Loopback(twin)
    twin.advance(0.05)  # the boot banner and telemetry nobody read
    link = loop.open("loop://a")
    assert link.read() == b""  # opening flushes what the device sent before
    link.write(encode(Info()))
    messages = LineDecoder(accept=DEVICE_TYPES).feed(link.read())
    assert any(isinstance(message, Banner) for message in messages)
    assert loop.opens == 1 and loop.writes == 1


def test_a_pulled_cable_fails_the_link_until_plugged_and_reopened() -> None:
    twin = DeviceTwin()
    loop = Loopback(twin)
    link = loop.open("loop://a")
    loop.unplug()
    with pytest.raises(PortError, match="read failed: cable pulled"):
        link.read()
    with pytest.raises(PortError, match="write failed: cable pulled"):
        link.write(b"H\n")
    with pytest.raises(PortError, match="cannot open: cable pulled"):
        loop.open("loop://a")
    twin.advance(0.1)
    loop.tick()  # dropped: nobody reads
    assert twin.output == bytearray()
    loop.plug()
    again = loop.open("loop://a")
    assert again.alive and not link.alive
    again.close()
    with pytest.raises(PortError, match="read failed: closed"):
        again.read()


def test_reopen_with_reboot_resets_the_device() -> None:
    twin = DeviceTwin()
    loop = Loopback(twin)
    link = loop.open("loop://a")
    twin.advance(0.3)
    assert twin.device_ms == 300
    loop.reopen(reboot=True)
    assert twin.device_ms == 0 and not link.alive
    assert loop.open("loop://a").alive
