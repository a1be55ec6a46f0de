#!/usr/bin/env bash
# CI step: the embedded runtime on the LOWEST eclipse-zenoh that setup.py allows (the main run,
# .ci/test.sh, has the highest). A throwaway virtual environment on top of this Python's packages
# gets only eclipse-zenoh at the lower bound; a small interop subset runs in it: the wire format
# (attachment), nodes in separate processes (messages, parameters, transient local to a late
# joiner, a restarted publisher), TLS + authentication + ACL, and the TF broadcasts. ~1 min.
#
#   bash .ci/zenoh_lowest.sh
set -euo pipefail
cd "$(dirname "$0")/.."
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_ROOT_USER_ACTION=ignore

REQUIREMENT="$(python3 -c 'import re, sys; sys.stdout.write(re.search(r"ZENOH_REQUIREMENT = \"([^\"]+)\"", open("setup.py").read()).group(1))')"
LOWEST="$(sed -n 's/.*>=\([0-9.]*\).*/\1/p' <<<"$REQUIREMENT")"
[ -n "$LOWEST" ] || { echo "zenoh_lowest.sh: no lower bound in $REQUIREMENT" >&2; exit 1; }

VENV="$(mktemp -d)/venv"
trap 'rm -rf "$(dirname "$VENV")"' EXIT
python3 -m venv --system-site-packages "$VENV"
# pip's log goes to a file: the machine's index configuration makes it print a warning per name.
"$VENV/bin/python" -m pip install --only-binary :all: "eclipse-zenoh==$LOWEST" >"$VENV/pip.log" 2>&1 \
  || { tail -20 "$VENV/pip.log" >&2; echo "zenoh_lowest.sh: cannot install eclipse-zenoh==$LOWEST" >&2; exit 1; }
GOT="$("$VENV/bin/python" -c 'from importlib.metadata import version; print(version("eclipse-zenoh"))')"
[ "$GOT" = "$LOWEST" ] || { echo "zenoh_lowest.sh: got eclipse-zenoh $GOT, wanted $LOWEST" >&2; exit 1; }
echo "=== interop subset on eclipse-zenoh $GOT (allowed: $REQUIREMENT)"
PYTHONPATH="$PWD" "$VENV/bin/python" -m pytest -q -p no:cacheprovider -m "not rclpy" \
  test/runtime/test_runtime_wire.py test/runtime/test_runtime_multiprocess.py \
  test/runtime/test_zenoh_security.py test/nodes/test_tf_broadcasts.py
