"""``tdcm foxglove``: a Foxglove client (the WebSocket protocol the app speaks, ``foxglove.sdk.v1``)
sees the bench's topics advertised with their ROS 2 schemas, subscribes to one and decodes the
CDR it receives as the message a peer published on the embedded runtime's graph."""

from __future__ import annotations

import json
import struct
from typing import Any

import pytest

from tdcm_ros.bagio import deserialize, from_dict, message_definition
from tdcm_ros.runtime import QoS
from test.support.processes import free_port, listening
from test.support.waiting import eventually

pytestmark = pytest.mark.process


def test_a_foxglove_client_receives_a_published_tip_pose(context: Any, spawn: Any) -> None:
    from websockets.sync import client as websockets_client  # the test extra's

    port = free_port()
    spawn("tdcm_ros", "foxglove", "--port", str(port), "--topics", "/tip_pose,/tf")
    eventually(lambda: listening(port), 60.0, "tdcm foxglove listening")
    publisher = context.create_port("probe").create_publisher(
        "tip_pose", "geometry_msgs/msg/PoseStamped", QoS(depth=10))
    pose = from_dict("geometry_msgs/msg/PoseStamped", {
        "header": {"stamp": {"sec": 12, "nanosec": 5}, "frame_id": "tdcm_base"},
        "pose": {"position": {"x": 0.012, "z": 0.05}, "orientation": {"w": 1.0}}})
    with websockets_client.connect(f"ws://127.0.0.1:{port}", subprotocols=["foxglove.sdk.v1"],
                                   open_timeout=30) as client:
        channels: dict[str, Any] = {}
        while not channels:  # the bridge makes its channels before it listens: one advertise
            reply = json.loads(client.recv(timeout=30))
            if reply["op"] == "advertise":
                channels.update({c["topic"]: c for c in reply["channels"]})
        assert set(channels) == {"/tip_pose", "/tf"}
        tip = channels["/tip_pose"]
        assert (tip["encoding"], tip["schemaEncoding"]) == ("cdr", "ros2msg")
        assert tip["schema"] == message_definition("geometry_msgs/msg/PoseStamped")
        client.send(json.dumps({"op": "subscribe",
                                "subscriptions": [{"id": 3, "channelId": tip["id"]}]}))

        def received() -> bytes | None:
            publisher.publish(pose)  # until the route exists, a message may go nowhere
            try:
                data = client.recv(timeout=0.5)
            except TimeoutError:
                return None
            return data if isinstance(data, bytes) and data[0] == 1 else None

        data = eventually(received, 60.0, "a tip pose through the bridge")
    subscription, _log_time = struct.unpack("<IQ", data[1:13])
    message = deserialize(data[13:], "geometry_msgs/msg/PoseStamped")
    assert subscription == 3 and message.header.frame_id == "tdcm_base"
    assert (message.pose.position.x, message.pose.position.z) == (0.012, 0.05)


def test_unknown_topics_and_ports_are_refused() -> None:
    from test.support.cli import tdcm

    done = tdcm("foxglove", "--topics", "/nope")
    assert done.returncode == 2 and "--topics" in done.stderr and "/tip_pose" in done.stderr
    done = tdcm("foxglove", "--port", "70000")
    assert done.returncode == 2 and "--port" in done.stderr
