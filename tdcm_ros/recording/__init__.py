"""Recording the embedded (zenoh) graph into rosbag2 MCAP bags (``tdcm record``)."""

from tdcm_ros.recording.recorder import Recorder

__all__ = ["Recorder"]
