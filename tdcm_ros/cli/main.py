"""Entry point of the ``tdcm`` console script.

Each subcommand lives in its own module exposing ``register(subparsers)``; that function adds
its parser and sets ``handler`` (a callable taking the parsed namespace and returning an exit
status). Known errors become a one-line message on stderr and the error's exit status. A module
may declare ``EXIT_MEANINGS`` (command path, e.g. ``"topic echo"`` -> status -> what it means
there); every ``--help`` ends with the statuses of :data:`EXIT_STATUSES` and those meanings.

Only the module of the command being run is imported (``tdcm solve`` never loads the evaluation,
the runtimes or scipy); ``tdcm``, ``tdcm -h`` and unknown commands import every module to list
them all.
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
from collections.abc import Mapping, Sequence

from tdcm_ros import __version__
from tdcm_ros.cli.deprecation import one_line_warnings
from tdcm_ros.cli.help import TdcmParser
from tdcm_ros.cli.progress import add_quiet_argument
from tdcm_ros.errors import InputError, PhysicsError, TdcmError

COMMANDS: dict[str, str] = {
    "demo": "tdcm_ros.cli.demo",
    "solve": "tdcm_ros.cli.solve",
    "inverse": "tdcm_ros.cli.inverse",
    "design": "tdcm_ros.cli.design",
    "urdf": "tdcm_ros.cli.urdf",
    "foxglove": "tdcm_ros.cli.foxglove",
    "up": "tdcm_ros.cli.up",
    "topic": "tdcm_ros.cli.topic",
    "record": "tdcm_ros.cli.record",
    "bag": "tdcm_ros.cli.bag",
    "param": "tdcm_ros.cli.param",
    "service": "tdcm_ros.cli.service",
    "bench": "tdcm_ros.cli.bench",
    "figures": "tdcm_ros.cli.figures",
    "evaluate": "tdcm_ros.cli.evaluate",
    "calibrate": "tdcm_ros.cli.calibrate",
    "scene": "tdcm_ros.cli.scene",
}
"""Command name -> module that registers it (in ``tdcm -h`` order)."""

INTERRUPTED_EXIT = 130
"""Exit status after Ctrl-C (128 + SIGINT, as shells report it)."""
CLOSED_PIPE_EXIT = 141
"""Exit status when the reader of stdout closed it (128 + SIGPIPE, as shells report it)."""

EXIT_STATUSES: dict[int, str] = {
    0: "success",
    TdcmError.exit_code: "failure",
    InputError.exit_code: "bad input: usage, a parameter, a value or a file",
    PhysicsError.exit_code: "a physical limit of the model, or numerics that did not converge",
    INTERRUPTED_EXIT: "interrupted (Ctrl-C)",
    CLOSED_PIPE_EXIT: "stdout closed by its reader (a pipe into head, ...)",
}
"""Exit statuses common to every command (``--help`` epilogs, doc/reference/cli.md)."""


def exit_status_epilog(meanings: Mapping[int, str]) -> str:
    """One paragraph listing the exit statuses, with what this command means by some."""
    parts = [f"{code} {text}" + (f" ({meanings[code]})" if code in meanings else "")
             for code, text in EXIT_STATUSES.items()]
    return "exit status: " + "; ".join(parts) + "."


def _add_exit_statuses(parser: argparse.ArgumentParser, path: str,
                       meanings: Mapping[str, Mapping[int, str]]) -> None:
    """Append the exit-status epilog to ``parser`` and to its verbs' parsers."""
    epilog = exit_status_epilog(meanings.get(path, {}))
    parser.epilog = f"{parser.epilog}\n\n{epilog}" if parser.epilog else epilog
    for action in parser._actions:  # argparse keeps subparsers only there
        if isinstance(action, argparse._SubParsersAction):
            for verb, child in action.choices.items():
                _add_exit_statuses(child, f"{path} {verb}", meanings)

DESCRIPTION = """\
tdcm: the shape model of a notched tendon-driven continuum manipulator (Algorithm 1), its ROS 2
nodes on an embedded zenoh runtime or on rclpy, and the tools around them. SI units throughout."""

EPILOG = """\
quick start:
  tdcm demo                                  # the paper's experiment end to end, simulated
  tdcm solve --tension 20 --plot shape.png   # one shape, summary and plot

conventions: commands that write several files take --out DIR, a single figure is --plot FILE;
a design is named by --design NAME wherever one is used (the same as --set design.preset=NAME);
in preset and scene names - and _ are the same character (paper-experiment, the spelling these
help texts use, is paper_experiment); long commands draw a progress bar on stderr when it is a
terminal (-q/--quiet: none). 'tdcm COMMAND -h' shows a command's options and examples."""


def _modules(argv: Sequence[str]) -> list[str]:
    """The modules to register for ``argv``: the named command's, else every one."""
    command = next((a for a in argv if not a.startswith("-")), None)
    if command in COMMANDS:
        return [COMMANDS[command]]
    return list(dict.fromkeys(COMMANDS.values()))


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The top-level parser with the subcommands ``argv`` needs (``None``: every one)."""
    parser = TdcmParser(prog="tdcm", description=DESCRIPTION,
                        epilog=f"{EPILOG}\n\n{exit_status_epilog({})}")
    parser.add_argument("--version", action="version", version=f"tdcm_ros {__version__}")
    add_quiet_argument(parser, top_level=True)
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    modules = list(dict.fromkeys(COMMANDS.values())) if argv is None else _modules(argv)
    for module_name in modules:
        module = importlib.import_module(module_name)
        known = set(subparsers.choices)
        module.register(subparsers)
        for name in subparsers.choices.keys() - known:
            _add_exit_statuses(subparsers.choices[name], name,
                               getattr(module, "EXIT_MEANINGS", {}))
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``tdcm``; returns the process exit status. As a process (``argv`` None), Ctrl-C
    (SIGINT) stops a command even if it was started with SIGINT ignored, as a background job of
    a non-interactive shell is: Python then leaves it ignored, and a command that runs until
    Ctrl-C would never stop (rclpy's tools install their own handler for the same reason)."""
    if argv is None:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    args_in = sys.argv[1:] if argv is None else list(argv)
    one_line_warnings()
    args = build_parser(args_in).parse_args(args_in)
    try:
        return int(args.handler(args))
    except TdcmError as error:
        print(f"tdcm {args.command}: {error}", file=sys.stderr)
        return error.exit_code
    except KeyboardInterrupt:
        return INTERRUPTED_EXIT
    except BrokenPipeError:
        _discard_stdout()
        return CLOSED_PIPE_EXIT


def _discard_stdout() -> None:
    """Point the process's stdout at the null device, so that the interpreter's last flush of a
    pipe its reader closed raises nothing (an in-process stdout without a file is left)."""
    try:
        descriptor = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):
        return
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, descriptor)
    os.close(null)


if __name__ == "__main__":
    sys.exit(main())
