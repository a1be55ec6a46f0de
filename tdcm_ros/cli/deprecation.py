"""Old option spellings kept for scripts: they still work and warn once on stderr.

``parser.add_argument("--plots", action=DeprecatedAlias, replacement="--out", ...)`` stores the
value like ``store`` and warns with :class:`DeprecatedOptionWarning` (a ``FutureWarning``, the
category Python shows end users by default; ``-W ignore::FutureWarning`` silences it).
"""

from __future__ import annotations

import argparse
import warnings
from collections.abc import Sequence
from typing import Any

from tdcm_ros.spec import DeprecatedNameWarning


class DeprecatedOptionWarning(DeprecatedNameWarning):
    """An option was given by a deprecated spelling."""


class DeprecatedAlias(argparse.Action):
    """``store`` that warns: the option is an old spelling of ``replacement``."""

    def __init__(self, option_strings: Sequence[str], dest: str, *, replacement: str,
                 **kwargs: Any) -> None:
        self.replacement = replacement
        help_text = kwargs.pop("help", None)
        kwargs["help"] = f"deprecated spelling of {replacement}" + (
            f" ({help_text})" if help_text else "")
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: Any, option_string: str | None = None) -> None:
        warnings.warn(f"{option_string} is deprecated; use {self.replacement} (same meaning)",
                      DeprecatedOptionWarning, stacklevel=2)
        setattr(namespace, self.dest, values)


def one_line_warnings() -> None:
    """Show a :class:`DeprecatedNameWarning` (a deprecated option, scene key or parameter name)
    as ``tdcm: warning: MESSAGE`` (one line, no source location); other warnings keep
    Python's format."""
    plain = warnings.formatwarning
    if getattr(plain, "tdcm_one_line", False):
        return

    def formatted(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  line: str | None = None) -> str:
        if issubclass(category, DeprecatedNameWarning):
            return f"tdcm: warning: {message}\n"
        return plain(message, category, filename, lineno, line)

    formatted.tdcm_one_line = True  # type: ignore[attr-defined]
    warnings.formatwarning = formatted
