"""``tdcm bag play`` warns when nodes on wall time will drop what it plays: a bag recorded
more than 0.5 s ago, played without ``--clock``."""

from __future__ import annotations

from tdcm_ros.cli.bag import stale_stamps_warning

NOW = 1_800_000_000_000_000_000


def test_an_old_bag_without_clock_warns_with_the_cure() -> None:
    warning = stale_stamps_warning(NOW - 3600 * 10**9, NOW, clock=False)
    assert warning.startswith("WARNING: the bag's messages are stamped 3600 s ago")
    assert "input.max_age_s" in warning and "--clock" in warning and "--use-sim-time" in warning


def test_with_clock_or_a_fresh_bag_nothing_is_said() -> None:
    assert stale_stamps_warning(NOW - 3600 * 10**9, NOW, clock=True) == ""
    assert stale_stamps_warning(NOW - 4 * 10**8, NOW, clock=False) == ""
