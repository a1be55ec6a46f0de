"""Nodes for the signal tests, each creating the file named by ``TDCM_TEST_STARTING`` once its
port exists. Three take a minute to build, spending up to 60 s in their constructor, as a node
loading compiled kernels on a loaded machine does for seconds. ``SlowStartNode`` lets a signal's
error through;
``SwallowingStartNode`` drops it and returns, as a native library that runs Python's signal
handlers inside a call and discards their error does (seen: model_node built on and spun);
``SwallowingSlowNode`` drops it and builds on for another minute (seen: an importlib callback
dropped it and model_node's build went on past the launcher's 5 s). ``SlowStopNode`` builds at
once and takes ``CLOSE_S`` s to close, as a node whose clean-up waits on a loaded machine does."""

from __future__ import annotations

import contextlib
import os
import threading
from pathlib import Path

from tdcm_ros.runtime.port import NodeLogic, NodePort

BUILD_S = 60.0
CLOSE_S = 5.0


class StartingNode(NodeLogic):
    """Creates the ``TDCM_TEST_STARTING`` file once its port exists."""

    default_name = "starting"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        Path(os.environ["TDCM_TEST_STARTING"]).touch()


class SlowStartNode(StartingNode):
    default_name = "slow_start"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        threading.Event().wait(BUILD_S)  # a signal's handler still runs, and may raise, here


class SwallowingStartNode(StartingNode):
    default_name = "swallowing_start"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        with contextlib.suppress(KeyboardInterrupt):
            threading.Event().wait(BUILD_S)


class SwallowingSlowNode(SwallowingStartNode):
    default_name = "swallowing_slow"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        threading.Event().wait(BUILD_S)  # the rest of the build, no signal's error to stop it


class SlowStopNode(StartingNode):
    default_name = "slow_stop"

    def close(self) -> None:
        threading.Event().wait(CLOSE_S)
