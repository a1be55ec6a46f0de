"""QoS a user sets by parameter, as rclpy's ``QoSOverridingOptions.with_default_policies()``.

An overridable endpoint declares three read-only parameters named as rclpy names them,
``qos_overrides.<fully qualified topic>.<subscription|publisher>.<policy>``:

- ``reliability``: ``reliable`` | ``best_effort``;
- ``durability``: ``volatile`` | ``transient_local``;
- ``depth``: the keep-last history depth, 1..10000 messages (history is always keep-last).

Their defaults are the node's own QoS; a parameter file or ``-p`` sets them before the
endpoint is created (read-only afterwards, as in rclpy). The nodes make their sensor inputs
overridable, so a best-effort marker or force driver (common for sensors) can be matched on DDS:

.. code-block:: yaml

    metrics_node:
      ros__parameters:
        qos_overrides:
          /markers:
            subscription: {reliability: best_effort}
"""

from __future__ import annotations

from typing import Any, Literal

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.names import resolve_topic
from tdcm_ros.runtime.port import NodePort, QoS

RELIABILITIES = ("reliable", "best_effort")
DURABILITIES = ("volatile", "transient_local")


def _one_of(name: str, allowed: tuple[str, ...]) -> Any:
    def check(value: Any) -> None:
        if value not in allowed:
            raise InputError(f"{name} = {value!r} is not a QoS choice; allowed: "
                             f"{' | '.join(allowed)}", parameter=name, value=value,
                             allowed=" | ".join(allowed))
    return check


def overridable_qos(port: NodePort, topic: str, qos: QoS,
                    endpoint: Literal["subscription", "publisher"] = "subscription") -> QoS:
    """``qos`` with the node's ``qos_overrides.<topic>.<endpoint>.*`` parameters applied
    (declared here, read-only; see the module docstring). ``topic`` resolves as the endpoint's."""
    prefix = f"qos_overrides.{resolve_topic(topic, port.namespace, port.node_name)}.{endpoint}"
    reliability = port.declare_parameter(
        f"{prefix}.reliability", qos.reliability, read_only=True,
        description=f"QoS reliability of this {endpoint}",
        validator=_one_of(f"{prefix}.reliability", RELIABILITIES))
    durability = port.declare_parameter(
        f"{prefix}.durability", qos.durability, read_only=True,
        description=f"QoS durability of this {endpoint}",
        validator=_one_of(f"{prefix}.durability", DURABILITIES))
    depth = port.declare_parameter(f"{prefix}.depth", qos.depth, range=(1, 10_000), read_only=True,
                                   description=f"QoS keep-last depth of this {endpoint} (messages)")
    return QoS(depth=depth, reliability=reliability, durability=durability)
