"""Two nodes of one name in the graph both warn, whichever came first (issue 25: two nodes of one
name ran with no warning); a name of its own does not. The warning comes from a liveliness
subscriber with history, on zenoh's thread: the test waits for it (a start-time query of the
graph with a 0.5 s bound missed the first node once beside a CPU hog)."""

from __future__ import annotations

import logging
from typing import Any

import pytest

from tdcm_ros.runtime import wire
from tdcm_ros.runtime.zenoh_query import graph_tokens
from test.support.waiting import eventually


def test_two_nodes_of_one_name_both_warn(context: Any,
                                         caplog: pytest.LogCaptureFixture) -> None:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    context.create_port("tension_driver")
    eventually(lambda: any(t.kind == wire.NODE and t.node_fqn == "/tension_driver"
                           for t in graph_tokens(context.session, context.domain_id)),
               15.0, "the first node's token")
    other = ZenohContext()
    try:
        with caplog.at_level(logging.WARNING, "/tension_driver"):
            other.create_port("tension_driver")
            other.create_port("model_node")

            def warned() -> list[str]:
                return sorted(r.getMessage() for r in caplog.records
                              if "in the graph" in r.getMessage())

            expected = sorted(
                f"another node named /tension_driver is in the graph (session {zid}); tools "
                "and parameter clients cannot tell the two apart"
                for zid in (context.zid, other.zid))
            eventually(lambda: warned() == expected, 15.0, "both nodes to warn",
                       detail=warned)
    finally:
        other.close()
    assert not any("/model_node" in r.getMessage() for r in caplog.records)
