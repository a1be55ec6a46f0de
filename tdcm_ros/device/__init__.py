"""Tension device: serial protocol, device twin, transports and the driver core (ROS-free).

- :mod:`.protocol` -- the versioned, checksummed line protocol (pure encode/decode, framing);
- :mod:`.core`, :mod:`.plant`, :mod:`.twin` -- the firmware's logic in Python on a simulated bench,
  served behind a pty;
- :mod:`.transport` -- serial devices, ptys and pyserial URLs;
- :mod:`.schedule`, :mod:`.driver` -- the transport-free logic of the ``tension_driver`` node.
"""

from tdcm_ros.device.errors import (
    DeviceError,
    FrameError,
    PortError,
    ProtocolVersionError,
)

__all__ = ["DeviceError", "FrameError", "PortError", "ProtocolVersionError"]
