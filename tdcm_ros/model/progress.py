"""The progress hook of long computations: ``progress(stage, done, total)``.

Design sweeps, the figures, calibration and the accuracy bench call it and draw nothing
themselves: the CLI attaches a progress bar on stderr, a library user what they like (or passes
``None``). ``stage`` names the work (``"fig2.png"``), ``done`` counts the units finished in that
stage so far, ``total`` is the stage's number of units, or ``None`` when it is not known
beforehand (the model evaluations of a least-squares fit).
"""

from __future__ import annotations

from collections.abc import Callable

Progress = Callable[[str, int, "int | None"], None]
"""``progress(stage, done, total)``: see the module docstring."""


def report_progress(progress: Progress | None, stage: str, done: int, total: int | None) -> None:
    """Call ``progress`` if there is one."""
    if progress is not None:
        progress(stage, done, total)


def within(progress: Progress | None, stage: str, offset: int, total: int | None
           ) -> Progress | None:
    """A hook for a part of a larger stage: its ``done`` is shifted by ``offset`` and reported
    under ``stage`` out of ``total`` (the part's own stage and total are dropped)."""
    if progress is None:
        return None
    return lambda _stage, done, _total: progress(stage, offset + done, total)
