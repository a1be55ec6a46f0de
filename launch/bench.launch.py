"""ROS 2 launch: the real bench: tension driver, model, mocap relabelling and live metrics.

``ros2 launch tdcm_ros bench.launch.py port:=/dev/ttyACM0 [driver_markers:=/vicon/markers]
[namespace:=/tdcm] [rviz:=true]``

Every source is real: the tension device on ``port`` and the motion-capture driver's markers
(e.g. MOCAP4ROS2's), which ``mocap_node`` relabels (``config/mocap_node.yaml``) into ``markers``
for ``metrics_node``; the driver's topic is remapped onto the node's input ``/vicon/markers`` by
``driver_markers``. ``rviz:=true`` also starts ``view.launch.py`` (robot_state_publisher with
the body's URDF, and RViz). For a simulated bench use ``mocap.launch.py source:=sim`` or ``tdcm up``.
"""

from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.conditions import IfCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    """tension_driver, model_node, mocap_node and metrics_node with the package's configs."""
    namespace = LaunchConfiguration("namespace")

    def params(name: str) -> PathJoinSubstitution:
        return PathJoinSubstitution([FindPackageShare("tdcm_ros"), "config", f"{name}.yaml"])

    # launch_ros reads use_sim_time as YAML; frame_prefix stays a string ('' included)
    common = {"use_sim_time": LaunchConfiguration("use_sim_time"),
              "frame_prefix": ParameterValue(LaunchConfiguration("frame_prefix"), value_type=str)}
    return LaunchDescription([
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="true: every node takes its time from /clock"),
        DeclareLaunchArgument("frame_prefix", default_value="",
                              description="put before every TF frame of this robot, e.g. robot1/"),
        DeclareLaunchArgument("port", default_value="/dev/ttyACM0",
                              description="serial port of the tension device"),
        DeclareLaunchArgument("driver_markers", default_value="/vicon/markers",
                              description="the motion-capture driver's Markers topic"),
        DeclareLaunchArgument("namespace", default_value="", description="node namespace"),
        DeclareLaunchArgument("rviz", default_value="false", choices=["true", "false"],
                              description="true: also view.launch.py (robot_state_publisher "
                                          "with the body's URDF, and RViz)"),
        Node(package="tdcm_ros", executable="tension_driver", name="tension_driver",
             namespace=namespace, output="screen",
             parameters=[params("tension_driver"), {"port": LaunchConfiguration("port")}, common]),
        Node(package="tdcm_ros", executable="model_node", name="model_node",
             namespace=namespace, output="screen", parameters=[params("model_node"), common]),
        Node(package="tdcm_ros", executable="mocap_node", name="mocap_node",
             namespace=namespace, output="screen",
             parameters=[params("mocap_node"), {"source": "relabel"}, common],
             remappings=[("/vicon/markers", LaunchConfiguration("driver_markers"))]),
        Node(package="tdcm_ros", executable="metrics_node", name="metrics_node",
             namespace=namespace, output="screen", parameters=[params("metrics_node"), common]),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(PathJoinSubstitution(
                [FindPackageShare("tdcm_ros"), "launch", "view.launch.py"])),
            launch_arguments={"params_file": params("model_node"), "namespace": namespace,
                              "frame_prefix": LaunchConfiguration("frame_prefix"),
                              "use_sim_time": LaunchConfiguration("use_sim_time")}.items(),
            condition=IfCondition(LaunchConfiguration("rviz"))),
    ])
