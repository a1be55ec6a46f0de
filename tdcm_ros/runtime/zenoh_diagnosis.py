"""Why a zenoh session reached no router, told in one sentence: a file the config names is
missing, the router's TLS certificate fails verification (another name, another CA), nothing
answers at the endpoint, or the router refused the user and password.

:func:`require_router` waits for a session's router and raises :class:`RuntimePortError` with
that sentence. Every session configured by a file (``TDCM_ZENOH_CONFIG``) calls it, where a
misconfiguration would otherwise run a closed graph silently, and so do the graph tools
(``tdcm topic``, ``param``, ``service``), which would otherwise print nothing and exit 0.
"""

from __future__ import annotations

import json
import socket
import ssl
import time

import zenoh

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.errors import RuntimePortError

#: Protocols whose listeners a TCP connect reaches (TLS runs over TCP).
TCP_PROTOCOLS = ("tcp", "tls")
#: Config keys that name files a session reads.
FILE_KEYS = (
    "transport/link/tls/root_ca_certificate",
    "transport/link/tls/connect_certificate",
    "transport/link/tls/connect_private_key",
    "transport/link/tls/listen_certificate",
    "transport/link/tls/listen_private_key",
    "transport/auth/usrpwd/dictionary_file",
)
#: s a session may take to reach its router before :func:`require_router` explains why not.
ROUTER_WAIT_S = 5.0


def _value(config: zenoh.Config, key: str) -> object:
    return json.loads(config.get_json(key))


def missing_files(config: zenoh.Config) -> list[str]:
    """``key = path`` of every file the config names that cannot be read."""
    missing = []
    for key in FILE_KEYS:
        path = _value(config, key)
        if isinstance(path, str) and path:
            try:
                with open(path, "rb"):
                    pass
            except OSError as error:
                missing.append(f"{key} = {path} ({error.strerror})")
    return missing


def tcp_address(locator: str) -> tuple[str, int]:
    """``(host, port)`` of a ``tcp/host:port`` or ``tls/host:port`` locator (a ``?`` or ``#``
    suffix ignored); ``InputError`` for any other."""
    proto, _, address = locator.partition("/")
    host, _, port = address.split("?")[0].split("#")[0].rpartition(":")
    if proto not in TCP_PROTOCOLS or not host or not port.isdigit():
        allowed = " or ".join(f"{p}/<host>:<port>" for p in TCP_PROTOCOLS)
        raise InputError(f"endpoint {locator!r} is not {allowed}", parameter="endpoint",
                         value=locator, allowed=allowed)
    return host.strip("[]"), int(port)


def _connect_error(locator: str, timeout: float) -> OSError | None:
    """Why a TCP connection to a ``tcp/`` or ``tls/`` locator fails (None if it opens)."""
    try:
        with socket.create_connection(tcp_address(locator), timeout=timeout):
            return None
    except OSError as error:
        return error


def is_listening(locator: str, timeout: float = 0.5) -> bool:
    """True if something accepts TCP connections at the locator."""
    return _connect_error(locator, timeout) is None


def nothing_listens(endpoint: str, timeout: float = 1.0) -> str | None:
    """Why a TCP connection to a ``tcp/`` or ``tls/`` endpoint fails (None if it opens, or
    for another protocol)."""
    if endpoint.partition("/")[0] not in TCP_PROTOCOLS:
        return None
    error = _connect_error(endpoint, timeout)
    return None if error is None else f"nothing answers at {endpoint}: {error.strerror or error}"


def tls_refusal(config: zenoh.Config, endpoint: str, timeout: float = 3.0) -> str | None:
    """Why a TLS handshake with the router at a ``tls/host:port`` endpoint fails, as zenoh would
    check it (the endpoint's host against the certificate's names, the configured root CA);
    None if it succeeds or the endpoint is not TLS."""
    if not endpoint.startswith("tls/"):
        return None
    host, port = tcp_address(endpoint)
    ca = _value(config, "transport/link/tls/root_ca_certificate")
    context = ssl.create_default_context(cafile=ca if isinstance(ca, str) and ca else None)
    certificate = _value(config, "transport/link/tls/connect_certificate")
    key = _value(config, "transport/link/tls/connect_private_key")
    if isinstance(certificate, str) and certificate and isinstance(key, str) and key:
        context.load_cert_chain(certificate, key)
    try:
        with socket.create_connection((host, port), timeout=timeout) as raw, \
                context.wrap_socket(raw, server_hostname=host):
            return None
    except ssl.SSLCertVerificationError as error:
        return (f"the router's TLS certificate at {endpoint} fails verification: "
                f"{error.verify_message} (a certificate for another name than {host!r}, or "
                f"one not signed by the CA in root_ca_certificate = {ca})")
    except ssl.SSLError as error:
        return f"the TLS handshake with the router at {endpoint} failed: {error.reason}"
    except OSError as error:
        return f"nothing answers at {endpoint}: {error.strerror or error}"


def why_no_router(config: zenoh.Config, endpoint: str) -> str:
    """The most likely reason a session with ``config`` reached no router at ``endpoint``."""
    if missing := missing_files(config):
        return f"the zenoh config names files that cannot be read: {'; '.join(missing)}"
    if (refusal := nothing_listens(endpoint) or tls_refusal(config, endpoint)) is not None:
        return refusal
    user = _value(config, "transport/auth/usrpwd/user")
    if isinstance(user, str) and user:
        return (f"the router at {endpoint} refused the session: user {user!r} with this "
                f"password is not in its users file (transport/auth/usrpwd), or the router "
                f"does not authenticate the same way")
    return f"no zenoh router was reached at {endpoint}"


def _connected(session: zenoh.Session) -> bool:
    return any(True for _ in session.info.routers_zid())


def require_router(session: zenoh.Session, config: zenoh.Config, endpoint: str,
                   timeout: float = ROUTER_WAIT_S) -> None:
    """Wait up to ``timeout`` s for ``session`` to reach a router; ``RuntimePortError`` naming
    the cause (:func:`why_no_router`) if it does not, at once if nothing listens there."""
    if not _connected(session) and (refusal := nothing_listens(endpoint)) is not None:
        raise RuntimePortError(f"no zenoh router: {refusal}")
    deadline = time.monotonic() + timeout
    while not _connected(session):
        if time.monotonic() > deadline:
            raise RuntimePortError(f"no zenoh router after {timeout:g} s: "
                                   f"{why_no_router(config, endpoint)}")
        time.sleep(0.05)
