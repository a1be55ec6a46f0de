"""ROS 2 launch: the tension driver on a real serial port, and the model node fed by it.

``ros2 launch tdcm_ros tension.launch.py [port:=/dev/ttyACM0] [params_file:=...]
[model_params_file:=...] [namespace:=/robot1] [use_sim_time:=true] [frame_prefix:=robot1/]``

This opens the real device (an Arduino UNO running ``firmware/tdcm_tension``). Without hardware
use ``tdcm up --twin`` (embedded runtime) or run the ``device_twin`` node and point ``port`` at
its link.
"""

from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    """tension_driver (``port`` overrides the file) and model_node."""
    config = [FindPackageShare("tdcm_ros"), "config"]
    # launch_ros reads use_sim_time as YAML; frame_prefix stays a string ('' included)
    common = {"use_sim_time": LaunchConfiguration("use_sim_time"),
              "frame_prefix": ParameterValue(LaunchConfiguration("frame_prefix"), value_type=str)}
    return LaunchDescription([
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="true: every node takes its time from /clock"),
        DeclareLaunchArgument("frame_prefix", default_value="",
                              description="put before every TF frame of this robot, e.g. robot1/"),
        DeclareLaunchArgument("namespace", default_value="", description="node namespace"),
        DeclareLaunchArgument("port", default_value="/dev/ttyACM0",
                              description="serial device, pty path or pyserial URL"),
        DeclareLaunchArgument("params_file",
                              default_value=PathJoinSubstitution([*config, "tension_driver.yaml"]),
                              description="ROS 2 parameter YAML for tension_driver"),
        DeclareLaunchArgument("model_params_file",
                              default_value=PathJoinSubstitution([*config, "model_node.yaml"]),
                              description="ROS 2 parameter YAML for model_node"),
        Node(package="tdcm_ros", executable="tension_driver", name="tension_driver",
             namespace=LaunchConfiguration("namespace"),
             parameters=[LaunchConfiguration("params_file"),
                         {"port": LaunchConfiguration("port")}, common],
             output="screen"),
        Node(package="tdcm_ros", executable="model_node", name="model_node",
             namespace=LaunchConfiguration("namespace"),
             parameters=[LaunchConfiguration("model_params_file"), common], output="screen"),
    ])
