"""Build any registered node in-process on the memory port, as the runtimes build it."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType
from typing import Any

from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.registry import NODES

#: Overrides a node needs to start in-process (no device, no Vicon, no pty link of its own).
START = {"mocap_node": {"source": "relabel", "relabel.input_topic": "/vicon/markers"},
         "tension_driver": {"port": "loop://"}}


def start_overrides(node: str, tmp_path: Path) -> dict[str, Any]:
    """:data:`START`'s overrides of ``node``, the device twin's link under ``tmp_path``."""
    overrides: dict[str, Any] = dict(START.get(node, {}))
    if node == "device_twin":
        overrides["link"] = str(tmp_path / "twin")
    return overrides


def built_node(node: str, tmp_path: Path, parameters: dict[str, Any] | None = None
               ) -> tuple[ModuleType, MemoryPort, Any]:
    """``node``'s module, its memory port and its logic, built with ``parameters`` and
    :func:`start_overrides` over them; the caller closes the logic."""
    module_name, _, class_name = NODES[node].partition(":")
    module = importlib.import_module(module_name)
    port = MemoryPort({**(parameters or {}), **start_overrides(node, tmp_path)}, name=node)
    return module, port, getattr(module, class_name)(port)
