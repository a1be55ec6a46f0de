"""Errors of the scenes subpackage."""

from __future__ import annotations

from tdcm_ros.errors import InputError, TdcmError


class SceneError(TdcmError):
    """Root of the scenes' errors."""


class InvalidSceneError(SceneError, InputError):
    """A scene file or value is malformed: names the key, the value and what is allowed."""

    kind = "invalid_scene"


class EffectConflictError(SceneError, InputError):
    """Two listed effects set the same field of the loading or of the plant: names both effects
    (in file order) and the field."""

    kind = "effect_conflict"

    def __init__(self, first: str, second: str, field: str) -> None:
        allowed = f"one effect setting {field}"
        super().__init__(f"effects.{first} and effects.{second} both set {field}; allowed: "
                         f"{allowed} (list only one of them)", parameter=f"effects.{second}",
                         value=second, allowed=allowed)
        self.first = first
        self.second = second
        self.field = field
