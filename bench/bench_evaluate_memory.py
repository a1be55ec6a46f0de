"""Memory benchmark (issue 15 item 5): peak RSS of ``tdcm evaluate`` against the bag's size.

Run: ``python bench/bench_evaluate_memory.py [--minutes 10 30] [--bags DIR] [--baseline DIR]
[--results FILE]``.
Writes simulated bags (``bench_evaluate.py --write``, in a child so that this process stays
small: a child's peak RSS from ``os.wait4`` counts at least its parent's RSS at the spawn; kept in
``--bags DIR`` and reused when there, else in a temporary folder; not measured), then runs
``python -m tdcm_ros evaluate BAG --set E=0.7e9 --json`` as a child per bag and reads its peak
RSS from ``os.wait4``. ``--baseline DIR`` runs the same on another checkout (e.g. the main branch
before this change) and says whether both print the same JSON.

Prints per bag: its size, the peak RSS, their ratio (the target is <= 3), the ratio of the peak
above the import floor (a child importing the evaluation modules and nothing else) to the bag,
between consecutive bags the marginal ratio: extra peak RSS per extra bag byte, and the child's
wall time from spawn to exit (the command end to end; one run, so noisy on a shared machine).
``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from bench_start import ROOT, run_once
from results import BenchResults, Column, add_results_argument

TARGET_RATIO = 3.0
MIB = 2.0**20
FLOOR = "import tdcm_ros.cli.evaluate, tdcm_ros.metrics.api"
BENCH_SET = "E=0.7e9"
"""The simulated robot's Young's modulus (``bench_evaluate.BENCH_E``)."""


def bag_bytes(bag: Path) -> int:
    """Size of a bag folder's files (bytes)."""
    return sum(f.stat().st_size for f in bag.iterdir() if f.is_file())


def bags(folder: Path, minutes: list[float]) -> list[Path]:
    """The bench bags of ``minutes`` in ``folder``, written when missing."""
    found = []
    for m in minutes:
        path = folder / f"bench_{m:g}min"
        if not path.exists():
            run_once([sys.executable, str(Path(__file__).with_name("bench_evaluate.py")),
                      "--minutes", f"{m:g}", "--write", str(path)], ROOT, None)
        found.append(path)
    return found


def measure(root: Path, bag: Path, out: Path) -> tuple[float, float]:
    """Wall time (s) and peak RSS (MiB) of ``tdcm evaluate BAG --json`` on the checkout
    ``root``; JSON to ``out``."""
    command = [sys.executable, "-m", "tdcm_ros", "evaluate", str(bag), "--set", BENCH_SET, "--json"]
    with out.open("wb") as stream:
        return run_once(command, root, stream)


def report(name: str, root: Path, paths: list[Path], scratch: Path,
           results: BenchResults) -> list[str]:
    """Print the rows of one checkout (and record them in ``results``); returns the JSON
    outputs per bag."""
    floor = run_once([sys.executable, "-c", FLOOR], root)[1]
    print(f"{name} ({root}): import floor {floor:.1f} MiB")
    print(f"  {'bag':<16} {'size MiB':>9} {'peak MiB':>9} {'peak/bag':>9} {'(peak-floor)/bag':>17}"
          f" {'wall s':>7}")
    outputs, previous = [], None
    rows: list[list[object]] = []
    for bag in paths:
        out = scratch / f"{name}_{bag.name}.json"
        (wall, peak), size = measure(root, bag, out), bag_bytes(bag) / MIB
        outputs.append(out.read_text())
        verdict = "met" if peak / size <= TARGET_RATIO else "NOT met"
        print(f"  {bag.name:<16} {size:9.1f} {peak:9.1f} {peak / size:9.2f} "
              f"{(peak - floor) / size:17.2f} {wall:7.2f}   (target peak/bag <= {TARGET_RATIO:g}: "
              f"{verdict})")
        marginal = None
        if previous is not None:
            marginal = (peak - previous[1]) / (size - previous[0])
            print(f"  {'':<16} marginal: {marginal:.2f} MiB "
                  f"of peak per MiB of bag from {previous[2]}")
        rows.append([bag.name, size, peak, peak / size, (peak - floor) / size, marginal, wall])
        previous = (size, peak, bag.name)
    results.table(
        f"Peak RSS of tdcm evaluate, {name} checkout",
        [Column("bag"), Column("size", "MiB", ".1f"), Column("peak RSS", "MiB", ".1f"),
         Column("peak / bag", format=".2f"), Column("(peak − import floor) / bag", format=".2f"),
         Column("marginal: peak per bag from the previous bag", "MiB/MiB", ".2f"),
         Column("wall time, one run", "s", ".2f")], rows,
        note=f"import floor (a child importing the evaluation modules and nothing else): "
             f"{floor:.1f} MiB; target peak / bag <= {TARGET_RATIO:g}")
    return outputs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, nargs="+", default=[10.0, 30.0],
                        help="lengths of the simulated bags (min)")
    parser.add_argument("--bags", type=Path, metavar="DIR",
                        help="folder keeping the bags between runs (default: a temporary one)")
    parser.add_argument("--baseline", type=Path, metavar="DIR",
                        help="another checkout measured on the same bags")
    add_results_argument(parser, "bench_evaluate_memory")
    args = parser.parse_args()
    results = BenchResults("bench_evaluate_memory")
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.bags or Path(tmp)
        folder.mkdir(exist_ok=True)
        paths = bags(folder, sorted(args.minutes))
        ours = report("this", ROOT, paths, Path(tmp), results)
        if args.baseline:
            theirs = report("baseline", args.baseline.resolve(), paths, Path(tmp), results)
            print(f"same JSON from both checkouts: {'yes' if ours == theirs else 'NO'}")
            results.table("Same output", ["checkouts", "same JSON"],
                          [[f"this and {args.baseline}", ours == theirs]])
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
