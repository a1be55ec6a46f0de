"""The error of the :mod:`tdcm_ros.runtime` subpackage."""

from __future__ import annotations

from tdcm_ros.errors import TdcmError


class RuntimePortError(TdcmError):
    """A runtime could not be started or used: bad name, missing transport, unreachable node."""
