"""The in-memory port: parameters checked like the runtimes, timers on its manual clock, messages
through a CDR round trip."""

from __future__ import annotations

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.port import NodeLogic, NodePort, QoS

START_NS = 1_000_000_000


class Echo(NodeLogic):
    """Republishes ``in`` on ``out`` and counts ticks of a ``period`` timer."""

    default_name = "echo"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        self.period = port.declare_parameter("period", 0.5, range=(0.01, 10.0))
        self.out = port.create_publisher("out", "std_msgs/msg/String", QoS(depth=5))
        port.create_subscription("in", "std_msgs/msg/String", self.out.publish)
        self.ticks: list[int] = []
        self.timer = port.create_timer(self.period, lambda: self.ticks.append(port.now_ns()))


def test_overrides_are_checked_and_int_widens_to_float() -> None:
    assert Echo(MemoryPort({"period": 2})).period == 2.0
    with pytest.raises(InputError, match=r"period = 20 is out of range; allowed: \[0.01, 10.0\]"):
        Echo(MemoryPort({"period": 20}))


def test_timers_fire_in_time_order_until_cancelled() -> None:
    port = MemoryPort({"period": 0.25}, start_ns=START_NS)
    node = Echo(port)
    port.advance(1.0)
    assert node.ticks == [START_NS + k * 250_000_000 for k in (1, 2, 3, 4)]
    assert port.now_ns() == START_NS + 1_000_000_000
    node.timer.cancel()
    port.advance(1.0)
    assert len(node.ticks) == 4


def test_a_delivered_message_round_trips_and_is_kept_with_its_send_time() -> None:
    port = MemoryPort(start_ns=START_NS)
    Echo(port)
    port.deliver("in", from_dict("std_msgs/msg/String", {"data": "hi"}))
    (message,) = port.messages("out")
    assert message.data == "hi" and port.sent("out") == [(START_NS, message)]
    assert port.publishers["out"].qos.depth == 5


def test_delivering_to_a_topic_nobody_subscribed_names_the_subscriptions() -> None:
    port = MemoryPort()
    Echo(port)
    with pytest.raises(RuntimePortError, match=r"no subscription on 'other'; subscribed: \['in'\]"):
        port.deliver("other", from_dict("std_msgs/msg/String", {"data": "x"}))


def test_a_timer_period_must_be_positive() -> None:
    with pytest.raises(InputError, match="timer period = 0 s must be > 0"):
        MemoryPort().create_timer(0, lambda: None)


class Counter(NodeLogic):
    """Serves ``~/reset`` (std_srvs/srv/Trigger): refuses until ``armed``, then counts."""

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        self.armed, self.resets = False, 0
        port.create_service("~/reset", "std_srvs/srv/Trigger", self.reset)

    def reset(self, _request: object) -> object:
        if not self.armed:
            return from_dict("std_srvs/srv/Trigger_Response",
                             {"success": False, "message": "refused: not armed"})
        self.resets += 1
        return from_dict("std_srvs/srv/Trigger_Response",
                         {"success": True, "message": f"reset {self.resets}"})


def test_services_answer_through_a_cdr_round_trip() -> None:
    port = MemoryPort()
    node = Counter(port)
    refused = port.call("~/reset")
    assert (refused.success, refused.message) == (False, "refused: not armed")
    node.armed = True
    assert port.call("~/reset").message == "reset 1"
    with pytest.raises(RuntimePortError, match=r"no service 'reset'; served: \['~/reset'\]"):
        port.call("reset")


class Newest(NodeLogic):
    """Keeps the newest ``in`` and publishes it on ``out`` from ``call_soon``: the keep-latest
    pattern of model_node."""

    default_name = "newest"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        self.out = port.create_publisher("out", "std_msgs/msg/String")
        port.create_subscription("in", "std_msgs/msg/String", self.on_in)
        self.pending: str | None = None
        self.skipped = 0
        self.order: list[str] = []

    def on_in(self, message) -> None:
        self.order.append(f"in {message.data}")
        if self.pending is None:
            self.port.call_soon(self.flush)
        else:
            self.skipped += 1
        self.pending = message.data

    def flush(self) -> None:
        self.order.append(f"flush {self.pending}")
        self.out.publish(from_dict("std_msgs/msg/String", {"data": self.pending}))
        self.pending = None


def text(data: str):
    return from_dict("std_msgs/msg/String", {"data": data})


def test_call_soon_runs_once_the_callback_returns_and_a_burst_first_delivers_all() -> None:
    port = MemoryPort()
    node = Newest(port)
    port.deliver("in", text("a"))  # an idle node: processed on arrival
    assert node.order == ["in a", "flush a"]
    with port.burst():  # three arrive while the node is busy: the newest is processed once
        for data in "bcd":
            port.deliver("in", text(data))
        assert [m.data for m in port.messages("out")] == ["a"]
    assert node.order[2:] == ["in b", "in c", "in d", "flush d"]
    assert [m.data for m in port.messages("out")] == ["a", "d"] and node.skipped == 2


def test_a_callback_queued_by_call_soon_waits_for_the_one_running() -> None:
    port = MemoryPort()
    order: list[str] = []

    def first() -> None:
        order.append("first starts")
        port.call_soon(lambda: order.append("second"))
        order.append("first ends")

    port.call_soon(first)
    assert order == ["first starts", "first ends", "second"]
    port.create_timer(1.0, lambda: port.call_soon(lambda: order.append("after the tick")))
    port.advance(1.0)
    assert order[-1] == "after the tick"
