"""Services on the embedded runtime in rmw_zenoh's format, checked by a plain zenoh session
acting as an rmw_zenoh client (key, ``SS`` token, request and reply attachments), and through
the runtime's own client. Formats: ``rmw_service_data.cpp``/``rmw_client_data.cpp`` of
rmw_zenoh_cpp 0.2.x (see :mod:`tdcm_ros.runtime.wire`)."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from tdcm_ros.bagio import deserialize, from_dict, serialize
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.port import NodeLogic, NodePort
from tdcm_ros.runtime.wire import decode_attachment, encode_attachment
from test.support.waiting import eventually

zenoh = pytest.importorskip("zenoh")

TRIGGER_HASH = "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"
KEY = f"0/counter/reset/std_srvs::srv::dds_::Trigger_/{TRIGGER_HASH}"
REQUEST = b"\x00\x01\x00\x00\x00"  # CDR of an empty Trigger request


class Counter(NodeLogic):
    """Serves ``~/reset``: counts calls; ``~/broken`` raises."""

    default_name = "counter"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        self.resets = 0
        port.create_service("~/reset", "std_srvs/srv/Trigger", self.reset)
        port.create_service("~/broken", "std_srvs/srv/Trigger", self.broken)

    def reset(self, _request: Any) -> Any:
        self.resets += 1
        return from_dict("std_srvs/srv/Trigger_Response",
                         {"success": True, "message": f"reset {self.resets}"})

    def broken(self, _request: Any) -> Any:
        raise ValueError("deliberately broken")


@pytest.fixture
def server(router: Any) -> Iterator[Any]:
    """A zenoh context serving :class:`Counter`, spinning in a thread."""
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    ctx = ZenohContext()
    node = Counter(ctx.create_port("counter"))
    spinner = threading.Thread(target=ctx.spin, daemon=True)
    spinner.start()
    yield node
    ctx.request_stop()
    spinner.join(5.0)
    ctx.close()


def _tokens(session: Any, kind: str) -> list[str]:
    return [str(r.ok.key_expr) for r in session.liveliness().get("@ros2_lv/0/**", timeout=1.0)
            if r.ok is not None and f"/{kind}/" in str(r.ok.key_expr)]


def test_a_plain_zenoh_session_calls_a_service_as_rmw_zenoh_does(server: Counter) -> None:
    from tdcm_ros.runtime.zenoh_runtime import open_session

    session = open_session()
    try:
        token = eventually(lambda: [t for t in _tokens(session, "SS") if "%counter%reset" in t],
                           10.0, "the SS token of /counter/reset")[0]
        assert token.endswith(f"/SS/%/%/counter/%counter%reset/std_srvs::srv::dds_::Trigger_/"
                              f"{TRIGGER_HASH}/::,10:,:,:,,")
        gid = bytes(range(16))
        before_ns = time.time_ns()
        replies = list(session.get(KEY, payload=REQUEST, timeout=5.0,
                                   attachment=encode_attachment(7, time.time_ns(), gid)))
        assert len(replies) == 1 and replies[0].ok is not None
        reply = replies[0].ok
        assert str(reply.key_expr) == KEY
        answer = deserialize(reply.payload.to_bytes(), "std_srvs/srv/Trigger_Response")
        assert (answer.success, answer.message) == (True, "reset 1")
        attachment = decode_attachment(reply.attachment.to_bytes())
        assert (attachment.sequence_number, attachment.gid) == (7, gid)
        # the server (a thread here, one clock) stamps its reply between the call and now
        assert before_ns <= attachment.source_timestamp_ns <= time.time_ns()
        bare = list(session.get(KEY, payload=REQUEST, timeout=5.0))  # no attachment: refused
        assert bare[0].err is not None and "attachment" in bare[0].err.payload.to_string()
        assert server.resets == 1
    finally:
        session.close()


def test_the_runtime_client_calls_with_a_client_token(server: Counter) -> None:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    client = ZenohContext()
    try:
        request = from_dict("std_srvs/srv/Trigger_Request", {})
        first = client.call_service("/counter/reset", "std_srvs/srv/Trigger", request)
        second = client.call_service("/counter/reset", "std_srvs/srv/Trigger")
        assert (first.message, second.message) == ("reset 1", "reset 2")
        eventually(lambda: any("%counter%reset" in t for t in _tokens(client.session, "SC")),
                   10.0, "the SC token of /counter/reset")
        assert ("/counter/reset", "std_srvs/srv/Trigger") in client.service_names(0.5)
        with pytest.raises(RuntimePortError, match="the handler failed"):
            client.call_service("/counter/broken", "std_srvs/srv/Trigger")
        assert client.call_service("/counter/reset", "std_srvs/srv/Trigger").message == "reset 3"
        with pytest.raises(RuntimePortError, match=r"/counter/absent .* has no server after 0.5 s"):
            client.call_service("/counter/absent", "std_srvs/srv/Trigger", timeout=0.5)
    finally:
        client.close()


def test_request_bytes_are_the_cdr_of_the_request() -> None:
    assert serialize(from_dict("std_srvs/srv/Trigger_Request", {})) == REQUEST
