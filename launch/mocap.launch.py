"""ROS 2 launch: the mocap node, relabelling the live motion-capture driver's markers by default.

``ros2 launch tdcm_ros mocap.launch.py [source:=relabel|csv|sim] [driver_markers:=/vicon/markers]
[params_file:=/path/to/params.yaml] [namespace:=/tdcm]``

A real bench is the default (``source:=relabel``: the driver's ``mocap4r2_msgs/Markers`` in,
labelled ``markers`` out); a simulated bench is asked for explicitly with ``source:=sim`` (a CSV
replay with ``source:=csv``). ``source`` overrides the parameter file. The node's input
``/vicon/markers`` (``relabel.input_topic``) is remapped to ``driver_markers``, e.g.
``driver_markers:=/markers`` for MOCAP4ROS2's Vicon driver (then give this node a ``namespace``
so that its own ``markers`` output does not land on ``/markers`` too).
"""

from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription

#: mocap_node's ``source`` values; the first is the default here.
SOURCES = ["relabel", "csv", "sim"]


def generate_launch_description() -> LaunchDescription:
    """The mocap node with ``source`` over ``params_file``, in ``namespace``."""
    default_params = PathJoinSubstitution([FindPackageShare("tdcm_ros"), "config",
                                           "mocap_node.yaml"])
    # launch_ros reads use_sim_time as YAML; frame_prefix stays a string ('' included)
    common = {"use_sim_time": LaunchConfiguration("use_sim_time"),
              "frame_prefix": ParameterValue(LaunchConfiguration("frame_prefix"), value_type=str)}
    return LaunchDescription([
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="true: every node takes its time from /clock"),
        DeclareLaunchArgument("frame_prefix", default_value="",
                              description="put before every TF frame of this robot, e.g. robot1/"),
        DeclareLaunchArgument("source", default_value=SOURCES[0], choices=SOURCES,
                              description="relabel: the live driver's markers (real bench); "
                                          "csv: a Nexus CSV replay; sim: simulated markers"),
        DeclareLaunchArgument("driver_markers", default_value="/vicon/markers",
                              description="the live driver's Markers topic (source relabel)"),
        DeclareLaunchArgument("params_file", default_value=default_params,
                              description="ROS 2 parameter YAML for mocap_node"),
        DeclareLaunchArgument("namespace", default_value="",
                              description="node namespace (e.g. to keep a driver's /markers "
                                          "apart from this node's output)"),
        Node(package="tdcm_ros", executable="mocap_node", name="mocap_node",
             namespace=LaunchConfiguration("namespace"),
             parameters=[LaunchConfiguration("params_file"),
                         {"source": LaunchConfiguration("source")}, common],
             remappings=[("/vicon/markers", LaunchConfiguration("driver_markers"))],
             output="screen"),
    ])
