"""Test side of the player tests: a small bag with known bytes and times, and a peer that takes
what the player publishes as raw CDR bytes on either runtime (zenoh context or plain rclpy)."""

from __future__ import annotations

import itertools
import signal
import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tdcm_ros.bagio import from_dict, serialize
from tdcm_ros.bagio.writer import BagWriter, OfferedQos
from tdcm_ros.runtime.port import QoS
from test.support.waiting import eventually

T0_NS = 1_700_000_000 * 10**9      # log time of the bag's first message
STEP_NS = 50_000_000               # spacing of the first burst (50 ms)
GAP_S = 4.0                        # bag time between the two bursts of /a
FIRST_BURST = 30                   # messages of /a (and of /b) in the first burst
SECOND_BURST = 10                  # messages of /a after the gap
LATCHED = OfferedQos(depth=1, durability="transient_local")
TYPES = {"/a": "std_msgs/msg/String", "/b": "std_msgs/msg/Float64", "/latched": "std_msgs/msg/String"}

DEEP = QoS(depth=1000)             # the peer's subscriptions: nothing dropped while it is busy
Message = tuple[str, int, bytes]   # (topic, log time ns, CDR bytes)


def sample_messages() -> list[Message]:
    """The bag's messages in log-time order: /latched once at the start, a first burst of /a
    (strings of varying length) interleaved with /b, then after :data:`GAP_S` a second burst."""
    out: list[Message] = [("/latched", T0_NS, serialize(from_dict(
        TYPES["/latched"], {"data": "mocap -> tdcm_base"}), TYPES["/latched"]))]
    for i in range(FIRST_BURST):
        t = T0_NS + (i + 1) * STEP_NS
        out.append(("/a", t, serialize(from_dict(TYPES["/a"], {"data": "a" * i}), TYPES["/a"])))
        out.append(("/b", t + STEP_NS // 2, serialize(from_dict(TYPES["/b"], {"data": i * 0.5}),
                                                      TYPES["/b"])))
    second = out[-1][1] + round(GAP_S * 1e9)
    for i in range(SECOND_BURST):
        out.append(("/a", second + i * STEP_NS, serialize(from_dict(
            TYPES["/a"], {"data": f"second {i}"}), TYPES["/a"])))
    return out


def write_bag(path: Path, messages: list[Message]) -> Path:
    """A rosbag2 MCAP bag of ``messages``; /latched recorded as transient local, depth 1."""
    writer = BagWriter(path)
    for topic, type_name in TYPES.items():
        writer.add_topic(topic, type_name, LATCHED if topic == "/latched" else OfferedQos())
    for topic, stamp, data in messages:
        writer.write(topic, stamp, data)
    writer.close()
    return path


def on(messages: list[Message], topic: str) -> list[bytes]:
    return [data for t, _, data in messages if t == topic]


class RawPeer:
    """Raw subscriptions on the test's runtime; ``got`` holds (topic, bytes, arrival s)."""

    def __init__(self, context: Any) -> None:
        self.context = context
        self.got: list[tuple[str, bytes, float]] = []
        self._names = itertools.count()

    def subscribe(self, topic: str, type_name: str, qos: QoS = DEEP) -> None:
        from test.support.plain_rclpy import PlainRclpyContext

        name = f"raw_peer_{next(self._names)}"
        if isinstance(self.context, PlainRclpyContext):
            from tdcm_ros.runtime.rclpy_runtime import message_class, qos_profile

            self.context.create_port(name).node.create_subscription(
                message_class(type_name), topic, lambda data: self._take(topic, data),
                qos_profile(qos), raw=True)
        else:
            self.context.create_port(name).create_raw_subscription(
                topic, type_name, lambda sample: self._take(topic, sample.data), qos)

    def _take(self, topic: str, data: bytes) -> None:
        self.got.append((topic, bytes(data), time.monotonic()))

    def on(self, topic: str) -> list[bytes]:
        return [data for t, data, _ in self.got if t == topic]

    def arrivals(self, topic: str) -> list[float]:
        return [at for t, _, at in self.got if t == topic]

    def spin_until(self, predicate: Callable[[], bool], timeout: float, what: str) -> None:
        eventually(predicate, timeout, what, spin=self.context)

    def spin_while_running(self, process: subprocess.Popen[bytes], timeout: float) -> int:
        """Spin until ``process`` exits; its exit status."""
        self.spin_until(lambda: process.poll() is not None, timeout, "the player to exit")
        self.context.spin_for(0.3)
        return int(process.returncode)



def interrupt(process: subprocess.Popen[bytes], timeout: float = 20.0) -> tuple[int, str]:
    """SIGINT, as Ctrl-C; the exit status and stderr."""
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=timeout)
    return int(process.returncode), err.decode()
