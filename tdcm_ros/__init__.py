"""tdcm_ros: shape estimation of notched tendon-driven continuum manipulators (TD-CMs).

The ROS-free core lives in :mod:`tdcm_ros.model`; nodes and runtimes build on it.
"""

__version__ = "0.1.0"
