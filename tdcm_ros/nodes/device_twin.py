"""``device_twin``: the simulated tension device (firmware logic on a simulated bench) on a pty.

Serves :class:`tdcm_ros.device.twin.PtyTwin` in real time (times ``speed``) behind the symlink
``link`` (default ``<tmp>/tdcm_twin_<pid>``), which ``tension_driver`` opens as its ``port``.
The plant is :class:`tdcm_ros.device.plant.PlantConfig` from the ``plant.<field>`` parameters;
with ``scene`` set (a shipped scene name or a YAML path) their defaults come from
``load_scene(scene).plant_config()`` and explicit ``plant.*`` values still override them, and the
scene's ``latency`` effect delays every line the device sends by its ``tension`` delay.

Publishes ``sim/tension_true`` (``geometry_msgs/msg/WrenchStamped``): the true tendon tension
(N, ``wrench.force.z``, frame ``frame_id`` after ``frame_prefix``) at every load-cell sample, stamped with the host time
of the sample; ``sim/joint_states_true`` (``sensor_msgs/msg/JointState``, name ``["roll"]``): the
simulated roll servo's true angle (rad) at the same samples and stamps; and ``/diagnostics``
(port, simulated time, device mode, faults, roll, and how the simulation kept up: ``sim_late_turns``
counts turns of the twin's thread more than ``LATE_TURN_S`` late, caught up with the host's bytes
spread over the gap; ``sim_pauses``/``sim_paused_s`` the gaps over ``MAX_GAP`` s, whose rest paused
simulated time, see :class:`~tdcm_ros.device.twin.PtyTwin`).
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Callable
from dataclasses import asdict

from tdcm_ros.bagio import from_dict
from tdcm_ros.device import PLANT_SPECS, ROLL_SPEED, PlantConfig, fault_names
from tdcm_ros.device.twin import LATE_TURN_S, TRUTH_DEPTH, DeviceTwin, PtyTwin
from tdcm_ros.errors import InputError
from tdcm_ros.nodes.frames import FRAME_PREFIX_SPECS, declare_frame_prefix, robot_frame
from tdcm_ros.nodes.joint_messages import JOINT_STATE, joint_state
from tdcm_ros.nodes.shape_messages import header
from tdcm_ros.runtime import (
    DiagnosticLevel,
    Diagnostics,
    NodeLogic,
    NodePort,
    QoS,
    Status,
    declare_specs,
    grouped,
)
from tdcm_ros.runtime.run_node import main_for
from tdcm_ros.spec import Spec, by_name

#: Parameters of the node besides the plant group (all fixed at start).
TWIN_SPECS = by_name(
    Spec("scene", description="scene name or YAML path giving the plant (optional)", default="",
         kind="str"),
    Spec("link", description="symlink to the pty (empty: <tmp>/tdcm_twin_<pid>)", default="",
         kind="str"),
    Spec("speed", description="simulated time / real time", default=1.0, low=0.01, high=100.0),
    Spec("roll_speed", "rad/s", "roll servo speed limit", ROLL_SPEED, low=0.01, high=100.0),
    Spec("frame_id", description="frame of sim/tension_true", default="tdcm_tendon", kind="str"),
    Spec("publish_period_s", "s", "how often the samples are published; every load-cell sample "
         "is published", 0.01, low=0.001, high=1.0),
    Spec("diagnostics_period_s", "s", "/diagnostics period", 1.0, low=0.05, high=60.0))

#: Every parameter of the node by full name, as declared below (parameter files are checked
#: against it).
PARAMETERS = {**grouped(TWIN_SPECS), **grouped(FRAME_PREFIX_SPECS),
              **grouped(PLANT_SPECS, "plant.")}


def scene_bench(scene: str) -> tuple[PlantConfig, Callable[[], float]]:
    """A scene's plant and its serial-line latency (s per line, the ``latency`` effect's
    ``tension`` delay; 0 without it). Imported lazily: scenes are optional for this node."""
    try:
        from tdcm_ros.scenes import load_scene
    except ImportError as error:
        raise InputError(f"scene = {scene!r} needs tdcm_ros.scenes, which cannot be imported: "
                         f"{error}", parameter="scene", value=scene) from error
    loaded = load_scene(scene)
    config = loaded.plant_config()
    if not isinstance(config, PlantConfig):
        raise InputError(f"scene = {scene!r} gave a {type(config).__name__}, not a PlantConfig",
                         parameter="scene", value=scene)
    world = loaded.world()
    return config, lambda: world.delay_s("tension")


def default_link() -> str:
    """``<tmp>/tdcm_twin_<pid>``: unique per process."""
    return os.path.join(tempfile.gettempdir(), f"tdcm_twin_{os.getpid()}")


def check_link(path: str) -> None:
    """Refuse to replace anything but a symlink (or nothing) at ``path``."""
    if os.path.lexists(path) and not os.path.islink(path):
        raise InputError(f"link = {path!r} exists and is not a symlink; allowed: a new path or "
                         f"an old twin link", parameter="link", value=path,
                         allowed="a path that is absent or a symlink")
    if not os.path.isdir(os.path.dirname(os.path.abspath(path))):
        raise InputError(f"link = {path!r}: its directory does not exist", parameter="link",
                         value=path, allowed="a path in an existing directory")


class DeviceTwinNode(NodeLogic):
    """Serves the device twin on a pty; see the module docstring."""

    default_name = "device_twin"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        own = declare_specs(port, TWIN_SPECS, read_only=True)
        scene = str(own["scene"])
        base, line_delay = scene_bench(scene) if scene.strip() else (PlantConfig(), None)
        values = declare_specs(port, PLANT_SPECS, prefix="plant.", defaults=asdict(base),
                               read_only=True)
        try:
            plant = PlantConfig(**values)
        except InputError as error:
            name = f"plant.{error.parameter}"
            raise InputError(f"{name}: {error}", parameter=name, value=error.value,
                             allowed=error.allowed) from error
        link = str(own["link"]).strip() or default_link()
        check_link(link)
        speed = float(own["speed"])
        self.frame_id = robot_frame(declare_frame_prefix(port), str(own["frame_id"]))
        period = float(own["publish_period_s"])
        diag_period = float(own["diagnostics_period_s"])
        # every sample counts (tdcm_ros.mocap.truth): a reader behind keeps them all
        self.truth = port.create_publisher("sim/tension_true", "geometry_msgs/msg/WrenchStamped",
                                           QoS(depth=TRUTH_DEPTH))
        self.roll_truth = port.create_publisher("sim/joint_states_true", JOINT_STATE,
                                                QoS(depth=TRUTH_DEPTH))
        twin = DeviceTwin(plant, roll_speed=float(own["roll_speed"]))
        self.server = PtyTwin(twin, speed=speed, link=link, line_delay=line_delay).start()
        self.samples = 0
        port.create_timer(period, self.publish_truth)
        self.diagnostics = Diagnostics(port, diag_period)
        self.diagnostics.add("device twin", "tdcm_twin", self.check)
        port.logger.info("device twin on %s -> %s (scene %r, speed %g)", self.server.port,
                         self.server.pty_path, scene or "none", speed)

    def publish_truth(self) -> None:
        """Publish every ground-truth sample taken since the last call."""
        for stamp_ns, tension in self.server.take_truth():
            self.truth.publish(from_dict("geometry_msgs/msg/WrenchStamped", {
                "header": header(stamp_ns, self.frame_id),
                "wrench": {"force": {"z": tension}}}))
            self.samples += 1
        for stamp_ns, roll in self.server.take_roll_truth():
            self.roll_truth.publish(joint_state(stamp_ns, roll))

    def _state(self) -> dict[str, str]:
        twin = self.server.twin
        return {"port": self.server.port, "pty": self.server.pty_path,
                "sim_time": f"{twin.time:.3f}", "mode": twin.core.mode.name.lower(),
                "faults": fault_names(twin.core.faults),
                "setpoint": f"{twin.core.setpoint_mn / 1000:.3f}",
                "tension_true": f"{twin.plant.tension:.3f}", "samples": str(self.samples),
                "roll_target": f"{twin.core.roll_target_mrad / 1000:.3f}",
                "roll_true": f"{twin.plant.roll:.4f}",
                "sim_late_turns": str(self.server.late_turns),
                "sim_pauses": str(self.server.pauses),
                "sim_paused_s": f"{self.server.paused_s:.3f}"}

    def check(self) -> Status:
        """The twin's state for ``/diagnostics`` (always OK: it is a simulation)."""
        state = self._state()
        return Status(DiagnosticLevel.OK, f"serving {state['port']}", state)

    def close(self) -> None:
        """Stop the twin (the pty closes, the link is removed); logs the final device state."""
        self.server.stop()
        state = self._state()
        self.port.logger.info("device twin stopped: mode %s, faults %s, true tension %s N; its "
                              "thread caught up %s late turn(s) (over %g s) and the simulation "
                              "paused %s time(s), %s s in all (gaps over %g s)", state["mode"],
                              state["faults"] or "none", state["tension_true"],
                              state["sim_late_turns"], LATE_TURN_S, state["sim_pauses"],
                              state["sim_paused_s"], self.server.max_gap)


def main() -> int:
    """``ros2 run tdcm_ros device_twin`` / ``device_twin`` console script."""
    return main_for(DeviceTwinNode)


if __name__ == "__main__":
    sys.exit(main())
