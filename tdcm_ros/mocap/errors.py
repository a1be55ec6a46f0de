"""Errors of :mod:`tdcm_ros.mocap`.

``MocapError`` is the root of the subpackage; every specific error also derives from
:class:`tdcm_ros.errors.InputError`, so the CLI and the nodes report it as bad input.
"""

from __future__ import annotations

from tdcm_ros.errors import InputError, TdcmError


class MocapError(TdcmError):
    """Root of every error raised by :mod:`tdcm_ros.mocap`."""


class CsvFormatError(MocapError, InputError):
    """A Vicon Nexus CSV export could not be read: missing section, column or a bad cell.

    ``path`` is the file, ``line`` the 1-based line number the problem was found on (``None``
    when it concerns the whole file, e.g. a missing ``Trajectories`` section).
    """

    def __init__(self, message: str, *, path: str, line: int | None, parameter: str = "csv",
                 value: object = None, allowed: str | None = None) -> None:
        where = f"{path}:{line}" if line is not None else path
        super().__init__(f"{where}: {message}", parameter=parameter, value=value, allowed=allowed)
        self.path = path
        self.line = line


class LabelError(MocapError, InputError):
    """A labelling configuration is invalid, or a named marker is missing from the source."""
