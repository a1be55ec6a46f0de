// Tension device core: protocol handling, the PI tension loop and the roll servo slew. Plain C++11, no Arduino
// headers; the sketch and the host harness (firmware/host/sim_main.cpp) both drive it.
// Python twin: tdcm_ros/device/core.py (same integer arithmetic, same decisions).
#ifndef TDCM_TENSION_CORE_H
#define TDCM_TENSION_CORE_H

#include <stdint.h>

#include "config.h"
#include "protocol.h"

namespace tdcm {

enum Fault : uint8_t {
  F_OVER_TENSION = 0x01, F_WATCHDOG = 0x02, F_ESTOP = 0x04, F_SENSOR = 0x08, F_CALIBRATION = 0x10
};
constexpr uint8_t TRIP_FAULTS = F_OVER_TENSION | F_WATCHDOG | F_ESTOP | F_SENSOR;

// Non-volatile calibration record (EEPROM on the UNO, RAM in host tests).
class Storage {
 public:
  virtual void read(uint8_t* data, uint8_t size) = 0;
  virtual void write(const uint8_t* data, uint8_t size) = 0;
};

// Where the device's lines go (each ends with '\n').
class LineSink {
 public:
  virtual void send(const char* text, uint8_t size) = 0;
};

uint8_t crc8(const uint8_t* data, uint8_t size);  // poly 0x07, init 0
void pack_calibration(int32_t tare, int32_t scale_mcpn, uint8_t* record);
bool unpack_calibration(const uint8_t* record, int32_t& tare, int32_t& scale_mcpn);

class TensionCore {
 public:
  TensionCore(Storage& storage, LineSink& sink, const char* cell)
      : storage_(storage), sink_(sink), cell_(cell) {}
  void boot(uint32_t now_ms);                 // load calibration, send the banner
  void receive(uint8_t byte, uint32_t now_ms);
  void sample(int32_t raw, uint32_t now_ms);  // a fresh load-cell reading (counts)
  void tick(uint32_t now_ms);                 // call often; controls every period
  uint16_t pulse_us() const { return (uint16_t)pulse_us_; }
  uint16_t roll_pulse_us() const;             // roll servo pulse for the current roll

 private:
  void banner();
  void release();
  void ack(char letter);
  void nack(char letter, Reject reason);
  void execute(const Command& command);
  void control();
  void roll();
  void emit();

  Storage& storage_;
  LineSink& sink_;
  const char* cell_;
  Framer framer_;
  Writer writer_;
  char mode_ = 'R';
  uint8_t faults_ = 0;
  bool have_sample_ = false;
  int32_t setpoint_mn_ = 0;
  int32_t pulse_us_ = PULSE_RELEASE_US;
  int32_t integral_mus_ = 0;
  int32_t raw_ = 0;
  int32_t tension_mn_ = 0;
  int32_t roll_target_mrad_ = 0;  // where the roll servo is going
  int32_t roll_mrad_ = 0;         // where its pulse points now (slew-limited)
  bool roll_engaged_ = false;     // an R was accepted since boot: J frames follow every T
  int32_t tare_ = DEFAULT_TARE;
  int32_t scale_mcpn_ = DEFAULT_SCALE_MCPN;
  uint32_t sample_ms_ = 0;
  uint32_t last_rx_ms_ = 0;
  uint32_t last_control_ms_ = 0;
};

}  // namespace tdcm

#endif
