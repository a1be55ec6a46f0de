#!/usr/bin/env bash
# The whole test suite with all its set-up (the README quick start's second command; .ci/run calls
# it). Works in a virtual environment (what a PEP 668 system needs) and outside one.
#
# What it installs on this machine before any test runs:
#   - into the `python3` first on PATH (the active virtual environment's, if any): this checkout in
#     editable mode with its `test` extra (pytest, pytest-xdist, hypothesis, ruff, mypy, stubs) and
#     the highest eclipse-zenoh that dependencies.toml allows;
#   - .ros/venv, a virtual environment of ROS 2 Jazzy pip wheels (rclpy, the message packages,
#     colcon; ~600 MB), and .ros/ws, a colcon workspace, both inside the checkout (.ci/ros.sh);
#   - nothing with apt (.ci/run's firmware step installs the AVR toolchain and simavr).
#
# Two halves, embedded (this Python, no ROS) and rclpy (.ci/ros.sh: the ROS venv, a colcon build of
# the package and its interface packages, the installed executables, then the tests marked `rclpy`
# with TDCM_REQUIRE_RCLPY=1 so that none of them can be skipped). They share no transport (zenoh
# routers on free loopback ports; DDS in domains 1..101, discovery on this host) and no files, so
# they may run side by side; on 2 cores they are ordered by load instead:
#   1. the in-process tier (CPU-bound, on simulated time: TDCM_TEST_CPU_WORKERS pytest-xdist
#      workers, default 2) beside an interop subset on the lowest eclipse-zenoh allowed
#      (.ci/zenoh_lowest.sh: processes, ~0.7 of a core; the in-process tests only take longer for
#      it, and cannot fail for it), while .ci/ros.sh --prepare builds the ROS venv and workspace in
#      the background, at niceness 19 (it has no deadline: it takes what CPU the tiers leave idle,
#      and goes on beside step 2);
#   2. the embedded process tier (marked `process`: processes and a transport, mostly waiting on
#      timers and sockets: TDCM_TEST_WORKERS workers, default 4), then its end-to-end demos (marked
#      `demo`: graphs of 7 real-time processes) alone, one at a time;
#   3. the rclpy tier (.ci/ros.sh --tests-only: the same split), so that two runtimes' real-time
#      graphs do not starve each other.
# Every step runs even when an earlier one failed; each pytest run lists its 25 slowest tests.
set -uo pipefail
cd "$(dirname "$0")/.."
source .ci/pip_env.sh
LOGS="$(mktemp -d)"
BACKGROUND=()
stop_tree() {  # stop_tree PID: SIGTERM to it and every descendant (a background job of a script
  local child  # ignores SIGINT, so Ctrl-C on this script would leave it running)
  for child in $(ps -o pid= --ppid "$1" 2>/dev/null); do stop_tree "$child"; done
  kill -TERM "$1" 2>/dev/null || true
}
finish() {
  local pid
  for pid in "${BACKGROUND[@]}"; do stop_tree "$pid"; done
  rm -rf "$LOGS"
}
trap finish EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
start=$SECONDS
failed=()
TICKS="$(getconf CLK_TCK)"
children_cpu() {  # children_cpu PID: CPU s used by the finished children of shell PID so far
  awk -v ticks="$TICKS" '{ print ($16 + $17) / ticks }' "/proc/$1/stat"
}
step() {  # step NAME COMMAND...: run it, say how long it took (wall, CPU), remember a failure
  local name="$1" t0=$SECONDS status=0 cpu0 shell=$BASHPID
  shift
  cpu0="$(children_cpu "$shell")"
  echo "=== $name"
  "$@" || status=$?
  echo "=== $name: exit $status after $((SECONDS - t0)) s ($(awk -v a="$cpu0" -v b="$(children_cpu "$shell")" \
    'BEGIN { printf "%.0f", b - a }') CPU-s)"
  [ "$status" = 0 ] || failed+=("$name (exit $status)")
  return "$status"
}

set -e
python3 -m pip install -q -e '.[test]'
# The highest eclipse-zenoh that dependencies.toml allows (pip keeps an older one that satisfies it otherwise).
python3 -m pip install -q --upgrade --only-binary :all: "eclipse-zenoh>=1.5.0,!=1.8.0,<1.9"
set +e

TDCM_ROS_BUILD_NICE=19 bash .ci/ros.sh --prepare >"$LOGS/ros_prepare.log" 2>&1 &
PREPARE=$!
BACKGROUND+=("$PREPARE")
step "lowest eclipse-zenoh" bash .ci/zenoh_lowest.sh -n 2 >"$LOGS/lowest.log" 2>&1 &
LOWEST=$!
BACKGROUND+=("$LOWEST")
# A worker that crashes ends its run (red, naming the test) instead of being replaced: after one
# rclpy worker's segfault xdist waited forever on its replacement (CI of a135fb7).
PYTEST=(python3 -m pytest -q -p no:cacheprovider --durations=25 --max-worker-restart=0)
step "in-process tier" "${PYTEST[@]}" -n "${TDCM_TEST_CPU_WORKERS:-2}" -m "not rclpy and not process"
lowest=0
wait "$LOWEST" || lowest=$?  # the step's own status line is in its log
echo "=== beside it:"
cat "$LOGS/lowest.log"
[ "$lowest" = 0 ] || failed+=("lowest eclipse-zenoh (exit $lowest)")
step "embedded process tier" "${PYTEST[@]}" -n "${TDCM_TEST_WORKERS:-4}" \
  -m "process and not rclpy and not demo"
step "embedded demos, alone" "${PYTEST[@]}" -m "demo and not rclpy"
prepare=0
wait "$PREPARE" || prepare=$?
echo "=== ROS venv and workspace (.ci/ros.sh --prepare): exit $prepare"
cat "$LOGS/ros_prepare.log"
if [ "$prepare" = 0 ]; then
  step "rclpy tier" bash .ci/ros.sh --tests-only
else
  failed+=("ros.sh --prepare (exit $prepare)")
fi

if [ "${#failed[@]}" != 0 ]; then
  printf 'test.sh: FAILED after %s s: %s\n' "$((SECONDS - start))" "${failed[*]}" >&2
  exit 1
fi
echo "test.sh: every tier passed in $((SECONDS - start)) s"
