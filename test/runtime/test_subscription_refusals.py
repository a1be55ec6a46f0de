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


def test_wildcard_and_attachment_less_requests_are_refused_with_an_error_reply(
        context: Any, caplog: pytest.LogCaptureFixture) -> None:
    """A service answers only a query on its exact key with rmw_zenoh's attachment; a wildcard
    query overlapping it or one without the attachment gets an error reply naming the refusal,
    never reaches the handler, is counted and warned about (throttled)."""
    import threading

    from tdcm_ros.bagio import service_type_hash

    trigger = "std_srvs/srv/Trigger"
    calls: list[str] = []

    def handle(_request: Any) -> Any:
        calls.append("called")
        return from_dict(f"{trigger}_Response", {"success": True, "message": "done"})

    context.create_port("tension_driver").create_service("~/clear_faults", trigger, handle)
    key = wire.topic_key(context.domain_id, "/tension_driver/clear_faults", trigger,
                         service_type_hash(trigger))
    request = bytes(serialize(from_dict(f"{trigger}_Request", {}), f"{trigger}_Request"))
    attachment = wire.encode_attachment(1, time.time_ns(), bytes(wire.GID_SIZE))
    session = _plain_session()
    spinner = threading.Thread(target=context.spin, daemon=True)
    spinner.start()

    def replies(selector: str, **options: Any) -> list[str]:
        got = []
        for reply in session.get(selector, payload=request, timeout=5.0, **options):
            got.append(reply.ok.payload.to_bytes().decode(errors="replace") if reply.ok
                       else "error: " + reply.err.payload.to_bytes().decode())
        return got

    try:
        eventually(lambda: any(r.ok for r in session.liveliness().get(
            f"{wire.ADMIN_SPACE}/{context.domain_id}/**/SS/**/%tension_driver%clear_faults/**",
            timeout=2.0)), 15.0, "the service's token")
        with caplog.at_level(logging.WARNING, "tdcm.zenoh"):
            wildcard = replies(f"{context.domain_id}/tension_driver/clear_fault$*/**",
                               attachment=attachment)
            bare = replies(key)
            exact = replies(key, attachment=attachment)
    finally:
        context.request_stop()
        spinner.join(5.0)
        session.close()
    overlapping = f"'{context.domain_id}/tension_driver/clear_fault$*/**'"
    assert wildcard == [(f"error: /tension_driver/clear_faults: refused: key {overlapping} is "
                        f"not the service's key")]
    assert bare == ["error: /tension_driver/clear_faults: refused: no rmw_zenoh attachment"]
    assert len(exact) == 1 and "done" in exact[0] and calls == ["called"]
    refusals = [r.getMessage() for r in caplog.records if "refused a request" in r.getMessage()]
    assert len(refusals) == 1 and "clear_faults" in refusals[0]
