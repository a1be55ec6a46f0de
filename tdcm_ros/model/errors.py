"""Errors of the model subpackage: invalid input, physical limits, non-convergence."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tdcm_ros.errors import InputError, PhysicsError, TdcmError

if TYPE_CHECKING:
    from tdcm_ros.model.result import SolveResult


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


class NotchClosureError(ModelLimitError):
    """A notch bent so far that its faces touch (contact is not part of the base model)."""

    kind = "notch_closure"

    def __init__(self, message: str, *, notch: int, gap_m: float) -> None:
        super().__init__(message)
        self.notch = notch
        self.gap_m = gap_m


class ConvergenceError(ModelError, PhysicsError):
    """Algorithm 1 did not reach the tolerance; ``result`` holds the last finite iterate, if any."""

    kind = "non_convergence"

    def __init__(self, message: str, *, result: SolveResult | None = None) -> None:
        super().__init__(message)
        self.result = result
