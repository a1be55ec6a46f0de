"""Recording a live graph (embedded zenoh or rclpy) into rosbag2 MCAP bags (``tdcm record``), and
playing bags back into it (``tdcm bag play``)."""

from tdcm_ros.recording.player import Player, PlayOptions, Progress, parse_remap
from tdcm_ros.recording.recorder import Recorder

__all__ = ["PlayOptions", "Player", "Progress", "Recorder", "parse_remap"]
