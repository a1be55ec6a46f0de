"""The ``tdcm`` command line: thin shells over library functions.

Its entry point is the script :mod:`tdcm_ros.cli.main` (``main``); each subcommand is a module of
this package with ``register(subparsers)``. Nothing else in the package imports the command line,
so this face exports nothing (and stays free to import).
"""

__all__: list[str] = []
