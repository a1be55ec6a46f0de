"""The one way the package gets ``matplotlib.pyplot``: imported on first use (so no face pulls
matplotlib), on the non-interactive Agg backend (files only, no display needed), and a typed
error naming the ``plot`` extra when matplotlib is missing."""

from __future__ import annotations

from typing import Any

from tdcm_ros.errors import InputError

INSTALL_HINT = "pip install 'tdcm_ros[plot]'"
"""How to get matplotlib: the package's ``plot`` extra."""


def load_pyplot(option: str, value: Any, *, subject: str | None = None) -> Any:
    """``matplotlib.pyplot`` on the Agg backend, for writing the file or folder ``value`` that
    ``option`` (e.g. ``"--out"``) names.

    Without matplotlib: an :class:`InputError` for ``option`` (its dashes stripped) and
    ``value``, saying ``"<subject> matplotlib: pip install 'tdcm_ros[plot]'"``, where
    ``subject`` defaults to ``"<option> needs"``.
    """
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise InputError(f"{subject or option + ' needs'} matplotlib: {INSTALL_HINT}",
                         parameter=option.lstrip("-"),
                         value=None if value is None else str(value),
                         allowed="matplotlib installed") from exc
    return plt
