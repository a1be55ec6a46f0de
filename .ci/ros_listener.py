#!/usr/bin/env python3
"""CI check of a running ``model_node`` from a plain rclpy node, as a user's own node would be.

Publishes ``geometry_msgs/WrenchStamped`` on ``tension`` (``wrench.force.z`` = the tension,
stamped with this node's clock now, repeated until answered), waits for ``nav_msgs/Path`` on
``midline`` carrying one of those stamps, and checks its frame and last pose against
``tdcm_ros.model.solve(preset(...), tension).tip_position``. Exit status 0 when all checks pass.

Started by ``.ci/ros.sh`` from a temporary directory with ``AMENT_PREFIX_PATH`` unset and
``PYTHONSAFEPATH=1``: ``tdcm_ros`` must then come from the colcon install space (``--install``),
and no directory of the source checkout (``--repo``) may be on ``sys.path`` other than the
install space and the virtual environment.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import rclpy
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Path as PathMsg
from rclpy.node import Node

import tdcm_ros
from tdcm_ros.model import preset, solve


def _inside(path: Path, root: Path) -> bool:
    return path == root or root in path.parents


def check_import_paths(install: Path, repo: Path) -> list[str]:
    """Problems with where ``tdcm_ros`` and ``sys.path`` point (empty when fine)."""
    problems = []
    module = Path(tdcm_ros.__file__).resolve()
    print(f"ros_listener: tdcm_ros imported from {module}", flush=True)
    if not _inside(module, install):
        problems.append(f"tdcm_ros comes from {module}, not from the install space {install}")
    allowed = (install, Path(sys.prefix).resolve())
    for entry in sys.path:
        resolved = Path(entry or os.getcwd()).resolve()
        if _inside(resolved, repo) and not any(_inside(resolved, root) for root in allowed):
            problems.append(f"sys.path holds {entry!r}, a directory of the source checkout")
    if "AMENT_PREFIX_PATH" in os.environ:
        problems.append("AMENT_PREFIX_PATH is set; this check runs without it")
    return problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--install", type=Path, required=True, help="colcon install space")
    parser.add_argument("--repo", type=Path, required=True, help="source checkout")
    parser.add_argument("--tension", type=float, default=20.0, help="N")
    parser.add_argument("--preset", default="paper-experiment")
    parser.add_argument("--frame-id", default="tdcm_base")
    parser.add_argument("--tolerance", type=float, default=1e-9, help="m")
    parser.add_argument("--timeout", type=float, default=120.0, help="s")
    args = parser.parse_args()

    problems = check_import_paths(args.install.resolve(), args.repo.resolve())
    expected = solve(preset(args.preset), args.tension).tip_position
    print(f"ros_listener: expected tip {[float(v) for v in expected]} m", flush=True)

    rclpy.init()
    node = Node("tdcm_ci_listener")
    sent: set[tuple[int, int]] = set()
    answers: list[PathMsg] = []
    publisher = node.create_publisher(WrenchStamped, "tension", 10)
    node.create_subscription(PathMsg, "midline", answers.append, 10)

    def send() -> None:
        message = WrenchStamped()
        message.header.stamp = node.get_clock().now().to_msg()
        message.header.frame_id = "tdcm_tendon"
        message.wrench.force.z = args.tension
        publisher.publish(message)
        sent.add((message.header.stamp.sec, message.header.stamp.nanosec))

    node.create_timer(0.25, send)
    answer = None
    deadline = time.monotonic() + args.timeout
    try:
        while answer is None and time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.1)
            answer = next((m for m in answers
                           if (m.header.stamp.sec, m.header.stamp.nanosec) in sent), None)
    finally:
        node.destroy_node()
        rclpy.shutdown()

    if answer is None:
        problems.append(f"no midline with a stamp of ours within {args.timeout} s "
                        f"({len(sent)} tensions sent, {len(answers)} midlines received)")
    else:
        stamp = answer.header.stamp
        print(f"ros_listener: midline stamped {stamp.sec}.{stamp.nanosec:09d} in "
              f"{answer.header.frame_id!r} with {len(answer.poses)} poses", flush=True)
        if answer.header.frame_id != args.frame_id:
            problems.append(f"midline frame_id {answer.header.frame_id!r} != {args.frame_id!r}")
        if not answer.poses:
            problems.append("midline has no poses")
        else:
            tip = answer.poses[-1].pose.position
            error = math.dist((tip.x, tip.y, tip.z), tuple(float(v) for v in expected))
            print(f"ros_listener: last pose ({tip.x}, {tip.y}, {tip.z}) m, "
                  f"{error:.3e} m from the reference solve", flush=True)
            if not error <= args.tolerance:
                problems.append(f"last midline pose is {error:.3e} m from the reference tip "
                                f"(tolerance {args.tolerance:g} m)")
    for problem in problems:
        print(f"ros_listener: FAIL: {problem}", file=sys.stderr, flush=True)
    if not problems:
        print("ros_listener: OK", flush=True)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
