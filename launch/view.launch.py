"""ROS 2 launch: see the body: robot_state_publisher with the body's URDF, and RViz.

``ros2 launch tdcm_ros view.launch.py [rviz:=true] [params_file:=...] [namespace:=/robot1]
[frame_prefix:=robot1/] [use_sim_time:=true] [rviz_config:=...]``

Beside a running bench (``tdcm up --runtime rclpy --twin``, ``bench.launch.py``, or
``bench.launch.py rviz:=true``, which includes this file): robot_state_publisher's
``robot_description`` is the body model_node models under ``params_file`` (``tdcm urdf --params``:
its ``design.file`` or ``design.preset`` and ``design.*`` values), and it turns model_node's
``joint_states`` into the body's TF; RViz opens ``config/rviz/tdcm.rviz`` (the body, midline,
markers, tip frame and diagnostics). Give the same ``namespace`` and ``frame_prefix`` as the
bench's.
"""

from typing import Any

from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription


def _robot_state_publisher(context: Any) -> list[Node]:
    """robot_state_publisher with the URDF of model_node's design under ``params_file``."""
    from tdcm_ros.cli.urdf import node_design
    from tdcm_ros.model import body_urdf

    values = context.launch_configurations
    namespace = values["namespace"].strip("/")
    node = f"/{namespace}/model_node" if namespace else "/model_node"
    description = body_urdf(node_design(values["params_file"], node))
    return [Node(package="robot_state_publisher", executable="robot_state_publisher",
                 name="robot_state_publisher", namespace=values["namespace"], output="screen",
                 parameters=[{"robot_description": ParameterValue(description, value_type=str),
                              "frame_prefix": ParameterValue(values["frame_prefix"],
                                                             value_type=str),
                              "use_sim_time": values["use_sim_time"]}])]


def generate_launch_description() -> LaunchDescription:
    """robot_state_publisher and, with ``rviz``, RViz with the package's configuration."""
    share = FindPackageShare("tdcm_ros")
    return LaunchDescription([
        DeclareLaunchArgument("rviz", default_value="true", choices=["true", "false"],
                              description="true: open RViz with rviz_config"),
        DeclareLaunchArgument("rviz_config",
                              default_value=PathJoinSubstitution([share, "config", "rviz",
                                                                  "tdcm.rviz"]),
                              description="RViz configuration file"),
        DeclareLaunchArgument("params_file",
                              default_value=PathJoinSubstitution([share, "config",
                                                                  "model_node.yaml"]),
                              description="model_node's parameter file: the body drawn is its "
                                          "design"),
        DeclareLaunchArgument("namespace", default_value="",
                              description="the bench's namespace (model_node's joint_states)"),
        DeclareLaunchArgument("frame_prefix", default_value="",
                              description="the bench's TF frame prefix, e.g. robot1/"),
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="true: take the time from /clock"),
        OpaqueFunction(function=_robot_state_publisher),
        Node(package="rviz2", executable="rviz2", name="rviz2", output="screen",
             arguments=["-d", LaunchConfiguration("rviz_config")],
             parameters=[{"use_sim_time": LaunchConfiguration("use_sim_time")}],
             condition=IfCondition(LaunchConfiguration("rviz"))),
    ])
