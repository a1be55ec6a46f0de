"""A typed subscription takes only what an rmw_zenoh publisher sends: a sample on the topic's
exact key with rmw_zenoh's attachment. A put on a wildcard key that overlaps the topic (which
drove the tendon to 12 N past a router's access list in issue 25) and a sample without the
attachment are refused, counted and warned about (throttled)."""

from __future__ import annotations

import logging
import time
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict, serialize
from tdcm_ros.runtime import wire
from test.runtime.test_transient_local_wire import _plain_session
from test.support.waiting import eventually

FLOAT = "std_msgs/msg/Float64"


def test_wildcard_keys_and_samples_without_attachment_are_refused(
        context: Any, caplog: pytest.LogCaptureFixture) -> None:
    from tdcm_ros.bagio import type_hash

    got: list[float] = []
    context.create_port("driver").create_subscription("tension_setpoint", FLOAT,
                                                      lambda m: got.append(m.data))
    key = wire.topic_key(context.domain_id, "/tension_setpoint", FLOAT, type_hash(FLOAT))
    session = _plain_session()
    attachment = wire.encode_attachment(1, time.time_ns(), bytes(wire.GID_SIZE))

    def payload(newtons: float) -> bytes:
        return bytes(serialize(from_dict(FLOAT, {"data": newtons}), FLOAT))

    try:
        eventually(lambda: any(r.ok for r in session.liveliness().get(
            f"{wire.ADMIN_SPACE}/{context.domain_id}/**/MS/**/%tension_setpoint/**",
            timeout=2.0)), 15.0, "the subscription's token")
        with caplog.at_level(logging.WARNING, "tdcm.zenoh"):
            session.put(f"{context.domain_id}/tension_setpoin$*/**", payload(12.0),
                        attachment=attachment)
            session.put(f"{context.domain_id}/*/std_msgs::msg::dds_::Float64_/*",
                        payload(13.0), attachment=attachment)
            session.put(key, payload(14.0))  # no attachment
            session.put(key, payload(1.5), attachment=attachment)
            eventually(lambda: got, 15.0, "the exact sample", spin=context)
            context.spin_for(0.2)
    finally:
        session.close()
    assert got == [1.5]
    refusals = [r.getMessage() for r in caplog.records if "refused a sample" in r.getMessage()]
    assert len(refusals) == 1  # the first at once, the other two held back
    assert "tension_setpoint" in refusals[0]
