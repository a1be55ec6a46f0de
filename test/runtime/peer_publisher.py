"""A peer process for restart tests: publishes ``tension`` (WrenchStamped, N) at 20 Hz until killed.

``python -m test.runtime.peer_publisher <tension N>``; the runtime comes from ``TDCM_RUNTIME``
(a plain rclpy node on rclpy, a zenoh context otherwise).
"""

from __future__ import annotations

import os
import sys
import time

from tdcm_ros.bagio import from_dict


def main() -> None:
    tension = float(sys.argv[1])
    if os.environ.get("TDCM_RUNTIME") == "rclpy":
        from test.support.plain_rclpy import PlainRclpyContext

        ctx = PlainRclpyContext()
    else:
        from tdcm_ros.runtime.zenoh_runtime import ZenohContext

        ctx = ZenohContext()
    publisher = ctx.create_port("peer_publisher").create_publisher(
        "tension", "geometry_msgs/msg/WrenchStamped")
    while True:
        stamp = time.time_ns()
        publisher.publish(from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": {"stamp": {"sec": stamp // 10**9, "nanosec": stamp % 10**9}},
            "wrench": {"force": {"z": tension}}}))
        ctx.spin_for(0.05)


if __name__ == "__main__":
    main()
