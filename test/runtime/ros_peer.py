"""A plain zenoh session acting as a ROS 2 Jazzy peer with rmw_zenoh_cpp (0.2.4 and later).

Written from rmw_zenoh_cpp's sources (ros2-gbp/rmw_zenoh-release, ``release/jazzy/rmw_zenoh_cpp/
0.2.9-1``: ``src/detail/liveliness_utils.cpp``, ``qos.cpp``, ``attachment_helpers.cpp``,
``rmw_publisher_data.cpp``, ``rmw_service_data.cpp``, ``rmw_client_data.cpp``) and NOT from the
package's ``tdcm_ros.runtime.wire``: the conformance tests compare what the package's nodes do
with what this independent reading of rmw_zenoh says. CDR and message hashes come from rosbags'
Jazzy typestore; service hashes are pinned from ROS 2 Jazzy's type-description JSON.

API (other conformance tests build on it; keep it small)::

    peer = RosPeer("tcp/127.0.0.1:7447", domain=0)   # also declares its own NN token
    peer.tokens()                       # [Token] of the domain (liveliness query)
    sub = peer.subscribe("/tip_pose", "geometry_msgs/msg/PoseStamped")   # Received samples
    peer.publish("/tension", "geometry_msgs/msg/WrenchStamped", msg)      # MP token + attachment
    reply = peer.call("/n/clear_faults", "std_srvs/srv/Trigger", request)  # Reply
    peer.message(type_name, **fields)   # a rosbags message of the Jazzy store (services included)
    peer.close()

Formats, as rmw_zenoh writes them:

- token ``@ros2_lv/<domain>/<zid>/<nid>/<id>/<NN|MP|MS|SS|SC>/<enclave>/<ns>/<node>`` and, for
  endpoints, ``/<topic>/<type>/<type hash>/<qos>``; every ``/`` inside a chunk becomes ``%``
  (``Entity::Entity``, ``mangle_name``);
- data and service key ``<domain>/<name without outer slashes>/<type>/<type hash>``
  (``TopicInfo``); type ``pkg::msg::dds_::Name_``, for a service the response type's name with
  ``Response_`` cut: ``pkg::srv::dds_::Name_``;
- QoS chunk (``qos_to_keyexpr``): ``rel:dur:hist,depth:dl_s,dl_ns:ls_s,ls_ns:liv,lease_s,lease_ns``
  with each value left empty when it equals rmw_zenoh's default (reliable 1, volatile 2,
  keep-last 1, depth 42, infinite durations, automatic liveliness 1);
- GID (``Entity::Entity``): XXH3-128 of the token; ``low64`` then ``high64`` copied from memory
  (little endian on every supported host);
- attachment (``AttachmentData::serialize_to_zbytes``, zenoh-ext serializer): int64 sequence
  number, int64 source timestamp (ns), ``std::array<uint8_t, 16>`` GID as a sequence (LEB128
  length 16, then the bytes); integers little endian: 33 bytes;
- a client queries the service key (target ALL_COMPLETE, no consolidation) with the CDR request
  and its attachment (sequence numbers from 1); the server replies on its key with the CDR
  response and an attachment holding the request's sequence number and the client's GID.
"""

from __future__ import annotations

import json
import struct
import threading
import time
from dataclasses import dataclass
from typing import Any

import xxhash
import zenoh
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from test.support.waiting import eventually

