#!/usr/bin/env bash
# The whole test suite with all its set-up (the README quick start's second command; .ci/run calls
# it). Works in a virtual environment (what a PEP 668 system needs) and outside one.
#
# What it installs on this machine before any test runs:
#   - into the `python3` first on PATH (the active virtual environment's, if any): this checkout in
#     editable mode with its `test` extra (pytest, pytest-xdist, hypothesis, ruff, mypy, stubs) and
#     the highest eclipse-zenoh that setup.py allows;
#   - .ros/venv, a virtual environment of ROS 2 Jazzy pip wheels (rclpy, the message packages,
#     colcon; ~600 MB), and .ros/ws, a colcon workspace, both inside the checkout (.ci/ros.sh);
#   - nothing with apt (.ci/run's firmware step installs the AVR toolchain and simavr).
#
# Two halves run side by side. They share no transport (zenoh routers on free loopback ports;
# DDS in domains 1..101, discovery on this host) and no files:
#   1. embedded: every test not marked `rclpy`, in this Python, on TDCM_TEST_WORKERS pytest-xdist
#      workers (default 3), then an interop subset on the lowest eclipse-zenoh allowed
#      (.ci/zenoh_lowest.sh);
#   2. rclpy: .ci/ros.sh (the ROS venv, colcon build of the package and its interface packages, the
#      installed executables, then the tests marked `rclpy` with TDCM_REQUIRE_RCLPY=1 so that none
#      of them can be skipped).
# Each half's output is printed once it ends; every pytest run lists its 25 slowest tests.
set -euo pipefail
cd "$(dirname "$0")/.."
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_ROOT_USER_ACTION=ignore
LOGS="$(mktemp -d)"
trap 'rm -rf "$LOGS"' EXIT

python3 -m pip install -q -e '.[test]'
# The highest eclipse-zenoh that setup.py allows (pip keeps an older one that satisfies it otherwise).
python3 -m pip install -q --upgrade --only-binary :all: "eclipse-zenoh>=1.5.0,!=1.8.0,<1.9"

embedded() {
  python3 -m pytest -q -p no:cacheprovider -n "${TDCM_TEST_WORKERS:-3}" --dist loadgroup --durations=25 \
    -m "not rclpy" && bash .ci/zenoh_lowest.sh -n 2
}

start=$SECONDS
embedded >"$LOGS/embedded.log" 2>&1 &
EMBEDDED=$!
bash .ci/ros.sh >"$LOGS/rclpy.log" 2>&1 &
RCLPY=$!

status=0
wait "$EMBEDDED" || status=$?
echo "=== embedded half (this Python): exit $status after $((SECONDS - start)) s"
cat "$LOGS/embedded.log"
ros_status=0
wait "$RCLPY" || ros_status=$?
echo "=== rclpy half (.ci/ros.sh): exit $ros_status after $((SECONDS - start)) s"
cat "$LOGS/rclpy.log"
if [ "$status" != 0 ] || [ "$ros_status" != 0 ]; then
  echo "test.sh: FAILED (embedded half exit $status, rclpy half exit $ros_status)" >&2
  exit 1
fi
echo "test.sh: both halves passed in $((SECONDS - start)) s"
