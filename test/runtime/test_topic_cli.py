"""``tdcm topic echo|hz|list`` against a private router, the tool in its own process."""

from __future__ import annotations

import subprocess
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import yaml
from runtime_helpers import wait_for

from tdcm_ros.bagio import from_dict

Spawn = Callable[..., subprocess.Popen[bytes]]
BURST = 300


@pytest.fixture
def port(router: subprocess.Popen[bytes]) -> Iterator[Any]:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    ctx = ZenohContext()
    yield ctx.create_port("test_publisher")
    ctx.close()


def documents(output: bytes) -> list[Any]:
    """The YAML documents ``topic echo`` printed (each ends with ``---``)."""
    return [doc for doc in yaml.safe_load_all(output.decode()) if doc is not None]


@pytest.mark.parametrize(("args", "expected"), [(("std_msgs/msg/String", "--once"), 1),
                                                (("--once",), 1),
                                                (("--count", "3"), 3)],
                         ids=["once_typed", "once_any_type", "count_3"])
def test_echo_prints_exactly_the_requested_number_of_a_burst(port, spawn: Spawn, args, expected):
    publisher = port.create_publisher("chatter", "std_msgs/msg/String")
    echo = spawn("tdcm_ros.cli.main", "topic", "echo", "chatter", *args)
    wait_for(publisher.matched, 15.0, "topic echo to subscribe")
    # Back to back, so many samples wait in the tool's queue when the first one is printed.
    for k in range(BURST):
        publisher.publish(from_dict("std_msgs/msg/String", {"data": f"burst {k}"}))
    out, err = echo.communicate(timeout=20)
    assert echo.returncode == 0, err.decode()
    docs = documents(out)
    assert len(docs) == expected, f"{args} printed {len(docs)} messages"
    # Keep-last history may skip samples of the burst, never repeat or reorder them.
    indices = [int(doc["data"].removeprefix("burst ")) for doc in docs]
    assert indices == sorted(set(indices))
