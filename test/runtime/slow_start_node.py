"""A node that takes a minute to build (run as ``slow_start_node:SlowStartNode``): it creates the
file named by ``TDCM_TEST_STARTING`` once its port exists, then spends up to 60 s in its
constructor, as a node loading compiled kernels on a loaded machine does for seconds."""

from __future__ import annotations

import os
import threading
from pathlib import Path

from tdcm_ros.runtime.port import NodeLogic, NodePort

BUILD_S = 60.0


class SlowStartNode(NodeLogic):
    default_name = "slow_start"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        Path(os.environ["TDCM_TEST_STARTING"]).touch()
        threading.Event().wait(BUILD_S)  # a signal's handler still runs, and may raise, here
