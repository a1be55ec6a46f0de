"""The QoS chunk of an rmw_zenoh endpoint token read back: its durability."""

from __future__ import annotations

import pytest

from tdcm_ros.runtime import QoS
from tdcm_ros.runtime.wire import durability_of, qos_chunk


@pytest.mark.parametrize("durability", ["volatile", "transient_local"])
@pytest.mark.parametrize("depth", [1, 10, 100])
def test_the_durability_a_chunk_declares_reads_back(durability: str, depth: int) -> None:
    chunk = qos_chunk(QoS(depth=depth, durability=durability))  # type: ignore[arg-type]
    assert durability_of(chunk) == durability


def test_rmw_zenohs_chunks_read_as_they_mean() -> None:
    """rmw_zenoh_cpp writes an empty field for its default (volatile) and 1 for transient
    local (rmw_zenoh's qos encoding, as its tokens carry it)."""
    assert durability_of(":1:,1:,:,:,,") == "transient_local"
    assert durability_of("::,10:,:,:,,") == "volatile"
    assert durability_of("") == "volatile"
