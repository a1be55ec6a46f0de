"""ROS 2 launch: the model node with the package's parameter file.

``ros2 launch tdcm_ros model.launch.py [params_file:=/path/to/params.yaml] [tension:=/bench/tension]
[namespace:=/robot1] [use_sim_time:=true] [frame_prefix:=robot1/]``

``tension`` remaps the node's input (a relative name, ``tension`` by default) to another topic.
"""

from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    """The model node, parameters from ``params_file``, input remapped to ``tension``."""
    default_params = PathJoinSubstitution([FindPackageShare("tdcm_ros"), "config",
                                           "model_node.yaml"])
    # launch_ros reads use_sim_time as YAML; frame_prefix stays a string ('' included)
    common = {"use_sim_time": LaunchConfiguration("use_sim_time"),
              "frame_prefix": ParameterValue(LaunchConfiguration("frame_prefix"), value_type=str)}
    return LaunchDescription([
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="true: every node takes its time from /clock"),
        DeclareLaunchArgument("frame_prefix", default_value="",
                              description="put before every TF frame of this robot, e.g. robot1/"),
        DeclareLaunchArgument("namespace", default_value="", description="node namespace"),
        DeclareLaunchArgument("params_file", default_value=default_params,
                              description="ROS 2 parameter YAML for model_node"),
        DeclareLaunchArgument("tension", default_value="tension",
                              description="topic of the tendon tension (WrenchStamped)"),
        Node(package="tdcm_ros", executable="model_node", name="model_node",
             namespace=LaunchConfiguration("namespace"),
             parameters=[LaunchConfiguration("params_file"), common],
             remappings=[("tension", LaunchConfiguration("tension"))], output="screen"),
    ])
