"""What ``setup.py`` declares, read by running it with ``setuptools.setup`` replaced (no build)."""

from __future__ import annotations

import re
import runpy
import sys
from pathlib import Path
from typing import Any
from unittest import mock

REPO = Path(__file__).resolve().parents[1]


def setup_kwargs(*argv: str) -> dict[str, Any]:
    """The keyword arguments ``setup.py`` passes to ``setup()`` when run as ``setup.py *argv``."""
    captured: dict[str, Any] = {}
    with mock.patch("setuptools.setup", lambda **kwargs: captured.update(kwargs)), \
            mock.patch.object(sys, "argv", [str(REPO / "setup.py"), *argv]):
        runpy.run_path(str(REPO / "setup.py"), run_name="__main__")
    return captured


def requirement_name(requirement: str) -> str:
    """``eclipse-zenoh>=1.5`` -> ``eclipse-zenoh`` (normalised: lower case, ``_`` as ``-``)."""
    return re.split(r"[<>=!~;\[ ]", requirement, maxsplit=1)[0].strip().lower().replace("_", "-")


def console_scripts(*argv: str) -> dict[str, str]:
    """Console script name -> ``module:function`` of ``setup.py *argv``."""
    entries = setup_kwargs(*argv)["entry_points"]["console_scripts"]
    return dict(tuple(part.strip() for part in entry.split("=", 1)) for entry in entries)
