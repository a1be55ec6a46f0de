"""Conformance: an embedded node's parameters through rmw_zenoh's formats only, as ``ros2 param``
on an rmw_zenoh (Jazzy 0.2.4+) machine reaches them.

The peer is a plain zenoh session; nothing of the package encodes or decodes for it. It follows
rmw_zenoh's sources (``src/detail/liveliness_utils.cpp``, ``rmw_service_data.cpp``,
``rmw_client_data.cpp``, ``attachment_helpers.cpp`` of tag ``release/jazzy/rmw_zenoh_cpp/0.2.9-1``)
and rclpy's parameter services (``rclpy/parameter_service.py``, Jazzy): the service key
``<domain>/<node>/<service>/rcl_interfaces::srv::dds_::<Type>_/<RIHS01>`` with the RIHS01 hashes of
the installed Jazzy ``rcl_interfaces`` (2.0.3, ``share/rcl_interfaces/srv/<Type>.json``), a query
carrying the CDR request (written here by hand) and the 33-byte attachment (int64 sequence
number, int64 time, 0x10 and a 16-byte GID, little endian), a reply carrying the CDR response
(read here by hand) and an attachment echoing the sequence number and the GID; the ``SS`` token
with rclpy's parameter-service QoS (keep-last 1000); and ``/parameter_events``
(``rcl_interfaces/msg/ParameterEvent``) with the node's fully qualified name.
"""

from __future__ import annotations

import json
import os
import struct
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from test.support.waiting import eventually

zenoh = pytest.importorskip("zenoh", reason="eclipse-zenoh not installed")

TALKER = "tdcm_ros.nodes.talker:Talker"
#: ``type_hashes`` of Jazzy's ``share/rcl_interfaces/{srv,msg}/<Type>.json`` (rcl_interfaces 2.0.3).
HASHES = {
    "GetParameters": "RIHS01_bf9803d5c74cf989a5de3e0c2e99444599a627c7ff75f97b8c05b01003675cbc",
    "SetParameters": "RIHS01_56eed9a67e169f9cb6c1f987bc88f868c14a8fc9f743a263bc734c154015d7e0",
    "ListParameters": "RIHS01_3e6062bfbb27bfb8730d4cef2558221f51a11646d78e7bb30a1e83afac3aad9d",
    "ParameterEvent": "RIHS01_043e627780fcad87a22d225bc2a037361dba713fca6a6b9f4b869a5aa0393204",
}
DOUBLE, STRING = 3, 4  # rcl_interfaces/msg/ParameterType
HEADER = b"\x00\x01\x00\x00"  # CDR, little endian


class Writer:
    """Little-endian CDR after the 4-byte header; alignment counts from the body's start."""

    def __init__(self) -> None:
        self.body = bytearray()

    def align(self, size: int) -> None:
        self.body += b"\x00" * (-len(self.body) % size)

    def put(self, fmt: str, value: Any) -> None:
        size = struct.calcsize(fmt)
        self.align(size)
        self.body += struct.pack("<" + fmt, value)

    def string(self, text: str) -> None:
        data = text.encode() + b"\x00"
        self.put("I", len(data))
        self.body += data

    def double_value(self, value: float) -> None:
        """A ``ParameterValue`` of type double; every other field empty."""
        self.put("B", DOUBLE)
        self.put("?", False)
        self.put("q", 0)
        self.put("d", value)
        self.string("")
        for _ in range(5):  # byte, bool, integer, double and string arrays
            self.put("I", 0)

    def cdr(self) -> bytes:
        return HEADER + bytes(self.body)


class Reader:
    """The inverse of :class:`Writer`."""

    def __init__(self, data: bytes) -> None:
        assert data[:4] == HEADER, data[:4]
        self.body, self.at = data[4:], 0

    def get(self, fmt: str) -> Any:
        size = struct.calcsize(fmt)
        self.at += -self.at % size
        (value,) = struct.unpack_from("<" + fmt, self.body, self.at)
        self.at += size
        return value

    def string(self) -> str:
        size = self.get("I")
        text = self.body[self.at:self.at + size - 1].decode()
        self.at += size
        return text

    def sequence(self, item: Callable[[], Any]) -> list[Any]:
        return [item() for _ in range(self.get("I"))]

    def value(self) -> Any:
        """A ``ParameterValue``: the field its type names (scalars only here)."""
        kind, flag, integer, double, text = (self.get("B"), self.get("?"), self.get("q"),
                                             self.get("d"), self.string())
        arrays = (self.sequence(lambda: self.get("B")), self.sequence(lambda: self.get("?")),
                  self.sequence(lambda: self.get("q")), self.sequence(lambda: self.get("d")),
                  self.sequence(self.string))
        return {1: flag, 2: integer, 3: double, 4: text}.get(kind, arrays)

    def parameter(self) -> tuple[str, Any]:
        return self.string(), self.value()


def attachment(sequence: int, gid: bytes) -> bytes:
    return struct.pack("<qqB", sequence, time.time_ns(), 16) + gid


