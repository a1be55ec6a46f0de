"""The error of the :mod:`tdcm_ros.bagio` subpackage."""

from __future__ import annotations

from tdcm_ros.errors import InputError


class BagError(InputError):
    """A bag, message type, definition or payload could not be handled; the message names it."""
