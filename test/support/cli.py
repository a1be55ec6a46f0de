"""``tdcm`` run in this process, as a shell would see it: exit status, stdout and stderr.

A subprocess costs a Python start and the imports (numpy, scipy, numba's cache) on every call,
about 1.5 s of CPU; :func:`tdcm` calls :func:`tdcm_ros.cli.main.main` with the standard streams
redirected instead. What needs a real process (a terminal, signals, ``python -m tdcm_ros``
itself, a package without numba) keeps ``subprocess``.
"""

from __future__ import annotations

import contextlib
import io
import subprocess
import warnings
from pathlib import Path

from tdcm_ros.cli.main import main


def tdcm(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """``tdcm ARGS`` in this process (from ``cwd`` if given): its status, stdout and stderr."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.ExitStack() as stack:
        if cwd is not None:
            stack.enter_context(contextlib.chdir(cwd))
        stack.enter_context(contextlib.redirect_stdout(out))
        stack.enter_context(contextlib.redirect_stderr(err))
        # warnings as a fresh interpreter shows them (pytest would record them instead)
        caught = stack.enter_context(warnings.catch_warnings(record=True))
        warnings.simplefilter("default")
        try:
            status = main(list(args))
        except SystemExit as exit_:  # argparse's usage errors and --help
            code = exit_.code
            status = code if isinstance(code, int) else (0 if code is None else 1)
        for shown in caught:
            err.write(warnings.formatwarning(shown.message, shown.category, shown.filename,
                                             shown.lineno, shown.line))
    return subprocess.CompletedProcess(["tdcm", *args], status, out.getvalue(), err.getvalue())
