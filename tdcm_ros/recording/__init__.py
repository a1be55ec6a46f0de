"""Recording a live graph (embedded zenoh or rclpy) into rosbag2 MCAP bags (``tdcm record``)."""

from tdcm_ros.recording.recorder import Recorder

__all__ = ["Recorder"]
