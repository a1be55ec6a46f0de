#!/usr/bin/env bash
# CI step: the docs site (doc/, Sphinx + MyST, what rosdoc2 builds).
#  1. the generated reference equals what the code gives (.ci/docs_reference.py check);
#  2. sphinx-build with warnings as errors and nitpicky references (-W -n): a broken internal link,
#     a missing page or an unresolvable cross-reference fails;
#  3. rosdoc2 build of the package (its settings: rosdoc2.yaml), in a throwaway virtual environment
#     holding rosdoc2 and the package with its runtime dependencies, as the ROS build farm installs
#     a package's dependencies before rosdoc2 runs (rosdoc2 mocks the ROS ones it cannot import:
#     rclpy, ament_index_python, launch); exit 0 and no autodoc import failure.
# The tutorials' commands run in the test suite (test/cli/test_documented_examples.py and
# test_graph_examples.py read every shell block of doc/). ~1 min.
#
#   bash .ci/docs.sh [--no-rosdoc2]
set -euo pipefail
cd "$(dirname "$0")/.."
source .ci/pip_env.sh

python3 .ci/docs_reference.py check
# Graphviz's dot draws the node graph (sphinx.ext.graphviz); from Debian, as firmware.sh does.
if ! command -v dot >/dev/null; then
  echo "docs: installing graphviz"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends graphviz >/dev/null
fi
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
echo "=== sphinx-build -W -n doc"
python3 -m sphinx -W -n --keep-going -q -b html doc "$OUT/html"
echo "docs: built $(find "$OUT/html" -name '*.html' | wc -l) pages, no warning"

[ "${1:-}" = "--no-rosdoc2" ] && exit 0
echo "=== rosdoc2 build"
python3 -m venv "$OUT/venv"
"$OUT/venv/bin/python" -m pip install -q rosdoc2 . >"$OUT/pip.log" 2>&1 \
  || { tail -20 "$OUT/pip.log" >&2; echo "docs.sh: cannot install rosdoc2 and the package" >&2; exit 1; }
status=0
"$OUT/venv/bin/rosdoc2" build -p . -o "$OUT/rosdoc2" -d "$OUT/rosdoc2_build" >"$OUT/rosdoc2.log" 2>&1 \
  || status=$?
if [ "$status" != 0 ] || grep -E "failed to import|ImportError|ModuleNotFoundError" "$OUT/rosdoc2.log"; then
  tail -40 "$OUT/rosdoc2.log" >&2
  echo "docs.sh: rosdoc2 build failed (exit $status) or an import failed" >&2
  exit 1
fi
echo "rosdoc2: built, $(grep -c WARNING "$OUT/rosdoc2.log" || true) warnings, no import failure"
