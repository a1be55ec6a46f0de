"""How often a liveliness query of the graph completes short: N tokens on a private router, Q queries.

Run: ``PYTHONPATH=. python3 bench/bench_liveliness_query.py [--tokens 50] [--queries 40]
[--hogs 0 1] [--results FILE]``.

A peer session declares ``--tokens`` rmw_zenoh publisher tokens; a second peer asks for them
``--queries`` times with :func:`tdcm_ros.runtime.zenoh_query.gather` (what every graph query of the
package uses), with ``--hogs`` CPU-bound processes running beside it. Prints, per hog count, how
many queries completed (zenoh's final reply came) with fewer tokens than were declared, the
fewest seen, and the median time a query took. Every query should return all of them.
``--results FILE`` also writes the printed figures as tables to a results file
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

from results import BenchResults, Column, add_results_argument

REPO = Path(__file__).resolve().parents[1]
HOG = "while True: pass"


def free_port() -> int:
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def measure(tokens: int, queries: int) -> tuple[int, int, float]:
    """(short queries, fewest tokens in one, median s per query) on the router in the env."""
    from tdcm_ros.bagio import type_hash
    from tdcm_ros.runtime import wire
    from tdcm_ros.runtime.port import DEFAULT_QOS
    from tdcm_ros.runtime.zenoh_query import gather
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    declarer, asker = ZenohContext(), ZenohContext()
    node = wire.NodeIdentity(declarer.domain_id, "c0ffee" * 5 + "00", 1, "/", "crowd")
    rihs = type_hash("std_msgs/msg/String")
    held = [declarer.session.liveliness().declare_token(wire.endpoint_token(
        node, 10 + i, wire.PUBLISHER, f"/crowd/t{i}", "std_msgs/msg/String", rihs, DEFAULT_QOS))
        for i in range(tokens)]
    key = f"{wire.ADMIN_SPACE}/{asker.domain_id}/**/crowd/**"

    def ask() -> int:
        replies = gather(lambda handler: asker.session.liveliness().get(key, handler,
                                                                        timeout=10.0), 10.0)
        return len(replies.kept) if replies.complete else -1

    deadline = time.monotonic() + 30.0
    while ask() != tokens:  # the graph has them all once
        if time.monotonic() > deadline:
            raise SystemExit(f"the {tokens} tokens never all showed in 30 s")
    counts, took = [], []
    for _ in range(queries):
        start = time.perf_counter()
        counts.append(ask())
        took.append(time.perf_counter() - start)
    for token in held:
        token.undeclare()
    asker.close()
    declarer.close()
    return sum(count != tokens for count in counts), min(counts), statistics.median(took)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tokens", type=int, default=50)
    parser.add_argument("--queries", type=int, default=40)
    parser.add_argument("--hogs", type=int, nargs="+", default=[0, 1])
    add_results_argument(parser, "bench_liveliness_query")
    args = parser.parse_args()
    results = BenchResults("bench_liveliness_query")
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    os.environ.update(TDCM_ZENOH_ENDPOINT=endpoint, ROS_DOMAIN_ID=os.environ.get("ROS_DOMAIN_ID",
                                                                                "97"))
    router = subprocess.Popen([sys.executable, "-m", "tdcm_ros.runtime.router", "--listen",
                               endpoint], cwd=REPO, stderr=subprocess.PIPE)
    assert router.stderr is not None
    while b"listening on" not in router.stderr.readline():
        if router.poll() is not None:
            raise SystemExit("the router did not start")
    print(f"{'hogs':>4} {'queries':>8} {'short':>6} {'fewest':>7} {'median s':>9}")
    rows = []
    try:
        for hogs in args.hogs:
            load = [subprocess.Popen([sys.executable, "-c", HOG]) for _ in range(hogs)]
            try:
                short, fewest, median = measure(args.tokens, args.queries)
            finally:
                for hog in load:
                    hog.kill()
                    hog.wait()
            print(f"{hogs:>4} {args.queries:>8} {short:>6} {fewest:>7} {median:>9.4f}")
            rows.append([hogs, args.queries, short, fewest, median])
    finally:
        router.terminate()
        router.wait()
    results.table(
        f"Liveliness queries of {args.tokens} tokens on a private router",
        [Column("CPU hogs"), Column("queries"), Column("short"), Column("fewest tokens"),
         Column("median query", "s", ".4f")], rows,
        note="short: queries that did not return every declared token (one that did not "
             "complete counts as -1 tokens); fewest: the fewest tokens one query returned")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
