"""The shipped RViz config shows what the nodes publish: every display's topic is one a node
of the package publishes (or robot_state_publisher's description), with the type the display
reads, and the fixed frame is model_node's base frame; setup.py installs it."""

from __future__ import annotations

from pathlib import Path

import yaml

from tdcm_ros.nodes import mocap_node
from tdcm_ros.nodes.model_node import PARAMETERS, ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "config" / "rviz" / "tdcm.rviz"
#: What each RViz display class reads.
READS = {"rviz_default_plugins/Path": "nav_msgs/msg/Path",
         "rviz_default_plugins/MarkerArray": "visualization_msgs/msg/MarkerArray",
         "rviz_default_plugins/Pose": "geometry_msgs/msg/PoseStamped",
         "rviz_default_plugins/PoseArray": "geometry_msgs/msg/PoseArray"}


def published() -> dict[str, str]:
    """``/topic: type`` of everything model_node and mocap_node publish (root namespace)."""
    model = MemoryPort({}, name="model_node")
    ModelNode(model)
    mocap = MemoryPort({"source": "sim"}, name="mocap_node")
    mocap_node.MocapNode(mocap)
    return {"/" + topic.lstrip("/"): publisher.type_name for port in (model, mocap)
            for topic, publisher in port.publishers.items()}


def test_every_display_reads_a_topic_the_nodes_publish_with_its_type() -> None:
    config = yaml.safe_load(CONFIG.read_text())
    manager = config["Visualization Manager"]
    topics = published()
    shown = []
    for display in manager["Displays"]:
        kind = display["Class"]
        if kind in READS:
            topic = display["Topic"]["Value"]
            assert topics.get(topic) == READS[kind], (display["Name"], topic)
            shown.append(topic)
        elif kind == "rviz_default_plugins/RobotModel":
            assert display["Description Topic"]["Value"] == "/robot_description"
    assert {"/midline", "/tip_pose", "/body_markers", "/markers_poses"} <= set(shown)
    assert manager["Global Options"]["Fixed Frame"] == PARAMETERS["frame_id"].default


def test_setup_installs_the_config() -> None:
    assert 'glob("config/rviz/*.rviz")' in (REPO / "setup.py").read_text()
