"""Entry point of the ``tdcm`` console script.

Each subcommand lives in its own module exposing ``register(subparsers)``; that function adds
its parser and sets ``handler`` (a callable taking the parsed namespace and returning an exit
status). Known errors become a one-line message on stderr and the error's exit status.

Only the module of the command being run is imported (``tdcm solve`` never loads the evaluation,
the runtimes or scipy); ``tdcm``, ``tdcm -h`` and unknown commands import every module to list
them all.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from tdcm_ros import __version__
from tdcm_ros.errors import TdcmError

COMMANDS: dict[str, str] = {
    "demo": "tdcm_ros.cli.demo",
    "solve": "tdcm_ros.cli.solve",
    "up": "tdcm_ros.cli.up",
    "topic": "tdcm_ros.cli.topic",
    "record": "tdcm_ros.cli.record",
    "bag": "tdcm_ros.cli.record",
    "param": "tdcm_ros.cli.param",
    "bench": "tdcm_ros.cli.bench",
    "figures": "tdcm_ros.cli.figures",
    "evaluate": "tdcm_ros.cli.evaluate",
    "calibrate": "tdcm_ros.cli.calibrate",
    "scene": "tdcm_ros.cli.scene",
}
"""Command name -> module that registers it (in ``tdcm -h`` order)."""


def _modules(argv: Sequence[str]) -> list[str]:
    """The modules to register for ``argv``: the named command's, else every one."""
    command = next((a for a in argv if not a.startswith("-")), None)
    if command in COMMANDS:
        return [COMMANDS[command]]
    return list(dict.fromkeys(COMMANDS.values()))


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The top-level parser with the subcommands ``argv`` needs (``None``: every one)."""
    parser = argparse.ArgumentParser(prog="tdcm", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"tdcm_ros {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    modules = list(dict.fromkeys(COMMANDS.values())) if argv is None else _modules(argv)
    for module_name in modules:
        importlib.import_module(module_name).register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``tdcm``; returns the process exit status."""
    args_in = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(args_in).parse_args(args_in)
    try:
        return int(args.handler(args))
    except TdcmError as error:
        print(f"tdcm {args.command}: {error}", file=sys.stderr)
        return error.exit_code
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
