"""The runtime port: the only interface node logic uses to talk to the world.

A node is a :class:`NodeLogic` subclass. Its constructor receives a :class:`NodePort` and
declares parameters, publishers, subscriptions and timers through it; it never imports rclpy or
zenoh. The same class runs on the zenoh runtime (no ROS) or the rclpy runtime (ROS 2 Jazzy)::

    class Talker(NodeLogic):
        default_name = "talker"

        def __init__(self, port: NodePort) -> None:
            super().__init__(port)
            self.period = port.declare_parameter("period", 0.5, description="s", range=(1e-3, 60))
            self.pub = port.create_publisher("chatter", "std_msgs/msg/String", QoS(depth=10))
            port.create_timer(self.period, self.tick)

Services (``create_service``) answer requests on the node's thread; a command is a
``std_srvs/srv/Trigger`` whose response says whether it was carried out and why not.
Messages are rosbags objects (:mod:`tdcm_ros.bagio`); both runtimes carry their CDR bytes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar, Literal, Protocol

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.parameters import P, SetCallback, Validator

Reliability = Literal["reliable", "best_effort"]
Durability = Literal["volatile", "transient_local"]


@dataclass(frozen=True)
class QoS:
    """Keep-last QoS of an endpoint: history ``depth`` (messages), reliability, durability."""

    depth: int = 10
    reliability: Reliability = "reliable"
    durability: Durability = "volatile"

    def __post_init__(self) -> None:
        if not 1 <= self.depth <= 10_000:
            raise InputError(f"QoS depth = {self.depth} is out of range; allowed: [1, 10000]",
                             parameter="depth", value=self.depth, allowed="[1, 10000]")
        if self.reliability not in ("reliable", "best_effort"):
            raise InputError(f"QoS reliability = {self.reliability!r} is invalid",
                             parameter="reliability", value=self.reliability,
                             allowed="reliable, best_effort")
        if self.durability not in ("volatile", "transient_local"):
            raise InputError(f"QoS durability = {self.durability!r} is invalid",
                             parameter="durability", value=self.durability,
                             allowed="volatile, transient_local")


DEFAULT_QOS = QoS()
#: Default time (s) a service call waits for a server and its answer.
SERVICE_TIMEOUT_S = 5.0
#: Where a node with ``use_sim_time`` takes its time from, as in ROS 2.
CLOCK_TOPIC = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
#: rclcpp's ``ClockQoS``: the newest time only.
CLOCK_QOS = QoS(depth=1, reliability="best_effort")


class Publisher(Protocol):
    """A declared publisher."""

    topic: str
    type_name: str

    def publish(self, message: Any) -> None:
        """Serialise a rosbags message to CDR and send it."""

    def publish_cdr(self, data: bytes) -> None:
        """Send CDR bytes already serialised for ``type_name``."""

    def matched(self) -> bool:
        """True once at least one subscription matches this publisher."""


class Timer(Protocol):
    """A periodic timer."""

    def cancel(self) -> None:
        """Stop the timer; its callback is not called again."""


class Logger(Protocol):
    """%-style logger (``logging.Logger`` fits; the rclpy adapter wraps rclpy's)."""

    def debug(self, msg: str, *args: object) -> None:
        """Log at DEBUG."""

    def info(self, msg: str, *args: object) -> None:
        """Log at INFO."""

    def warning(self, msg: str, *args: object) -> None:
        """Log at WARNING."""

    def error(self, msg: str, *args: object) -> None:
        """Log at ERROR."""


class NodePort(Protocol):
    """What a runtime offers a node. Callbacks run one at a time, never concurrently."""

    node_name: str
    namespace: str

    @property
    def logger(self) -> Logger:
        """The node's logger."""

    def declare_parameter(self, name: str, default: P, *, description: str = "",
                          range: tuple[float, float] | None = None,
                          validator: Validator | None = None,
                          read_only: bool = False, formerly: tuple[str, ...] = ()) -> P:
        """Declare a parameter; returns its value (YAML override or default), checked, of the
        default's type. A parameter file may still set it by a name in ``formerly`` (a
        deprecated alias; the node's log warns)."""

    def unused_overrides(self) -> list[str]:
        """Names the node's parameter file sets that it did not declare (sorted): a typo, or a
        parameter of another node."""

    def get_parameter(self, name: str) -> Any:
        """Current value of a declared parameter, of its default's type (``Any`` statically:
        the type depends on the name)."""

    def add_on_set_parameters(self, callback: SetCallback) -> None:
        """Add a check run on each runtime change ``{name: value}``; raise ``InputError`` to reject."""

    def create_publisher(self, topic: str, type_name: str, qos: QoS = DEFAULT_QOS) -> Publisher:
        """Declare a publisher; relative topics resolve under the node's namespace."""

    def create_subscription(self, topic: str, type_name: str, callback: Callable[[Any], None],
                            qos: QoS = DEFAULT_QOS) -> None:
        """Subscribe; ``callback`` receives the deserialised rosbags message."""

    def create_service(self, name: str, type_name: str,
                       handler: Callable[[Any], Any]) -> None:
        """Serve ``type_name`` (``pkg/srv/Name``) on ``name`` (``~/x``: under the node's name);
        ``handler`` gets the deserialised request and returns the response message. It runs on
        the node's callback thread like every callback; if it raises, the error is logged and
        the caller gets no response."""

    def call_service(self, name: str, type_name: str, request: Any = None,
                     timeout: float = SERVICE_TIMEOUT_S) -> Any:
        """Call service ``name`` (resolved like a topic) of ``type_name`` with ``request``
        (default: an empty request); the response, or ``RuntimePortError`` if no server
        answers within ``timeout`` s. Blocks the calling thread: call it from a thread of the
        node's own, never from a callback (on rclpy the callbacks' thread delivers the
        answer)."""

    def create_timer(self, period: float, callback: Callable[[], None]) -> Timer:
        """Call ``callback`` every ``period`` seconds."""

    def call_soon(self, callback: Callable[[], None]) -> None:
        """Call ``callback`` once on the node's callback thread, after the callbacks already
        due: messages received before this call are delivered first, so a node that keeps
        only the newest input of a burst processes it once. Safe from any thread; a failing
        callback is logged like any other."""

    def now_ns(self) -> int:
        """Current time of the node's clock, ns since the UNIX epoch (with the ROS parameter
        ``use_sim_time``: the latest ``/clock``, 0 before the first)."""

    def graph_hubs(self) -> frozenset[str]:
        """What connects the node to the graph: on zenoh the ids of the routers connected to its
        session (empty: cut off from the graph); on rclpy ``{"dds"}`` always (DDS has no router
        to lose). A restarted router has a new id, so a change shows even when no check saw the
        graph gone."""


class NodeLogic:
    """Base of every transport-agnostic node. Subclasses set ``default_name``."""

    default_name: ClassVar[str] = "node"

    def __init__(self, port: NodePort) -> None:
        self.port = port

    def close(self) -> None:
        """Release resources before the runtime shuts down (default: nothing)."""

