"""Zenoh session configs of the embedded runtime, and the check for exposed listeners.

Without a file: loopback defaults like rmw_zenoh's. With a file (``TDCM_ZENOH_CONFIG`` for every
session, ``TDCM_ZENOH_ROUTER_CONFIG`` first for the router): the file, with the role's keys set
on top: ``mode``; the router listens on the endpoint, a peer connects to it and, where the file
leaves ``listen/endpoints`` at zenoh's default (every interface), listens on loopback only. The
file brings TLS (``transport/link/tls``), user/password authentication (``transport/auth/usrpwd``)
and the access-control list (``access_control``); see ``doc/howto/several_hosts.md`` and
``config/zenoh/``.
"""

from __future__ import annotations

import ipaddress
import json
import logging
import os

import zenoh

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.errors import RuntimePortError

ROUTER_CONFIG_ENV = "TDCM_ZENOH_ROUTER_CONFIG"
MODES = ("peer", "router")
LOOPBACK_LISTEN = "tcp/127.0.0.1:0"
#: Protocols whose listeners other hosts can reach over IP.
NETWORK_PROTOCOLS = ("tcp", "tls", "udp", "quic", "ws")
#: Protocols that authenticate the connecting side with ``enable_mtls``.
MTLS_PROTOCOLS = ("tls", "quic")
DOCS_SECTION = 'doc/howto/several_hosts.md "Several hosts: TLS, authentication, access control"'

log = logging.getLogger("tdcm.zenoh")


def build(*, mode: str, endpoint: str, path: str | None) -> zenoh.Config:
    """The config of a ``mode`` session (``peer`` or ``router``) whose router is at ``endpoint``.

    ``path``: the shared config file (``TDCM_ZENOH_CONFIG``) or ``None``; a router takes the
    file named by ``TDCM_ZENOH_ROUTER_CONFIG`` first.
    """
    if mode not in MODES:
        raise InputError(f"mode = {mode!r} is not a session role; allowed: {', '.join(MODES)}",
                         parameter="mode", value=mode, allowed=", ".join(MODES))
    if mode == "router":
        path = os.environ.get(ROUTER_CONFIG_ENV) or path
    config = load(path) if path else default_config()
    return with_role(config, mode=mode, endpoint=endpoint, from_file=bool(path))


def default_config() -> zenoh.Config:
    """Loopback defaults like rmw_zenoh's: multicast scouting off (gossip on, zenoh's default),
    timestamping on (transient-local publishers need it)."""
    config = zenoh.Config()
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("timestamping/enabled",
                        json.dumps({"router": True, "peer": True, "client": True}))
    return config


def load(path: str) -> zenoh.Config:
    """The zenoh JSON5 config file at ``path``."""
    try:
        return zenoh.Config.from_file(path)
    except zenoh.ZError as error:
        raise RuntimePortError(f"cannot load zenoh config {path}: {error}") from error


def with_role(config: zenoh.Config, *, mode: str, endpoint: str, from_file: bool) -> zenoh.Config:
    """Set ``mode`` and the role's endpoints: a router listens on ``endpoint``; a peer connects to
    it and listens on loopback unless a file (``from_file``) chose its own listen endpoints."""
    config.insert_json5("mode", json.dumps(mode))
    if mode == "router":
        config.insert_json5("listen/endpoints", json.dumps([endpoint]))
        return config
    config.insert_json5("connect/endpoints", json.dumps([endpoint]))
    if not from_file or _listen_is_zenoh_default(config):
        config.insert_json5("listen/endpoints", json.dumps([LOOPBACK_LISTEN]))
    return config


def _listen_is_zenoh_default(config: zenoh.Config) -> bool:
    """True if ``listen/endpoints`` is zenoh's own default (every interface)."""
    return bool(config.get_json("listen/endpoints") == zenoh.Config().get_json("listen/endpoints"))


def listen_endpoints(config: zenoh.Config, mode: str) -> list[str]:
    """The endpoints a ``mode`` session with ``config`` listens on."""
    value = json.loads(config.get_json("listen/endpoints"))
    if isinstance(value, dict):
        value = value.get(mode) or []
    return [str(item) for item in value]


def is_loopback(endpoint: str) -> bool:
    """True if ``endpoint`` (``proto/host:port[?…][#…]``) only accepts connections from this host:
    a loopback address, ``localhost``, or a protocol that is not IP (unix sockets, serial)."""
    protocol, _, address = endpoint.partition("/")
    if protocol not in NETWORK_PROTOCOLS:
        return True
    host = address.split("?")[0].split("#")[0].rpartition(":")[0].strip("[]")
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False  # a host name other than localhost: possibly reachable


def authenticates(config: zenoh.Config, endpoint: str) -> bool:
    """True if a session with ``config`` makes whoever connects on ``endpoint`` authenticate:
    a user/password dictionary (``transport/auth/usrpwd/dictionary_file``), or mutual TLS
    (``transport/link/tls/enable_mtls``) on a tls/quic endpoint."""
    if json.loads(config.get_json("transport/auth/usrpwd/dictionary_file")):
        return True
    protocol = endpoint.partition("/")[0]
    return protocol in MTLS_PROTOCOLS and bool(
        json.loads(config.get_json("transport/link/tls/enable_mtls")))


def exposed_endpoints(config: zenoh.Config, mode: str) -> list[str]:
    """Endpoints a ``mode`` session with ``config`` listens on beyond loopback without
    authenticating who connects."""
    return [endpoint for endpoint in listen_endpoints(config, mode)
            if not is_loopback(endpoint) and not authenticates(config, endpoint)]


def warn_if_exposed(config: zenoh.Config, mode: str) -> list[str]:
    """Log one warning per endpoint of :func:`exposed_endpoints`; returns them."""
    exposed = exposed_endpoints(config, mode)
    for endpoint in exposed:
        log.warning("zenoh %s listens on %s beyond loopback without authentication (no "
                    "transport/auth/usrpwd dictionary_file, no TLS with enable_mtls): any host "
                    "that reaches it can command the nodes; see %s", mode, endpoint,
                    DOCS_SECTION)
    return exposed
