"""``/rosout`` on the embedded runtime: a node's log records as ``rcl_interfaces/msg/Log``.

rclpy and rclcpp nodes publish every record of their logger on ``/rosout`` (rcl's
``logging_rosout.c``) with ``rmw_qos_profile_rosout_default``: reliable, transient local, keep
last 1000, lifespan 10 s. :class:`RosoutHandler` does the same for a port's Python logger.
The port's :class:`~tdcm_ros.runtime.port.QoS` has no lifespan, so records stay in the
publisher's cache (1000 deep) for late joiners instead of expiring after 10 s, and the token's
QoS chunk shows no lifespan where a ROS node's shows ``10,0``.
"""

from __future__ import annotations

import logging
import threading
from typing import Any

from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.port import QoS

ROSOUT_TOPIC = "/rosout"
LOG_TYPE = "rcl_interfaces/msg/Log"
#: ``rmw_qos_profile_rosout_default`` as far as :class:`QoS` goes (no lifespan: see above).
ROSOUT_QOS = QoS(depth=1000, reliability="reliable", durability="transient_local")
#: ``rcl_interfaces/msg/Log`` levels (a ``byte``), highest first.
_LEVELS = ((logging.CRITICAL, 50), (logging.ERROR, 40), (logging.WARNING, 30),
           (logging.INFO, 20))
_DEBUG = 10


def log_level(levelno: int) -> int:
    """The ``Log`` level of a Python level number: FATAL 50 from CRITICAL, ERROR 40, WARN 30,
    INFO 20, DEBUG 10 for anything lower (levels between round down, as rcutils severities)."""
    return next((ros for python, ros in _LEVELS if levelno >= python), _DEBUG)


def logger_name(node_fqn: str) -> str:
    """rcl's logger name of node ``/ns/name``: ``ns.name`` (no leading slash, dots)."""
    return node_fqn.strip("/").replace("/", ".")


class RosoutHandler(logging.Handler):
    """Publishes each record as ``rcl_interfaces/msg/Log`` through ``publisher`` (anything with
    ``publish(message)``), named ``logger_name(node_fqn)``. A record logged while a record is
    being published on the same thread (the transport logging) is not published, so logging
    never recurses."""

    def __init__(self, node_fqn: str, publisher: Any) -> None:
        super().__init__()
        self.name_field = logger_name(node_fqn)
        self._publisher = publisher
        self._busy = threading.local()

    def emit(self, record: logging.LogRecord) -> None:
        if getattr(self._busy, "active", False):
            return
        self._busy.active = True
        try:
            seconds = int(record.created)
            self._publisher.publish(from_dict(LOG_TYPE, {
                "stamp": {"sec": seconds, "nanosec": int((record.created - seconds) * 1e9)},
                "level": log_level(record.levelno), "name": self.name_field,
                "msg": record.getMessage(), "file": record.pathname,
                "function": record.funcName or "", "line": record.lineno}))
        except Exception:  # noqa: BLE001 - logging must not raise; the stdlib reports it
            self.handleError(record)
        finally:
            self._busy.active = False