ADMIN_SPACE = "@ros2_lv"
#: rmw_zenoh's QoS defaults (``qos.cpp``) as ``rmw/types.h`` enum values.
DEFAULT_RELIABILITY, DEFAULT_DURABILITY, DEFAULT_DEPTH = 1, 2, 42  # history: keep-last (1) always
RELIABILITY = {"reliable": 1, "best_effort": 2}
DURABILITY = {"transient_local": 1, "volatile": 2}
#: ``rmw_qos_profile_services_default`` (reliable, volatile, keep last 10).
SERVICE_QOS = ("reliable", "volatile", 10)
_EMPTY = "uint8 structure_needs_at_least_one_member"
#: Service types the peer can call: request and response ``.msg`` text (an empty half holds
#: rosidl's placeholder) and the RIHS01 hash from ROS 2 Jazzy's type-description JSON
#: (``share/<pkg>/srv/<Name>.json``, ``type_hashes``; checked by test_conformance_vectors.py).
SERVICES: dict[str, tuple[str, str, str]] = {
    "std_srvs/srv/Trigger": (
        _EMPTY, "bool success\nstring message",
        "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"),
    "rcl_interfaces/srv/DescribeParameters": (
        "string[] names", "rcl_interfaces/ParameterDescriptor[] descriptors",
        "RIHS01_845b484d71eb0673dae682f2e3ba3c4851a65a3dcfb97bddd82c5b57e91e4cff"),
    "rcl_interfaces/srv/GetParameters": (
        "string[] names", "rcl_interfaces/ParameterValue[] values",
        "RIHS01_bf9803d5c74cf989a5de3e0c2e99444599a627c7ff75f97b8c05b01003675cbc"),
    "rcl_interfaces/srv/GetParameterTypes": (
        "string[] names", "uint8[] types",
        "RIHS01_da199c878688b3e530bdfe3ca8f74cb9fa0c303101e980a9e8f260e25e1c80ca"),
    "rcl_interfaces/srv/ListParameters": (
        "uint64 DEPTH_RECURSIVE=0\nstring[] prefixes\nuint64 depth",
        "rcl_interfaces/ListParametersResult result",
        "RIHS01_3e6062bfbb27bfb8730d4cef2558221f51a11646d78e7bb30a1e83afac3aad9d"),
    "rcl_interfaces/srv/SetParameters": (
        "rcl_interfaces/Parameter[] parameters", "rcl_interfaces/SetParametersResult[] results",
        "RIHS01_56eed9a67e169f9cb6c1f987bc88f868c14a8fc9f743a263bc734c154015d7e0"),
    "rcl_interfaces/srv/SetParametersAtomically": (
        "rcl_interfaces/Parameter[] parameters", "rcl_interfaces/SetParametersResult result",
        "RIHS01_0e192ef259c07fc3c07a13191d27002222e65e00ccec653ca05e856f79285fcd"),
    "lifecycle_msgs/srv/ChangeState": (
        "lifecycle_msgs/Transition transition", "bool success",
        "RIHS01_356fe34f0475a43acf54542013af4167b0e729f77ea22ffb045c6ad8e20668e5"),
    "lifecycle_msgs/srv/GetState": (
        _EMPTY, "lifecycle_msgs/State current_state",
        "RIHS01_800a0a5aae599782b02932de0caf563f6dc4e7e94b794eadde075ba2cbef9795"),
    "lifecycle_msgs/srv/GetAvailableStates": (
        _EMPTY, "lifecycle_msgs/State[] available_states",
        "RIHS01_00a07d79d2207d71e81a8cbc1880e5d924cc16d4688ea8e8e06e443dc8f8aa1d"),
    "lifecycle_msgs/srv/GetAvailableTransitions": (
        _EMPTY, "lifecycle_msgs/TransitionDescription[] available_transitions",
        "RIHS01_59b7ecefce0982a8a844b9f2c4f14764c1c4543cc55e72924e2aa4adad83e9bc"),
}


def typestore() -> Any:
    """rosbags' Jazzy store plus the request and response types of :data:`SERVICES`."""
    store = get_typestore(Stores.ROS2_JAZZY)
    for name, (request, response, _) in SERVICES.items():
        package, _, short = name.partition("/srv/")
        for half, text in (("Request", request), ("Response", response)):
            parsed = get_types_from_msg(text, f"{package}/msg/{short}_{half}")
            store.register({f"{name}_{half}": parsed[f"{package}/msg/{short}_{half}"]})
    return store


STORE = typestore()


def mangle(name: str) -> str:
    return name.replace("/", "%")


def dds_type(type_name: str) -> str:
    """``pkg/msg/Name`` -> ``pkg::msg::dds_::Name_`` (and ``pkg/srv/Name`` likewise)."""
    package, kind, name = type_name.split("/")
    return f"{package}::{kind}::dds_::{name}_"


def type_hash(type_name: str) -> str:
    """RIHS01 of a message (rosbags' Jazzy store) or a service (:data:`SERVICES`)."""
    return SERVICES[type_name][2] if "/srv/" in type_name else str(STORE.hash_rihs01(type_name))


def qos_chunk(reliability: str = "reliable", durability: str = "volatile", depth: int = 10) -> str:
    """The QoS chunk of a keep-last endpoint with infinite deadline, lifespan and lease."""
    rel = RELIABILITY[reliability]
    dur = DURABILITY[durability]
    return (f"{'' if rel == DEFAULT_RELIABILITY else rel}:"
            f"{'' if dur == DEFAULT_DURABILITY else dur}:"
            f",{'' if depth == DEFAULT_DEPTH else depth}:,:,:,,")


