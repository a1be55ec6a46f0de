"""The multi-process fixtures of :mod:`graph_fixtures` for the runtime tests."""

from graph_fixtures import (  # noqa: F401 - fixtures are found by name in a conftest
    context,
    graph_env,
    params,
    router,
    runtime,
    spawn,
    zenoh_env,
)
