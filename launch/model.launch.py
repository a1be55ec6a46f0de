"""ROS 2 launch: the model node with the package's parameter file.

``ros2 launch tdcm_ros model.launch.py [params_file:=/path/to/params.yaml]``
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    """The model node, parameters from ``params_file``."""
    default_params = os.path.join(get_package_share_directory("tdcm_ros"), "config",
                                  "model_node.yaml")
    params = LaunchConfiguration("params_file")
    return LaunchDescription([
        DeclareLaunchArgument("params_file", default_value=default_params,
                              description="ROS 2 parameter YAML for model_node"),
        Node(package="tdcm_ros", executable="model_node", name="model_node",
             parameters=[params], output="screen"),
    ])
