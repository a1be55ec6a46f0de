"""Fixtures shared by every test directory: hostile YAML texts and a printing stopwatch.

Hypothesis explores new random examples on every local run, with no per-example deadline (speed is
measured by bench/, not by tests); under CI (``CI`` set) it is derandomized, so a CI run is reproducible and a red CI names a failure that reruns the same. What
local runs find becomes a regression test of its own (e.g. the absurd chunk size in
test/bagio/test_bagio_hostile.py).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager

import pytest
from hypothesis import settings

#: The multi-process fixtures (``runtime``, ``router``, ``context``, ``spawn``, ...) for every folder.
pytest_plugins = ["test.support.graph"]

# No per-example deadline: hypothesis's default (200 ms) is a wall-clock bound that a loaded
# machine breaks (a property test failed on it 7 times in 9 on the shared 2-core machine).
settings.register_profile("local", deadline=None)
settings.register_profile("ci", settings.get_profile("local"), derandomize=True, print_blob=True)
settings.load_profile("ci" if os.environ.get("CI") else "local")



@pytest.fixture(autouse=True, scope="session")
def _cache_in_a_temporary_folder(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Rows the package caches on disk (:mod:`tdcm_ros.model.file_cache`) go to a folder of
    this session, for the processes the tests start too, not to the user's cache."""
    before = os.environ.get("TDCM_CACHE_DIR")
    os.environ["TDCM_CACHE_DIR"] = str(tmp_path_factory.mktemp("tdcm_cache"))
    yield
    if before is None:
        os.environ.pop("TDCM_CACHE_DIR", None)
    else:
        os.environ["TDCM_CACHE_DIR"] = before


NESTED_LEVELS = 5000
HUGE_BYTES = 10_000_000


def alias_bomb(levels: int = 9) -> str:
    """The "billion laughs" as one flow sequence: ``levels`` anchored lists, each of nine
    aliases to the previous one (9**levels strings once expanded)."""
    items = ["&l0 [" + ", ".join(["lol"] * 9) + "]"]
    for level in range(1, levels):
        items.append(f"&l{level} [" + ", ".join([f"*l{level - 1}"] * 9) + "]")
    return "[" + ", ".join(items) + "]"


#: name -> (hostile YAML text, a phrase the error must contain)
HOSTILE_YAML: dict[str, tuple[str, str]] = {
    "billion_laughs": (f"laughs: {alias_bomb()}\n", "anchors and aliases"),
    "flow_nesting": ("[" * NESTED_LEVELS + "]" * NESTED_LEVELS, "deeper than 64 levels"),
    "flow_mapping_nesting": ("{a: " * NESTED_LEVELS + "1" + "}" * NESTED_LEVELS,
                             "deeper than 64 levels"),
    "block_nesting": ("- " * NESTED_LEVELS + "x\n", "deeper than 64 levels"),
    "huge_input": ("k: " + "x" * HUGE_BYTES + "\n", "bytes of YAML, over the limit of"),
    "duplicate_top_level_key": ("seed: 1\nname: a\nseed: 2\n", "line 3: duplicate key 'seed'"),
    "duplicate_nested_key": ("schedule:\n  trials: 1\n  trials: 2\n",
                             "line 3: duplicate key 'trials'"),
}


@pytest.fixture(params=sorted(HOSTILE_YAML))
def hostile_yaml(request: pytest.FixtureRequest) -> tuple[str, str, str]:
    """``(name, text, phrase)`` for each hostile YAML text."""
    return (request.param, *HOSTILE_YAML[request.param])


@pytest.fixture
def alias_bomb_value() -> str:
    """A 9-level alias bomb to put under any key."""
    return alias_bomb()


@contextmanager
def _stopwatch(label: str) -> Iterator[None]:
    start = time.perf_counter()
    try:
        yield
    finally:
        print(f"{label}: {1e3 * (time.perf_counter() - start):.1f} ms")


@pytest.fixture
def stopwatch() -> Callable[[str], AbstractContextManager[None]]:
    """``with stopwatch(label):`` prints the block's wall time (never asserted on)."""
    return _stopwatch


#: Fixtures that start processes or a transport: a test using one is in the process tier.
PROCESS_FIXTURES = frozenset({"router", "spawn", "context", "runtime", "zenoh_env", "graph_env"})


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark every test that uses a process fixture, and every end-to-end demo, ``process``
    (tests that start processes by other means carry the mark themselves)."""
    for item in items:
        if PROCESS_FIXTURES & set(getattr(item, "fixturenames", ())) or item.get_closest_marker(
                "demo"):
            item.add_marker(pytest.mark.process)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Iterator[None]:
    """Keep each phase's report on the item (``item.report_call``): fixtures that own processes
    show what those said when the test failed."""
    outcome = yield
    report = outcome.get_result()
    setattr(item, f"report_{report.when}", report)
