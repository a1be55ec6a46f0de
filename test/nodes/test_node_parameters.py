"""What each node declares is exactly its ``PARAMETERS`` table: the same names, each with the
spec's finite range as its ROS range (so parameter files checked against the table are checked
against what the node reads)."""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.registry import NODES

#: Overrides a node needs to start in-process (no device, no Vicon, no pty link of its own).
START = {"mocap_node": {"source": "relabel", "relabel.input_topic": "/vicon/markers"},
         "tension_driver": {"port": "loop://"}}


@pytest.mark.parametrize("node", sorted(NODES))
def test_declared_parameters_are_the_table(node: str, tmp_path: Path) -> None:
    module_name, _, class_name = NODES[node].partition(":")
    module = importlib.import_module(module_name)
    overrides: dict[str, Any] = dict(START.get(node, {}))
    if node == "device_twin":
        overrides["link"] = str(tmp_path / "twin")
    port = MemoryPort(overrides, name=node)
    logic = getattr(module, class_name)(port)
    try:
        declared = port.store.specs
        assert list(declared) and set(declared) == set(module.PARAMETERS)
        for name, spec in module.PARAMETERS.items():
            assert declared[name].range == spec.bounds, name
            assert declared[name].description.startswith(spec.description), name
    finally:
        logic.close()
