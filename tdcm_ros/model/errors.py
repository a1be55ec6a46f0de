"""Errors of the model subpackage: invalid input and physical limits.

Non-convergence (:class:`~tdcm_ros.model.result.ConvergenceError`) lives beside the result it
carries, so this module imports nothing of the model and sits under every other model module.
"""

from __future__ import annotations

from tdcm_ros.errors import InputError, PhysicsError, TdcmError


class ModelError(TdcmError):
    """Root of the model's errors."""


class InvalidDesignError(ModelError, InputError):
    """A design field is missing, of the wrong type, or outside its allowed range."""

    kind = "invalid_design"


class InvalidSettingsError(ModelError, InputError):
    """A solver setting is outside its allowed range."""

    kind = "invalid_settings"


class TensionRangeError(ModelError, InputError):
    """The tendon tension is negative, NaN or infinite."""

    kind = "tension_out_of_range"


class ModelLimitError(ModelError, PhysicsError):
    """The requested state lies beyond a physical limit of the model."""


class TendonSingularityError(ModelLimitError):
    """The tendon's offset curve cusps: ``R_c * kappa`` reached 1 where the tendon follows the body."""

    kind = "tendon_singularity"

    def __init__(self, message: str, *, arc_length_m: float, rc_kappa: float) -> None:
        super().__init__(message)
        self.arc_length_m = arc_length_m
        self.rc_kappa = rc_kappa


class StrainLimitError(ModelLimitError):
    """A notch's peak strain passed the material's recoverable strain."""

    kind = "strain_limit"

    def __init__(self, message: str, *, notch: int, strain: float) -> None:
        super().__init__(message)
        self.notch = notch
        self.strain = strain


class NotchClosureError(ModelLimitError):
    """A notch bent so far that its faces touch (contact is not part of the base model)."""

    kind = "notch_closure"

    def __init__(self, message: str, *, notch: int, gap_m: float) -> None:
        super().__init__(message)
        self.notch = notch
        self.gap_m = gap_m