def key_expr(domain: int, name: str, type_name: str) -> str:
    """Data key of a topic, or query key of a service."""
    return f"{domain}/{name.strip('/')}/{dds_type(type_name)}/{type_hash(type_name)}"


def gid(token: str) -> bytes:
    """The 16-byte GID rmw_zenoh derives from a liveliness token."""
    digest = xxhash.xxh3_128(token.encode()).digest()  # canonical: high64 then low64, big endian
    high, low = struct.unpack(">QQ", digest)
    return struct.pack("<QQ", low, high)


def attachment(sequence_number: int, timestamp_ns: int, source_gid: bytes) -> bytes:
    """rmw_zenoh's 33-byte attachment."""
    assert len(source_gid) == 16
    return struct.pack("<qq", sequence_number, timestamp_ns) + bytes([16]) + source_gid


@dataclass(frozen=True)
class Attachment:
    sequence_number: int
    timestamp_ns: int
    gid: bytes


def parse_attachment(data: bytes) -> Attachment:
    """Decode rmw_zenoh's attachment (raises ``ValueError`` on any other layout)."""
    if len(data) != 33 or data[16] != 16:
        raise ValueError(f"not rmw_zenoh's attachment: {data.hex()}")
    sequence_number, timestamp_ns = struct.unpack_from("<qq", data)
    return Attachment(sequence_number, timestamp_ns, bytes(data[17:]))


@dataclass(frozen=True)
class Token:
    """A liveliness token split into its chunks (names demangled)."""

    key: str
    domain: int
    zid: str
    nid: str
    id: str
    kind: str
    enclave: str
    namespace: str
    node: str
    topic: str = ""
    type: str = ""
    type_hash: str = ""
    qos: str = ""


def parse_token(key: str) -> Token:
    """Split a token as ``Entity::make(keyexpr)`` does (raises ``ValueError`` when malformed)."""
    parts = key.split("/")
    if parts[0] != ADMIN_SPACE or len(parts) not in (9, 13) or "" in parts:
        raise ValueError(f"not an rmw_zenoh liveliness token: {key}")
    if (parts[5] == "NN") != (len(parts) == 9) or parts[5] not in ("NN", "MP", "MS", "SS", "SC"):
        raise ValueError(f"entity kind {parts[5]} does not fit {len(parts)} chunks: {key}")
    names = [p.replace("%", "/") for p in parts[6:]]
    return Token(key, int(parts[1]), parts[2], parts[3], parts[4], parts[5], *names)


@dataclass(frozen=True)
class Received:
    """A sample: its key, CDR payload, decoded message and attachment (None when absent)."""

    key: str
    payload: bytes
    message: Any
    attachment: Attachment | None


@dataclass(frozen=True)
class Reply:
    """A service reply: key, CDR payload, decoded response, attachment."""

    key: str
    payload: bytes
    response: Any
    attachment: Attachment


class Subscription:
    """Samples of one topic, in arrival order (``samples``; ``wait`` for the first n)."""

    def __init__(self, type_name: str) -> None:
        self.type_name = type_name
        self.samples: list[Received] = []
        self._lock = threading.Lock()

    def on_sample(self, sample: zenoh.Sample) -> None:
        payload = bytes(sample.payload.to_bytes())
        raw = sample.attachment.to_bytes() if sample.attachment is not None else None
        received = Received(str(sample.key_expr), payload,
                            STORE.deserialize_cdr(payload, self.type_name),
                            parse_attachment(bytes(raw)) if raw is not None else None)
        with self._lock:
            self.samples.append(received)

    def wait(self, count: int = 1, timeout: float = 20.0) -> list[Received]:
        """The samples so far, once there are ``count`` (:func:`eventually`: fails after
        ``timeout`` s, scaled)."""
        eventually(lambda: len(self.samples) >= count, timeout,
                   f"{count} {self.type_name} samples",
                   detail=lambda: f"{len(self.samples)} received")
        with self._lock:
            return list(self.samples)


