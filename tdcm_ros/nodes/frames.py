"""``frame_prefix``: one robot's TF frames named apart from another's on the shared ``/tf`` and
``/tf_static`` (robot_state_publisher's parameter of the same name).

Every node that names a frame of the robot (its base, tip, stations, tendon) takes the
read-only parameter ``frame_prefix`` (default ``''``) and puts it before those names:
``frame_prefix: robot1/`` makes ``tdcm_base`` ``robot1/tdcm_base``. The motion-capture frame
(``mocap``) is the room's, shared by every robot in it, and is not prefixed.
"""

from __future__ import annotations

from tdcm_ros.runtime import NodePort, declare_specs, validate_frame_prefix
from tdcm_ros.spec import Spec, by_name

FRAME_PREFIX_SPECS = by_name(Spec(
    "frame_prefix", description="put before every TF frame of this robot (e.g. robot1/: "
    "robot1/tdcm_base); the mocap frame is shared and not prefixed", default="", kind="str"))


def declare_frame_prefix(port: NodePort) -> str:
    """Declare the read-only ``frame_prefix`` and return it, checked."""
    values = declare_specs(port, FRAME_PREFIX_SPECS, read_only=True)
    return validate_frame_prefix(str(values["frame_prefix"]))


def robot_frame(prefix: str, name: str) -> str:
    """The frame ``name`` of the robot with the (checked) ``frame_prefix`` ``prefix``, a leading
    ``/`` of ``name`` dropped as tf2 does."""
    return prefix + name.lstrip("/")
