"""A node that takes ``CLOSE_S`` s to close, as a node whose clean-up waits on a loaded machine
does; it creates the file named by ``TDCM_TEST_STARTING`` once built."""

from __future__ import annotations

import os
import threading
from pathlib import Path

from tdcm_ros.runtime.port import NodeLogic, NodePort

CLOSE_S = 5.0


class SlowStopNode(NodeLogic):
    default_name = "slow_stop"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        Path(os.environ["TDCM_TEST_STARTING"]).touch()

    def close(self) -> None:
        threading.Event().wait(CLOSE_S)
