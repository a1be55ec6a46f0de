"""Entry point of the ``tdcm`` console script.

Each subcommand lives in its own module exposing ``register(subparsers)``; that function adds
its parser and sets ``handler`` (a callable taking the parsed namespace and returning an exit
status). Known errors become a one-line message on stderr and the error's exit status.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from tdcm_ros import __version__
from tdcm_ros.errors import TdcmError

SUBCOMMAND_MODULES: tuple[str, ...] = (
    "tdcm_ros.cli.demo",
    "tdcm_ros.cli.solve",
    "tdcm_ros.cli.up",
    "tdcm_ros.cli.topic",
    "tdcm_ros.cli.record",
    "tdcm_ros.cli.param",
    "tdcm_ros.cli.bench",
    "tdcm_ros.cli.figures",
    "tdcm_ros.cli.evaluate",
    "tdcm_ros.cli.calibrate",
    "tdcm_ros.cli.scene",
)


def build_parser() -> argparse.ArgumentParser:
    """Build the top-level parser with every registered subcommand."""
    parser = argparse.ArgumentParser(prog="tdcm", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"tdcm_ros {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module_name in SUBCOMMAND_MODULES:
        importlib.import_module(module_name).register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``tdcm``; returns the process exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args))
    except TdcmError as error:
        print(f"tdcm {args.command}: {error}", file=sys.stderr)
        return error.exit_code
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
