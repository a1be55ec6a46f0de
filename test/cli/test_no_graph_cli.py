"""With nothing answering at the zenoh endpoint, the graph tools say so and exit non-zero
(before: ``topic list`` printed nothing and exited 0, ``topic echo`` waited for a publisher,
``topic pub`` published "anyway"). In process: the refused connection is seen at once."""

from __future__ import annotations

import pytest

from test.support.cli import tdcm
from test.support.processes import free_port

COMMANDS = [
    ("topic", "list"),
    ("topic", "echo", "tension", "--once"),
    ("topic", "pub", "--once", "estop", "std_msgs/msg/Empty", "{}"),
    ("param", "list", "/model_node"),
    ("service", "call", "/tension_driver/estop", "std_srvs/srv/Trigger"),
]


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c[:2]))
def test_a_graph_tool_with_no_router_says_so_and_exits_1(
        command: tuple[str, ...], monkeypatch: pytest.MonkeyPatch) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    monkeypatch.setenv("TDCM_ZENOH_ENDPOINT", endpoint)
    monkeypatch.setenv("TDCM_RUNTIME", "zenoh")
    monkeypatch.delenv("TDCM_ZENOH_CONFIG", raising=False)
    result = tdcm(*command)
    assert result.returncode == 1, (result.stdout, result.stderr)
    assert f"no zenoh router: nothing answers at {endpoint}" in result.stderr
    assert result.stdout == ""
