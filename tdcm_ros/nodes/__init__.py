"""Transport-agnostic node logic; each node is a :class:`tdcm_ros.runtime.NodeLogic`.

Nodes are run, not imported: each module below is its own entry point, started by name through
:data:`tdcm_ros.runtime.NODES` or its console script (``main``). Nothing else in the package
imports them, so this face exports nothing.

- :mod:`.model_node` -- tension in, predicted shape out;
- :mod:`.tension_driver` -- the tension device on a serial line;
- :mod:`.device_twin` -- a simulated device behind a pty;
- :mod:`.mocap_node` -- motion-capture markers (CSV replay, live, simulated);
- :mod:`.metrics_node` -- running Table I metrics;
- :mod:`.shape_controller` -- a tip target in, the driver's setpoints out (feedback from mocap);
- :mod:`.talker` -- a minimal example node;
- :mod:`.shape_messages` -- the ROS messages of a solved shape;
- :mod:`.driver_diagnostics` -- the tension device's components on ``/diagnostics``.
"""

__all__: list[str] = []
