"""ROS 2 launch: the mocap node with the package's parameter file.

``ros2 launch tdcm_ros mocap.launch.py [params_file:=/path/to/params.yaml] [namespace:=/tdcm]``
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    """The mocap node, parameters from ``params_file``, in ``namespace``."""
    default_params = os.path.join(get_package_share_directory("tdcm_ros"), "config",
                                  "mocap_node.yaml")
    return LaunchDescription([
        DeclareLaunchArgument("params_file", default_value=default_params,
                              description="ROS 2 parameter YAML for mocap_node"),
        DeclareLaunchArgument("namespace", default_value="",
                              description="node namespace (e.g. to keep a driver's /markers "
                                          "apart from this node's output)"),
        Node(package="tdcm_ros", executable="mocap_node", name="mocap_node",
             namespace=LaunchConfiguration("namespace"),
             parameters=[LaunchConfiguration("params_file")], output="screen"),
    ])