class RosPeer:
    """A plain zenoh session calling services and reading topics the way rmw_zenoh does."""

    def __init__(self, endpoint: str) -> None:
        config = zenoh.Config()
        config.insert_json5("mode", '"client"')
        config.insert_json5("connect/endpoints", json.dumps([endpoint]))
        config.insert_json5("scouting/multicast/enabled", "false")
        self.session = zenoh.open(config)
        self.gid = bytes(range(100, 116))
        self.sequence = 0

    def tokens(self) -> list[str]:
        return [str(r.ok.key_expr) for r in self.session.liveliness().get("@ros2_lv/0/**",
                                                                          timeout=2.0) if r.ok]

    def call(self, node: str, service: str, type_name: str, request: bytes) -> Reader:
        self.sequence += 1
        key = f"0/{node}/{service}/rcl_interfaces::srv::dds_::{type_name}_/{HASHES[type_name]}"
        replies = [r for r in self.session.get(key, payload=request, timeout=5.0,
                                               attachment=attachment(self.sequence, self.gid))]
        assert len(replies) == 1 and replies[0].ok is not None, (key, replies)
        echoed = replies[0].ok.attachment.to_bytes()
        assert len(echoed) == 33 and echoed[16] == 16, echoed
        assert struct.unpack_from("<q", echoed)[0] == self.sequence and echoed[17:] == self.gid
        return Reader(replies[0].ok.payload.to_bytes())

    def close(self) -> None:
        self.session.close()


def names_request(*names: str) -> bytes:
    writer = Writer()
    writer.put("I", len(names))
    for name in names:
        writer.string(name)
    return writer.cdr()


def set_request(name: str, value: float) -> bytes:
    writer = Writer()
    writer.put("I", 1)
    writer.string(name)
    writer.double_value(value)
    return writer.cdr()


def list_request() -> bytes:
    writer = Writer()
    writer.put("I", 0)  # no prefixes
    writer.put("Q", 0)  # DEPTH_RECURSIVE
    return writer.cdr()


def test_a_plain_zenoh_peer_lists_gets_and_sets_parameters_and_sees_the_event(
        zenoh_env: dict[str, str], router: Any, spawn: Any, tmp_path: Path) -> None:
    peer = RosPeer(os.environ["TDCM_ZENOH_ENDPOINT"])
    events: list[tuple[str, list[tuple[str, Any]]]] = []
    lock = threading.Lock()

    def on_event(sample: Any) -> None:
        reader = Reader(sample.payload.to_bytes())
        reader.get("i"), reader.get("I")  # stamp
        node = reader.string()
        reader.sequence(reader.parameter)  # new
        with lock:
            events.append((node, reader.sequence(reader.parameter)))

    subscriber = peer.session.declare_subscriber(
        f"0/parameter_events/rcl_interfaces::msg::dds_::ParameterEvent_/{HASHES['ParameterEvent']}",
        on_event)
    path = tmp_path / "talker.yaml"
    path.write_text("talker:\n  ros__parameters:\n    period: 0.5\n    prefix: conformance\n")
    spawn("tdcm_ros.runtime.run_node", TALKER, "--params", str(path))
    try:
        # every service this test calls: a server's token says its queryable is declared (the
        # port declares the queryable first, and both reach the router in order), one token
        # says nothing of the others (list_parameters once answered empty after get_parameters')
        servers = {f"/SS/%/%/talker/%talker%{service}/rcl_interfaces::srv::dds_::{kind}_/"
                   f"{HASHES[kind]}/::,1000:,:,:,," for service, kind in (
                       ("list_parameters", "ListParameters"), ("get_parameters", "GetParameters"),
                       ("set_parameters", "SetParameters"))}

        def missing() -> set[str]:
            tokens = peer.tokens()
            return {s for s in servers if not any(t.endswith(s) for t in tokens)}
        eventually(lambda: not missing(), 30.0,
                   "the talker's list_parameters, get_parameters and set_parameters server tokens",
                   detail=lambda: f"missing {sorted(missing())}")

        result = peer.call("talker", "list_parameters", "ListParameters", list_request())
        names = result.sequence(result.string)
        assert {"period", "prefix", "use_sim_time"} <= set(names), names

        got = peer.call("talker", "get_parameters", "GetParameters",
                        names_request("period", "prefix"))
        assert got.sequence(got.value) == [0.5, "conformance"]

        accepted = peer.call("talker", "set_parameters", "SetParameters",
                             set_request("period", 0.25))
        assert accepted.sequence(lambda: (accepted.get("?"), accepted.string())) == [(True, "")]

        refused = peer.call("talker", "set_parameters", "SetParameters",
                            set_request("period", -1.0))
        [(successful, reason)] = refused.sequence(lambda: (refused.get("?"), refused.string()))
        assert not successful and "period" in reason and "out of range" in reason, reason

        after = peer.call("talker", "get_parameters", "GetParameters", names_request("period"))
        assert after.sequence(after.value) == [0.25]

        undeclared = peer.call("talker", "get_parameters", "GetParameters",
                               names_request("period", "nope"))
        assert undeclared.sequence(undeclared.value) == []  # rclpy: none if one is undeclared

        def changed() -> bool:
            with lock:
                return ("/talker", [("period", 0.25)]) in events
        eventually(changed, 5.0, "the change on /parameter_events")
        with lock:
            assert not any(("period", -1.0) in params for _, params in events)
    finally:
        subscriber.undeclare()
        peer.close()
