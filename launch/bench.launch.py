"""ROS 2 launch: the real bench: tension driver, model, mocap relabelling and live metrics.

``ros2 launch tdcm_ros bench.launch.py port:=/dev/ttyACM0 [namespace:=/tdcm]``

The Vicon driver (e.g. MOCAP4ROS2's) publishes ``/vicon/markers``; ``mocap_node`` relabels them
(``config/mocap_node.yaml``) into ``markers`` for ``metrics_node``.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    """tension_driver, model_node, mocap_node and metrics_node with the package's configs."""
    config = os.path.join(get_package_share_directory("tdcm_ros"), "config")
    namespace = LaunchConfiguration("namespace")

    def params(name: str) -> str:
        return os.path.join(config, f"{name}.yaml")

    return LaunchDescription([
        DeclareLaunchArgument("port", default_value="/dev/ttyACM0",
                              description="serial port of the tension device"),
        DeclareLaunchArgument("namespace", default_value="", description="node namespace"),
        Node(package="tdcm_ros", executable="tension_driver", name="tension_driver",
             namespace=namespace, output="screen",
             parameters=[params("tension_driver"), {"port": LaunchConfiguration("port")}]),
        Node(package="tdcm_ros", executable="model_node", name="model_node",
             namespace=namespace, output="screen", parameters=[params("model_node")]),
        Node(package="tdcm_ros", executable="mocap_node", name="mocap_node",
             namespace=namespace, output="screen",
             parameters=[params("mocap_node"), {"source": "relabel"}]),
        Node(package="tdcm_ros", executable="metrics_node", name="metrics_node",
             namespace=namespace, output="screen", parameters=[params("metrics_node")]),
    ])
