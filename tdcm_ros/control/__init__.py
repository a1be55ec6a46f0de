"""ROS-free core of the ``shape_controller`` node (never imports rclpy or zenoh): targets in
``tdcm_base`` resolved to a roll and an in-plane target, the inverse model's feed-forward, the
measured tip from motion capture, an on-line estimate of the effective stiffness, the driver's
limits (its TF buffer is :class:`tdcm_ros.mocap.TransformBuffer`).
"""

from tdcm_ros.control.controller import (
    DEFAULT_ADAPT_MIN_N,
    DEFAULT_TOLERANCE_M,
    MODES,
    Observation,
    Resolved,
    ShapeController,
)
from tdcm_ros.control.errors import TargetRefusedError
from tdcm_ros.control.estimator import GainEstimator, GainSettings, ModelTip
from tdcm_ros.control.limits import DRIVER_LIMIT_NAMES, DriverLimits, clamp, slew
from tdcm_ros.control.measured import marker_to_tip, measured_tip
from tdcm_ros.control.simulation import TrackingRun, simulate_tracking
from tdcm_ros.control.target import (
    AXIS_EPS_M,
    PlaneTarget,
    angle_target,
    check_roll,
    in_plane,
    point_target,
    rotate_z,
)

__all__ = [
    "AXIS_EPS_M",
    "DEFAULT_ADAPT_MIN_N",
    "DEFAULT_TOLERANCE_M",
    "DRIVER_LIMIT_NAMES",
    "MODES",
    "DriverLimits",
    "GainEstimator",
    "GainSettings",
    "ModelTip",
    "Observation",
    "PlaneTarget",
    "Resolved",
    "ShapeController",
    "TargetRefusedError",
    "TrackingRun",
    "angle_target",
    "check_roll",
    "clamp",
    "in_plane",
    "marker_to_tip",
    "measured_tip",
    "point_target",
    "rotate_z",
    "simulate_tracking",
    "slew",
]
