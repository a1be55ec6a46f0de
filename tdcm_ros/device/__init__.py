"""Tension device: serial protocol, device twin, transports and the driver core (ROS-free).

- :mod:`.protocol` -- the versioned, checksummed line protocol (pure encode/decode, framing);
- :mod:`.core`, :mod:`.plant`, :mod:`.twin` -- the firmware's logic in Python on a simulated bench,
  served behind a pty;
- :mod:`.transport` -- serial devices, ptys and pyserial URLs (:class:`Transport`, what the
  driver needs of a port);
- :mod:`.schedule`, :mod:`.driver` -- the transport-free logic of the ``tension_driver`` node.

Separate entry points, kept out of this face: the scripts :mod:`.twin` (``python -m
tdcm_ros.device.twin``: ``DeviceTwin``, ``PtyTwin``) and :mod:`.transcript`, :mod:`.loopback`
(an in-process cable from the driver to a ``DeviceTwin``, for tests), and
:mod:`.constants` (the firmware's constants, used as a namespace).
"""

from tdcm_ros.device.clock_map import DeviceClockMap
from tdcm_ros.device.core import TRIP_FAULTS
from tdcm_ros.device.driver import (
    DRIVER_SPECS,
    DriverConfig,
    DriverStatus,
    Level,
    LinkState,
    TensionDriver,
    fault_names,
)
from tdcm_ros.device.errors import (
    DeviceError,
    FrameError,
    PortError,
    ProtocolVersionError,
)
from tdcm_ros.device.plant import PLANT_SPECS, ROLL_SPEED, PlantConfig
from tdcm_ros.device.protocol import (
    Fault,
    Heartbeat,
    Mode,
    RollState,
    SetMode,
    SetRoll,
    SetSetpoint,
    Telemetry,
    decode,
    encode,
)
from tdcm_ros.device.schedule import SCHEDULE_SPECS, StepSchedule
from tdcm_ros.device.transport import Transport

__all__ = [
    "DRIVER_SPECS",
    "PLANT_SPECS",
    "ROLL_SPEED",
    "SCHEDULE_SPECS",
    "TRIP_FAULTS",
    "DeviceClockMap",
    "DeviceError",
    "DriverConfig",
    "DriverStatus",
    "Fault",
    "FrameError",
    "Heartbeat",
    "Level",
    "LinkState",
    "Mode",
    "PlantConfig",
    "PortError",
    "ProtocolVersionError",
    "RollState",
    "SetMode",
    "SetRoll",
    "SetSetpoint",
    "StepSchedule",
    "Telemetry",
    "TensionDriver",
    "Transport",
    "decode",
    "encode",
    "fault_names",
]
