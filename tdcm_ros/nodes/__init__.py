"""Transport-agnostic node logic; each node is a :class:`tdcm_ros.runtime.port.NodeLogic`."""