class RosPeer:
    """One zenoh session on ``endpoint`` (client of a router, scouting off) acting as the ROS
    node ``/ros_peer`` on ``domain``."""

    NAME = "ros_peer"

    def __init__(self, endpoint: str, domain: int = 0) -> None:
        config = zenoh.Config.from_json5(json.dumps({
            "mode": "client", "connect": {"endpoints": [endpoint]},
            "scouting": {"multicast": {"enabled": False}}}))
        self.session = zenoh.open(config)
        self.domain = domain
        self.zid = str(self.session.zid())
        self._ids = iter(range(1, 1 << 30))
        self._declared: list[Any] = []
        self._publishers: dict[str, tuple[Any, bytes, list[int]]] = {}
        self._clients: dict[str, tuple[bytes, list[int]]] = {}
        self.node_token = self._prefix(0, "NN")
        self._declared.append(self.session.liveliness().declare_token(self.node_token))

    def _prefix(self, entity_id: int, kind: str) -> str:
        return f"{ADMIN_SPACE}/{self.domain}/{self.zid}/0/{entity_id}/{kind}/%/%/{self.NAME}"

    def _endpoint_token(self, kind: str, name: str, type_name: str, qos: str) -> str:
        token = (f"{self._prefix(next(self._ids), kind)}/{mangle(name)}/{dds_type(type_name)}/"
                 f"{type_hash(type_name)}/{qos}")
        self._declared.append(self.session.liveliness().declare_token(token))
        return token

    def message(self, type_name: str, **fields: Any) -> Any:
        """A rosbags message of ``type_name`` (``pkg/msg/Name`` or ``pkg/srv/Name_Request``)."""
        return STORE.types[type_name](**fields)

    def tokens(self, timeout: float = 1.0) -> list[Token]:
        """Every liveliness token of the domain (``Entity::make`` parses each)."""
        replies = self.session.liveliness().get(f"{ADMIN_SPACE}/{self.domain}/**", timeout=timeout)
        return [parse_token(str(r.ok.key_expr)) for r in replies if r.ok is not None]

    def subscribe(self, topic: str, type_name: str) -> Subscription:
        """Subscribe (volatile, with an ``MS`` token) to ``topic`` of ``type_name``."""
        subscription = Subscription(type_name)
        self._endpoint_token("MS", topic, type_name, qos_chunk())
        self._declared.append(self.session.declare_subscriber(
            key_expr(self.domain, topic, type_name), subscription.on_sample))
        return subscription

    def publish(self, topic: str, type_name: str, message: Any) -> bytes:
        """Publish ``message`` (reliable, volatile, depth 10, with an ``MP`` token) with
        rmw_zenoh's attachment; the CDR bytes sent."""
        if topic not in self._publishers:
            token = self._endpoint_token("MP", topic, type_name, qos_chunk())
            publisher = self.session.declare_publisher(key_expr(self.domain, topic, type_name))
            self._declared.append(publisher)
            self._publishers[topic] = (publisher, gid(token), [0])
        publisher, source_gid, sequence = self._publishers[topic]
        sequence[0] += 1
        payload = bytes(STORE.serialize_cdr(message, type_name))
        publisher.put(payload, attachment=attachment(sequence[0], time.time_ns(), source_gid))
        return payload

    def client_gid(self, service: str) -> bytes:
        """The GID of this peer's client of ``service`` (after the first :meth:`call`)."""
        return self._clients[service][0]

    def call(self, service: str, srv_type: str, request: Any, timeout: float = 10.0) -> Reply:
        """Call ``service`` of ``srv_type`` as an rmw_zenoh client (``SC`` token, sequence
        numbers from 1); the one reply. Raises ``RuntimeError`` with an error reply's text,
        ``TimeoutError`` without a reply."""
        if service not in self._clients:
            token = self._endpoint_token("SC", service, srv_type, qos_chunk(*SERVICE_QOS))
            self._clients[service] = (gid(token), [0])
        source_gid, sequence = self._clients[service]
        sequence[0] += 1
        payload = bytes(STORE.serialize_cdr(request, f"{srv_type}_Request"))
        replies = self.session.get(
            key_expr(self.domain, service, srv_type), payload=payload,
            attachment=attachment(sequence[0], time.time_ns(), source_gid),
            target=zenoh.QueryTarget.ALL_COMPLETE, consolidation=zenoh.ConsolidationMode.NONE,
            timeout=timeout)
        for reply in replies:
            if reply.ok is None:
                raise RuntimeError(reply.err.payload.to_string() if reply.err else "error reply")
            data = bytes(reply.ok.payload.to_bytes())
            raw = reply.ok.attachment.to_bytes() if reply.ok.attachment is not None else b""
            return Reply(str(reply.ok.key_expr), data,
                         STORE.deserialize_cdr(data, f"{srv_type}_Response"),
                         parse_attachment(bytes(raw)))
        raise TimeoutError(f"no reply from {service} within {timeout} s")

    def close(self) -> None:
        for entity in reversed(self._declared):
            entity.undeclare()
        self.session.close()
