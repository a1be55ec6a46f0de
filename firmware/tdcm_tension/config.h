// Device constants: the one firmware place for them.
// Python mirror: tdcm_ros/device/constants.py (test_constants_match in
// test/firmware/test_firmware_core.py checks
// that every value below equals its Python twin). Units are in the names: _MS milliseconds,
// _MN millinewtons, _US microseconds of servo pulse, _MUS 1e-3 us, _MCPN 1e-3 counts per N.
#ifndef TDCM_CONFIG_H
#define TDCM_CONFIG_H

#include <stdint.h>

namespace tdcm {

constexpr int32_t PROTOCOL_VERSION = 1;
constexpr int32_t BAUD_RATE = 115200;
constexpr int32_t MAX_LINE = 80;            // '$' through checksum, '\n' excluded
#define TDCM_FIRMWARE_VERSION "0.1.0"

constexpr int32_t CONTROL_PERIOD_MS = 20;   // control tick + telemetry (50 Hz)
constexpr int32_t WATCHDOG_MS = 500;        // host silence that releases while tensioning
constexpr int32_t SENSOR_TIMEOUT_MS = 250;  // load-cell silence -> SENSOR fault

constexpr int32_t SETPOINT_MAX_MN = 22000;
constexpr int32_t TRIP_MN = 25000;          // over-tension trip
constexpr int32_t TENSION_LIMIT_MN = 999999;

constexpr int32_t PULSE_MIN_US = 1000;
constexpr int32_t PULSE_MAX_US = 2000;
constexpr int32_t PULSE_RELEASE_US = 1000;
constexpr int32_t SLEW_US_PER_TICK = 20;

constexpr int32_t KP_US_PER_N = 5;
constexpr int32_t KI_US_PER_NS = 100;
constexpr int32_t INTEGRAL_LIMIT_MUS = (PULSE_MAX_US - PULSE_MIN_US) * 1000;

constexpr int32_t SCALE_MIN_MCPN = 1000;
constexpr int32_t SCALE_MAX_MCPN = 2000000000;
constexpr int32_t CAL_LOAD_MIN_MN = 100;
constexpr int32_t CAL_LOAD_MAX_MN = 100000;
constexpr int32_t DEFAULT_TARE = 0;
constexpr int32_t DEFAULT_SCALE_MCPN = 1000000;

// Roll servo (hobby servo, direct drive): 1500 us = 0 rad, 637 us/rad (2000 us over pi rad, so
// 500..2500 us spans -pi/2..pi/2); _MRAD milliradians.
constexpr int32_t ROLL_MAX_MRAD = 1571;            // |roll| the R command accepts (pi/2, rounded up)
constexpr int32_t ROLL_SLEW_MRAD_PER_TICK = 40;    // roll slew limit per control tick (2 rad/s)
constexpr int32_t ROLL_PULSE_CENTER_US = 1500;     // pulse at 0 rad (the boot position)
constexpr int32_t ROLL_US_PER_RAD = 637;
constexpr int32_t ROLL_PULSE_MIN_US = 500;
constexpr int32_t ROLL_PULSE_MAX_US = 2500;

constexpr int32_t EEPROM_MAGIC = 0x7D01;
constexpr int32_t EEPROM_RECORD_SIZE = 11;  // magic u16, tare i32, scale i32, crc8 (LE)

// error * KI * period must fit in int32 for every error the loop can see.
static_assert((int64_t)(SETPOINT_MAX_MN + TENSION_LIMIT_MN) * KI_US_PER_NS * CONTROL_PERIOD_MS
                  < INT32_MAX, "integral increment overflows int32");

}  // namespace tdcm

#endif
