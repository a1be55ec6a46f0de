"""Opening the device: one driver per port (an ``flock``), the second refused naming the holder."""

from __future__ import annotations

import os
import pty
from collections.abc import Iterator

import pytest

from tdcm_ros.device.errors import PortError
from tdcm_ros.device.transport import lock_holders, open_transport


@pytest.fixture
def pty_path() -> Iterator[str]:
    """The path of a fresh pty's device end (what ``tdcm_ros.device.twin`` offers)."""
    primary, secondary = pty.openpty()
    yield os.ttyname(secondary)
    os.close(secondary)
    os.close(primary)


def test_a_second_open_of_a_held_port_is_refused_naming_the_holder(pty_path: str) -> None:
    """Issue 25: a second driver opened the port the first held and the tension fell to 0 N."""
    first = open_transport(pty_path)
    try:
        assert lock_holders(pty_path) == [lock_holders(pty_path)[0]]
        with pytest.raises(PortError) as refused:
            open_transport(pty_path)
        message = str(refused.value)
        assert f"port {pty_path!r} is in use by pid {os.getpid()} (" in message
        assert message.endswith("one driver per device")
    finally:
        first.close()
    assert lock_holders(pty_path) == []
    open_transport(pty_path).close()  # free again once the first is closed


def test_urls_without_a_file_still_open() -> None:
    open_transport("loop://").close()
