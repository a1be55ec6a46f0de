"""Start benchmark (issue 15 item 5): ``tdcm solve`` from process start to its JSON.

Run: ``python bench/bench_start.py [--runs 15] [--tension 20] [--baseline /work/main]
[--results FILE]``.
Times whole child processes
(wall clock from spawn to exit, JSON on stdout) and reads each child's peak RSS from
``os.wait4``, interleaving in every round:

- ``cli``: ``python -m tdcm_ros solve --tension T --json`` (what ``tdcm solve`` runs, without the
  console-script wrapper of the environment, e.g. a pyenv shim);
- ``library``: ``python -c`` importing ``tdcm_ros.model``, solving and printing the same JSON;
- ``python``: a bare interpreter (``python -c pass``), the floor of any process;
- ``baseline`` (with ``--baseline DIR``): the ``cli`` command on another checkout, e.g. the main
  branch before this change, in the same rounds.

Children run in the checkout this script belongs to (working directory and ``PYTHONPATH``).
Prints medians, minima, peak RSS and the ratios to the library run. Target: ``cli`` median
<= 0.3 s. ``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import IO

from results import BenchResults, Column, add_results_argument

TARGET_S = 0.3
LIBRARY = ("import json; from tdcm_ros.model import preset, solve; "
           "print(json.dumps(solve(preset('paper-experiment'), {t}).summary()))")


ROOT = Path(__file__).resolve().parents[1]


def run_once(command: list[str], root: Path, stdout: IO[bytes] | int | None = subprocess.DEVNULL
             ) -> tuple[float, float]:
    """Wall time (s) from spawn to exit and peak RSS (MiB) of one child running ``command`` on
    the checkout ``root`` (its standard output to ``stdout``); it must succeed. The peak counts
    at least this process's RSS at the spawn, so keep this process small."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    started = time.perf_counter()
    child = subprocess.Popen(command, stdout=stdout, env=env, cwd=root)
    _, status, usage = os.wait4(child.pid, 0)
    elapsed = time.perf_counter() - started
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode:
        raise SystemExit(f"{' '.join(command)} exited with {child.returncode}")
    return elapsed, usage.ru_maxrss / 1024.0  # ru_maxrss is in KiB on Linux


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15, help="rounds (each runs every command)")
    parser.add_argument("--tension", type=float, default=20.0, help="tension of the solve (N)")
    parser.add_argument("--baseline", type=Path, metavar="DIR",
                        help="another checkout whose cli start is timed in the same rounds")
    add_results_argument(parser, "bench_start")
    args = parser.parse_args()
    results = BenchResults("bench_start")
    cli = [sys.executable, "-m", "tdcm_ros", "solve", "--tension", f"{args.tension:g}", "--json"]
    commands = {
        "cli": (cli, ROOT),
        "library": ([sys.executable, "-c", LIBRARY.format(t=float(args.tension))], ROOT),
        "python": ([sys.executable, "-c", "pass"], ROOT),
    }
    if args.baseline:
        commands["baseline"] = (cli, args.baseline.resolve())
    times: dict[str, list[float]] = {name: [] for name in commands}
    peaks: dict[str, list[float]] = {name: [] for name in commands}
    for command, root in commands.values():  # warm the file cache, not counted
        run_once(command, root)
    for _ in range(args.runs):
        for name, (command, root) in commands.items():
            elapsed, peak = run_once(command, root)
            times[name].append(elapsed)
            peaks[name].append(peak)
    print(f"tdcm solve start, {args.runs} interleaved runs each ({sys.executable}, "
          f"checkout {ROOT}{f', baseline {args.baseline}' if args.baseline else ''})")
    library = statistics.median(times["library"])
    rows = []
    for name in commands:
        median = statistics.median(times[name])
        print(f"  {name:<8} median {median:.3f} s  min {min(times[name]):.3f} s  "
              f"peak RSS {max(peaks[name]):6.1f} MiB  ({median / library:.2f}x library)")
        rows.append([name, median, min(times[name]), max(peaks[name]), median / library])
    cli = statistics.median(times["cli"])
    print(f"cli over library: +{cli - library:.3f} s; target cli <= {TARGET_S:g} s: "
          f"{'met' if cli <= TARGET_S else 'NOT met'}")
    results.table(
        f"tdcm solve start, {args.runs} interleaved runs each",
        [Column("command"), Column("median", "s", ".3f"), Column("min", "s", ".3f"),
         Column("peak RSS", "MiB", ".1f"), Column("× library", format=".2f")], rows,
        note=f"wall clock from spawn to exit, tension {args.tension:g} N; cli: python -m "
             "tdcm_ros solve --json; library: python -c importing tdcm_ros.model and solving; "
             "python: python -c pass"
             + (f"; baseline: the cli on {args.baseline}" if args.baseline else "")
             + f". cli over library: +{cli - library:.3f} s; target cli <= {TARGET_S:g} s: "
             f"{'met' if cli <= TARGET_S else 'NOT met'}")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
