"""Progress bars of long commands (tqdm, on stderr so stdout stays clean for ``--json``).

A bar is drawn only when stderr is a terminal and ``--quiet`` was not given: a pipe, a log file
or CI gets none. ``-q/--quiet`` is a global option (``tdcm -q figures``) also accepted after the
long commands (``tdcm figures -q``).
"""

from __future__ import annotations

import argparse
import sys
from types import TracebackType
from typing import Any, Self, TextIO

QUIET_HELP = "draw no progress bar (bars go to stderr, and only when it is a terminal)"


def add_quiet_argument(parser: argparse.ArgumentParser, *, top_level: bool = False) -> None:
    """Add ``-q/--quiet``; on a subcommand it leaves the global flag alone unless given."""
    parser.add_argument("-q", "--quiet", action="store_true", help=QUIET_HELP,
                        default=False if top_level else argparse.SUPPRESS)


class ProgressBars:
    """A :data:`tdcm_ros.model.Progress` hook drawing one tqdm bar per stage on ``stream``;
    draws nothing when ``quiet`` or when ``stream`` is not a terminal."""

    def __init__(self, *, quiet: bool, stream: TextIO | None = None) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = not quiet and self.stream.isatty()
        self._stage: str | None = None
        self._bar: Any = None

    @classmethod
    def of(cls, args: argparse.Namespace) -> ProgressBars:
        """Bars for a parsed command line (``--quiet`` given or not)."""
        return cls(quiet=bool(getattr(args, "quiet", False)))

    def __call__(self, stage: str, done: int, total: int | None) -> None:
        if not self.enabled:
            return
        if stage != self._stage:
            from tqdm import tqdm

            self.close()
            self._bar = tqdm(total=total, desc=stage, file=self.stream, leave=False,
                             dynamic_ncols=True)
            self._stage = stage
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        """Remove the current bar (the next stage opens a new one)."""
        if self._bar is not None:
            self._bar.close()
        self._bar, self._stage = None, None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        self.close()
