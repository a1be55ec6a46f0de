"""ROS 2 launch: the shape controller beside a running bench (``bench.launch.py`` or ``tdcm up``).

``ros2 launch tdcm_ros controller.launch.py [mode:=feedforward|feedback] [namespace:=/tdcm]``

It commands the ``tension_driver`` of the same namespace (``tension_setpoint``,
``roll_setpoint``) within that driver's limits, once a target arrives on ``target_point`` or
``target_angle``; ``mode`` can also be changed at run time (``tdcm param set``).
"""

from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    """shape_controller with the package's config and the chosen mode."""
    params = PathJoinSubstitution([FindPackageShare("tdcm_ros"), "config",
                                   "shape_controller.yaml"])
    # launch_ros reads use_sim_time as YAML; frame_prefix stays a string ('' included)
    common = {"use_sim_time": LaunchConfiguration("use_sim_time"),
              "frame_prefix": ParameterValue(LaunchConfiguration("frame_prefix"), value_type=str)}
    return LaunchDescription([
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="true: every node takes its time from /clock"),
        DeclareLaunchArgument("frame_prefix", default_value="",
                              description="put before every TF frame of this robot, e.g. robot1/"),
        DeclareLaunchArgument("mode", default_value="feedback",
                              choices=["feedforward", "feedback"],
                              description="feedforward, or feedback from motion capture"),
        DeclareLaunchArgument("namespace", default_value="", description="node namespace"),
        Node(package="tdcm_ros", executable="shape_controller", name="shape_controller",
             namespace=LaunchConfiguration("namespace"), output="screen",
             parameters=[params, {"mode": LaunchConfiguration("mode")}, common]),
    ])
