"""Device constants shared by the protocol, the device twin and the driver.

This is the one Python place for them; the firmware's twin of this file is
``firmware/tdcm_tension/config.h`` and ``test_constants_match`` in
``test/firmware/test_firmware_core.py`` checks that the
two agree. Names carry their unit: ``_MS`` milliseconds, ``_MN`` millinewtons, ``_US``
microseconds of servo pulse, ``_MRAD`` milliradians. The control loop works in these integer units
on both sides so the twin and the firmware compute bit-identical results.
"""

from __future__ import annotations

PROTOCOL_VERSION = 1          #: version field of every frame
BAUD_RATE = 115200            #: serial line rate, 8N1
MAX_LINE = 80                 #: longest frame, from '$' through the checksum, without '\n'
FIRMWARE_VERSION = "0.1.0"    #: reported in the banner

CONTROL_PERIOD_MS = 20        #: control tick and telemetry period (50 Hz)
WATCHDOG_MS = 500             #: host silence that releases the tendon while tensioning
SENSOR_TIMEOUT_MS = 250       #: load-cell silence that raises the SENSOR fault

SETPOINT_MAX_MN = 22000       #: largest setpoint the device accepts
TRIP_MN = 25000               #: over-tension trip threshold
TENSION_LIMIT_MN = 999999     #: reported tension is clamped to +-this

PULSE_MIN_US = 1000           #: pulse clamp, low end
PULSE_MAX_US = 2000           #: pulse clamp, high end
PULSE_RELEASE_US = 1000       #: pulse that slackens the tendon
SLEW_US_PER_TICK = 20         #: pulse slew limit per control tick (1000 us/s)

KP_US_PER_N = 5               #: proportional gain, us of pulse per N of error
KI_US_PER_NS = 100            #: integral gain, us of pulse per N of error per second
INTEGRAL_LIMIT_MUS = (PULSE_MAX_US - PULSE_MIN_US) * 1000  #: |integral| clamp, in 1e-3 us

SCALE_MIN_MCPN = 1000         #: calibration scale range, in 1e-3 counts per N
SCALE_MAX_MCPN = 2_000_000_000
CAL_LOAD_MIN_MN = 100         #: known load accepted by the calibrate command
CAL_LOAD_MAX_MN = 100000
DEFAULT_TARE = 0              #: used when the EEPROM record is invalid (CAL fault set)
DEFAULT_SCALE_MCPN = 1_000_000

ROLL_MAX_MRAD = 1571          #: |roll| the R command accepts, in mrad (pi/2 rounded up)
ROLL_SLEW_MRAD_PER_TICK = 40  #: roll slew limit per control tick, in mrad (2 rad/s)
ROLL_PULSE_CENTER_US = 1500   #: roll servo pulse at 0 rad (the boot position)
ROLL_US_PER_RAD = 637         #: roll servo gain: 2000 us over pi rad (500..2500 us = -pi/2..pi/2)
ROLL_PULSE_MIN_US = 500       #: roll servo pulse clamp, low end
ROLL_PULSE_MAX_US = 2500      #: roll servo pulse clamp, high end

EEPROM_MAGIC = 0x7D01         #: first two bytes of the calibration record
EEPROM_RECORD_SIZE = 11       #: magic u16 + tare i32 + scale i32 + crc8, little endian
