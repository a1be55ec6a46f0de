#!/usr/bin/env bash
# The whole test suite with all its set-up (the README quick start's second command; .ci/run calls it):
#   1. the ROS-free core and every node on the embedded runtime, in this Python (no ROS): every test
#      not marked `rclpy`;
#   2. the embedded runtime on the lowest eclipse-zenoh setup.py allows (.ci/zenoh_lowest.sh: a small
#      interop subset in a throwaway virtual environment; step 1 runs on the highest allowed);
#   3. the rclpy half on real ROS 2 Jazzy, in a separate virtual environment (.ci/ros.sh: pip wheels of
#      rclpy, colcon build of tdcm_ros and the interface packages, the installed executables, then the
#      tests marked `rclpy` with TDCM_REQUIRE_RCLPY=1 so none of them can be skipped).
set -euo pipefail
cd "$(dirname "$0")/.."
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_ROOT_USER_ACTION=ignore
python3 -m pip install -q -e '.[test]'
# The highest eclipse-zenoh that setup.py allows (pip keeps an older one that satisfies it otherwise).
python3 -m pip install -q --upgrade --only-binary :all: "eclipse-zenoh>=1.5.0,!=1.8.0,<1.9"
python3 -m pytest -q -m "not rclpy"
bash .ci/zenoh_lowest.sh
bash .ci/ros.sh
