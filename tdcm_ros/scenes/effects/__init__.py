"""Effects by name (:data:`REGISTRY`); importing this package registers every effect."""

from tdcm_ros.scenes.effects import actuation, mechanics, sensing, timing
from tdcm_ros.scenes.effects.base import (
    CONSTRUCTED,
    REGISTRY,
    STAGES,
    Effect,
    EffectContext,
    build,
    check_names,
    parse_effect,
)

__all__ = ["CONSTRUCTED", "REGISTRY", "STAGES", "Effect", "EffectContext", "actuation", "build",
           "check_names", "mechanics", "parse_effect", "sensing", "timing"]
