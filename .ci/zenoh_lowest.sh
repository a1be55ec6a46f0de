#!/usr/bin/env bash
# CI step: the embedded runtime on the LOWEST eclipse-zenoh that dependencies.toml allows (the main run,
# .ci/test.sh, has the highest). Only eclipse-zenoh at the lower bound is installed, into a
# throwaway folder (pip --target) put first on PYTHONPATH: it shadows the installed one for this
# run and its children, inside a virtual environment or outside one alike. A small interop
# subset runs on it: the wire format (attachment), nodes in separate processes (messages,
# parameters, transient local to a late joiner, a restarted publisher), TLS + authentication +
# ACL, and the TF broadcasts. ~1 min.
#
#   bash .ci/zenoh_lowest.sh [pytest options]
set -euo pipefail
cd "$(dirname "$0")/.."
source .ci/pip_env.sh

REQUIREMENT="$(python3 .ci/deps.py requirement eclipse-zenoh)"
LOWEST="$(sed -n 's/.*>=\([0-9.]*\).*/\1/p' <<<"$REQUIREMENT")"
[ -n "$LOWEST" ] || { echo "zenoh_lowest.sh: no lower bound in $REQUIREMENT" >&2; exit 1; }

TARGET="$(mktemp -d)"
trap 'rm -rf "$TARGET"' EXIT
# pip's log goes to a file: the machine's index configuration makes it print a warning per name.
python3 -m pip install --no-deps --only-binary :all: --target "$TARGET/site" \
    "eclipse-zenoh==$LOWEST" >"$TARGET/pip.log" 2>&1 \
  || { tail -20 "$TARGET/pip.log" >&2; echo "zenoh_lowest.sh: cannot install eclipse-zenoh==$LOWEST" >&2; exit 1; }
export PYTHONPATH="$TARGET/site:$PWD${PYTHONPATH:+:$PYTHONPATH}"
GOT="$(python3 -c 'import zenoh; from importlib.metadata import version; print(version("eclipse-zenoh"), zenoh.__file__)')"
case "$GOT" in
  "$LOWEST $TARGET/site/"*) ;;
  *) echo "zenoh_lowest.sh: got eclipse-zenoh $GOT, wanted $LOWEST from $TARGET/site" >&2; exit 1 ;;
esac
echo "=== interop subset on eclipse-zenoh $LOWEST (allowed: $REQUIREMENT)"
python3 -m pytest -q -p no:cacheprovider -m "not rclpy" "$@" \
  test/runtime/test_runtime_wire.py test/runtime/test_runtime_multiprocess.py \
  test/runtime/test_zenoh_security.py test/nodes/test_tf_broadcasts.py
