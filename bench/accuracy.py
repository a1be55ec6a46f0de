"""Accuracy vs time of every method and setting; same as ``tdcm bench accuracy``.

Usage: ``python bench/accuracy.py [--json] [--plot FILE.png] [--quick]``.
"""

from __future__ import annotations

import sys

from tdcm_ros.cli.main import main

if __name__ == "__main__":
    sys.exit(main(["bench", "accuracy", *sys.argv[1:]]))
