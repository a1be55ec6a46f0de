"""A second node of a name already in the graph warns (issue 25: two nodes of one name ran with
no warning); a name of its own does not."""

from __future__ import annotations

import logging
from typing import Any

import pytest

from tdcm_ros.runtime import wire
from tdcm_ros.runtime.zenoh_query import graph_tokens
from test.support.waiting import eventually


def test_a_second_node_of_one_name_warns(context: Any,
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
    finally:
        other.close()
    warned = [r.getMessage() for r in caplog.records if "already in the graph" in r.getMessage()]
    expected = (f"a node named /tension_driver is already in the graph (session {context.zid}); "
                "tools and parameter clients cannot tell the two apart")
    assert warned == [expected]
