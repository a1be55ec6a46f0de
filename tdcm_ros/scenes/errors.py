"""Errors of the scenes subpackage."""

from __future__ import annotations

from tdcm_ros.errors import InputError, TdcmError


class SceneError(TdcmError):
    """Root of the scenes' errors."""


class InvalidSceneError(SceneError, InputError):
    """A scene file or value is malformed: names the key, the value and what is allowed."""

    kind = "invalid_scene"
