"""rmw_zenoh (Jazzy) wire conventions as pure functions: keys, liveliness tokens, attachment.

Sources (ros2/rmw_zenoh, ``docs/design.md`` and ``rmw_zenoh_cpp/src/detail/``):

- data key ``<domain>/<fully qualified name without leading '/'>/<pkg::msg::dds_::Name_>/<RIHS01>``
  (``liveliness_utils.cpp`` ``TopicInfo``, ``strip_slashes``; ``type_support_common.cpp``);
- tokens ``@ros2_lv/<domain>/<zid>/<nid>/<id>/<NN|MP|MS|SS|SC>/<enclave>/<ns>/<node>`` plus, for
  endpoints, ``/<topic>/<type>/<hash>/<qos>``; names mangled ``/`` -> ``%``;
- QoS ``<rel>:<dur>:<hist>,<depth>:<deadline s>,<ns>:<lifespan s>,<ns>:<liveliness>,<s>,<ns>``,
  each component empty when equal to rmw_zenoh's default (``qos.cpp``: reliable, volatile,
  keep-last, depth 42, infinite durations, automatic liveliness); values are ``rmw/types.h`` enums;
- services (``rmw_service_data.cpp``, ``rmw_client_data.cpp``): the server declares a queryable
  (complete) on the service's key, whose type chunk is ``pkg::srv::dds_::Name_`` and hash the
  service type's RIHS01, and an ``SS`` token; a client queries that key with the CDR request and
  an attachment (its sequence number, time, GID); the reply carries the CDR response and an
  attachment with the request's sequence number and the client's GID;
- attachment (since Jazzy 0.2.4, rmw_zenoh#605): zenoh-ext serialisation of
  ``(int64 sequence_number, int64 source_timestamp_ns, uint8[16] gid)`` = 8 + 8 + LEB128 length
  (``0x10``) + 16 bytes, integers little endian.

The GID (publisher and attachment) is rmw_zenoh's: XXH3-128 of the entity's whole liveliness token,
its low 64 bits then its high 64 bits, each little endian (``liveliness_utils.cpp`` ``Entity``,
``simplified_xxhash3.cpp``).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import xxhash

from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.port import QoS

ADMIN_SPACE = "@ros2_lv"
NODE, PUBLISHER, SUBSCRIPTION, SERVICE, CLIENT = "NN", "MP", "MS", "SS", "SC"
RMW_ZENOH_DEFAULT_DEPTH = 42
_RELIABILITY = {"reliable": 1, "best_effort": 2}
_DURABILITY = {"transient_local": 1, "volatile": 2}
_DURABILITY_BY_CODE = {str(code): name for name, code in _DURABILITY.items()}
_ATTACHMENT = struct.Struct("<qqB16s")
#: QoS of service servers and clients (``rmw_qos_profile_services_default``: reliable,
#: volatile, keep-last 10), as their tokens carry it.
SERVICE_QOS = QoS(depth=10)
GID_SIZE = 16


def dds_type_name(type_name: str) -> str:
    """``pkg/msg/Name`` -> ``pkg::msg::dds_::Name_`` (the type chunk of keys and tokens)."""
    parts = type_name.split("/")
    if len(parts) != 3:
        raise RuntimePortError(f"type name {type_name!r} is not of the form pkg/msg/Name")
    return f"{parts[0]}::{parts[1]}::dds_::{parts[2]}_"


def ros_type_name(dds_name: str) -> str:
    """``pkg::msg::dds_::Name_`` -> ``pkg/msg/Name``."""
    parts = dds_name.split("::")
    if len(parts) != 4 or parts[2] != "dds_" or not parts[3].endswith("_"):
        raise RuntimePortError(f"{dds_name!r} is not an rmw_zenoh type chunk pkg::msg::dds_::Name_")
    return f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"


def topic_key(domain_id: int, topic: str, type_name: str, type_hash: str) -> str:
    """Data key expression of a fully qualified topic."""
    return f"{domain_id}/{topic.strip('/')}/{dds_type_name(type_name)}/{type_hash}"


def mangle(name: str) -> str:
    """Replace every ``/`` by ``%`` (token chunks cannot hold ``/``)."""
    return name.replace("/", "%")


def demangle(name: str) -> str:
    """Inverse of :func:`mangle`."""
    return name.replace("%", "/")


def qos_chunk(qos: QoS) -> str:
    """The QoS chunk of an endpoint token (history keep-last, infinite durations)."""
    rel = "" if qos.reliability == "reliable" else str(_RELIABILITY[qos.reliability])
    dur = "" if qos.durability == "volatile" else str(_DURABILITY[qos.durability])
    depth = "" if qos.depth == RMW_ZENOH_DEFAULT_DEPTH else str(qos.depth)
    return f"{rel}:{dur}:,{depth}:,:,:,,"


def durability_of(chunk: str) -> str:
    """The durability an endpoint token's QoS chunk (:func:`qos_chunk`) declares:
    ``transient_local`` or ``volatile`` (rmw_zenoh's default where the field is empty)."""
    fields = chunk.split(":")
    return _DURABILITY_BY_CODE.get(fields[1] if len(fields) > 1 else "", "volatile")


@dataclass(frozen=True)
class NodeIdentity:
    """Where a node lives: domain, zenoh session id, node id, enclave, namespace and name."""

    domain_id: int
    zid: str
    node_id: int
    namespace: str
    name: str
    enclave: str = "/"

    def prefix(self, entity_id: int, kind: str) -> str:
        """Token chunks up to and including the node name."""
        return (f"{ADMIN_SPACE}/{self.domain_id}/{self.zid}/{self.node_id}/{entity_id}/{kind}/"
                f"{mangle(self.enclave)}/{mangle(self.namespace)}/{mangle(self.name)}")


def node_token(node: NodeIdentity) -> str:
    """Liveliness token of a node (its entity id repeats the node id)."""
    return node.prefix(node.node_id, NODE)


def endpoint_token(node: NodeIdentity, entity_id: int, kind: str, topic: str, type_name: str,
                   type_hash: str, qos: QoS) -> str:
    """Liveliness token of a publisher (``MP``), subscription (``MS``), service server (``SS``)
    or client (``SC``); a service's ``type_name`` is ``pkg/srv/Name`` (its chunk
    ``pkg::srv::dds_::Name_``, the response type's DDS name without ``Response_``)."""
    return (f"{node.prefix(entity_id, kind)}/{mangle(topic)}/{dds_type_name(type_name)}/"
            f"{type_hash}/{qos_chunk(qos)}")


@dataclass(frozen=True)
class TokenInfo:
    """A parsed liveliness token; topic fields are empty for nodes."""

    domain_id: int
    zid: str
    kind: str
    namespace: str
    node_name: str
    topic: str = ""
    type_name: str = ""
    type_hash: str = ""
    qos: str = ""

    @property
    def node_fqn(self) -> str:
        """``/ns/node`` of the owning node."""
        return f"{self.namespace.rstrip('/')}/{self.node_name}"


def parse_token(key: str) -> TokenInfo:
    """Parse an rmw_zenoh liveliness token; raises ``RuntimePortError`` when malformed."""
    parts = key.split("/")
    if len(parts) < 9 or parts[0] != ADMIN_SPACE or parts[5] not in (
            NODE, PUBLISHER, SUBSCRIPTION, SERVICE, CLIENT):
        raise RuntimePortError(f"not an rmw_zenoh liveliness token: {key!r}")
    info = TokenInfo(int(parts[1]), parts[2], parts[5], demangle(parts[7]), demangle(parts[8]))
    if parts[5] == NODE:
        return info
    if len(parts) < 13:
        raise RuntimePortError(f"endpoint token without topic chunks: {key!r}")
    type_name = ros_type_name(parts[10]) if "::dds_::" in parts[10] else parts[10]
    return TokenInfo(info.domain_id, info.zid, info.kind, info.namespace, info.node_name,
                     demangle(parts[9]), type_name, parts[11], parts[12])


def gid_of(token: str) -> bytes:
    """16-byte GID of an entity as rmw_zenoh computes it from its liveliness token: XXH3-128,
    low 64 bits first, little endian (a little-endian 128-bit integer)."""
    return xxhash.xxh3_128_intdigest(token.encode()).to_bytes(GID_SIZE, "little")


def encode_attachment(sequence_number: int, source_timestamp_ns: int, gid: bytes) -> bytes:
    """rmw_zenoh attachment bytes (33 bytes)."""
    if len(gid) != GID_SIZE:
        raise RuntimePortError(f"GID has {len(gid)} bytes; expected {GID_SIZE}")
    return _ATTACHMENT.pack(sequence_number, source_timestamp_ns, GID_SIZE, gid)


@dataclass(frozen=True)
class Attachment:
    """Decoded attachment: sequence number, source timestamp (ns since epoch), GID."""

    sequence_number: int
    source_timestamp_ns: int
    gid: bytes


@dataclass(frozen=True)
class RawSample:
    """A received sample: fully qualified topic, type, CDR payload and decoded attachment."""

    topic: str
    type_name: str
    data: bytes
    attachment: Attachment | None


def decode_attachment(data: bytes) -> Attachment:
    """Decode an rmw_zenoh attachment; raises ``RuntimePortError`` on another layout."""
    if len(data) != _ATTACHMENT.size or data[16] != GID_SIZE:
        raise RuntimePortError(f"attachment of {len(data)} bytes is not rmw_zenoh's "
                               f"(int64, int64, 16-byte gid) layout")
    seq, stamp, _, gid = _ATTACHMENT.unpack(data)
    return Attachment(seq, stamp, gid)
