#!/usr/bin/env bash
# The whole test suite with all its set-up (the README quick start's second command; .ci/run calls it):
#   1. the ROS-free core and every node on the embedded runtime, in this Python (no ROS): every test
#      not marked `rclpy`;
#   2. the embedded runtime on the lowest eclipse-zenoh setup.py allows (.ci/zenoh_lowest.sh: a small
#      interop subset in a throwaway virtual environment; step 1 runs on the highest allowed);
#   3. the rclpy half on real ROS 2 Jazzy (run beside 1 and 2, its log printed after them), in a separate virtual environment (.ci/ros.sh: pip wheels of
#      rclpy, colcon build of tdcm_ros and the interface packages, the installed executables, then the
#      tests marked `rclpy` with TDCM_REQUIRE_RCLPY=1 so none of them can be skipped).
set -euo pipefail
cd "$(dirname "$0")/.."
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_ROOT_USER_ACTION=ignore
python3 -m pip install -q -e '.[test]'
# The highest eclipse-zenoh that setup.py allows (pip keeps an older one that satisfies it otherwise).
python3 -m pip install -q --upgrade --only-binary :all: "eclipse-zenoh>=1.5.0,!=1.8.0,<1.9"
# The rclpy half (.ci/ros.sh) runs beside steps 1-2: both halves mostly wait on timers and the
# network (a whole run used ~7 CPU minutes in 14 wall minutes when they ran one after the other),
# they share no transport (zenoh on free TCP ports vs DDS in ros.sh's own domain) and the rclpy
# half imports the package from its colcon install space. Its log is printed after them.
mkdir -p .ros
bash .ci/ros.sh >.ros/ros.log 2>&1 &
ROS_PID=$!
failed=()
python3 -m pytest -q -m "not rclpy" || failed+=("pytest -m 'not rclpy'")
bash .ci/zenoh_lowest.sh || failed+=(".ci/zenoh_lowest.sh")
wait "$ROS_PID" || failed+=(".ci/ros.sh (log above)")
cat .ros/ros.log
if [ "${#failed[@]}" -gt 0 ]; then
  printf 'test.sh: FAILED: %s\n' "${failed[@]}" >&2
  exit 1
fi
