"""Errors of the shape controller's core."""

from __future__ import annotations

from tdcm_ros.errors import InputError


class TargetRefusedError(InputError):
    """A target the controller will not command: not finite, in an unknown frame, outside the
    roll limits or farther from the tip's reachable path than the tolerance. The message names
    the value and the allowed range (with its unit)."""

    kind = "target_refused"
