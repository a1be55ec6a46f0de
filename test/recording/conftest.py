"""The player tests run on the multi-process fixtures of test/runtime's :mod:`graph_fixtures`."""

from graph_fixtures import (  # noqa: F401 - fixtures are found by name in a conftest
    context,
    graph_env,
    params,
    router,
    runtime,
    spawn,
    zenoh_env,
)
