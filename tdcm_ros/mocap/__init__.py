"""ROS-free motion capture: Vicon Nexus CSV reading, labelling, occlusion, sources, and the
registration of the ``mocap`` frame to ``tdcm_base``, and a TF buffer (lookups between frames
at a stamp).

Never imports rclpy; ``tdcm_ros.nodes.mocap_node`` puts it on a runtime.
"""

from tdcm_ros.mocap.errors import CsvFormatError, LabelError, MocapError
from tdcm_ros.mocap.labelling import (
    ArcLengthLabeller,
    LabelledFrame,
    Labeller,
    NameLabeller,
    NameMap,
    project_on_polyline,
    straight_axis,
)
from tdcm_ros.mocap.nexus_csv import Trajectories, parse_nexus_csv, read_nexus_csv
from tdcm_ros.mocap.occlusion import visible
from tdcm_ros.mocap.register import estimate_from_recordings, given_registration
from tdcm_ros.mocap.registration import (
    Registration,
    RegistrationError,
    estimate_registration,
)
from tdcm_ros.mocap.sources import CsvReplay, RawFrame, SimSource, SourceError
from tdcm_ros.mocap.tf_buffer import (
    ExtrapolationError,
    TransformBuffer,
    TransformLookupError,
)
from tdcm_ros.mocap.truth import FrameClock, TruthTrack

__all__ = [
    "ArcLengthLabeller",
    "CsvFormatError",
    "CsvReplay",
    "ExtrapolationError",
    "FrameClock",
    "LabelError",
    "LabelledFrame",
    "Labeller",
    "MocapError",
    "NameLabeller",
    "NameMap",
    "RawFrame",
    "Registration",
    "RegistrationError",
    "SimSource",
    "SourceError",
    "Trajectories",
    "TransformBuffer",
    "TransformLookupError",
    "TruthTrack",
    "estimate_from_recordings",
    "estimate_registration",
    "given_registration",
    "parse_nexus_csv",
    "project_on_polyline",
    "read_nexus_csv",
    "straight_axis",
    "visible",
]
