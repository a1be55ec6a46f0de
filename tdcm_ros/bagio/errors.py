"""The error of the :mod:`tdcm_ros.bagio` subpackage."""

from __future__ import annotations

from tdcm_ros.errors import TdcmError


class BagError(TdcmError):
    """A message type, definition or payload could not be handled; the message names it."""
