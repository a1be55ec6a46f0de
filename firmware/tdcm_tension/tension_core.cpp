#include "tension_core.h"

namespace tdcm {

namespace {

int32_t clamp(int32_t value, int32_t low, int32_t high) {
  return value < low ? low : (value > high ? high : value);
}

void put_le(uint8_t* out, uint32_t value, uint8_t size) {
  for (uint8_t i = 0; i < size; ++i) out[i] = (uint8_t)(value >> (8 * i));
}

uint32_t get_le(const uint8_t* in, uint8_t size) {
  uint32_t value = 0;
  for (uint8_t i = 0; i < size; ++i) value |= (uint32_t)in[i] << (8 * i);
  return value;
}

}  // namespace

uint8_t crc8(const uint8_t* data, uint8_t size) {
  uint8_t crc = 0;
  for (uint8_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (uint8_t bit = 0; bit < 8; ++bit) crc = (crc & 0x80) ? (uint8_t)((crc << 1) ^ 0x07) : (uint8_t)(crc << 1);
  }
  return crc;
}

void pack_calibration(int32_t tare, int32_t scale_mcpn, uint8_t* record) {
  put_le(record, EEPROM_MAGIC, 2);
  put_le(record + 2, (uint32_t)tare, 4);
  put_le(record + 6, (uint32_t)scale_mcpn, 4);
  record[10] = crc8(record, 10);
}

bool unpack_calibration(const uint8_t* record, int32_t& tare, int32_t& scale_mcpn) {
  if (crc8(record, 10) != record[10] || get_le(record, 2) != (uint32_t)EEPROM_MAGIC) return false;
  int32_t scale = (int32_t)get_le(record + 6, 4);
  if (scale < SCALE_MIN_MCPN || scale > SCALE_MAX_MCPN) return false;
  tare = (int32_t)get_le(record + 2, 4);
  scale_mcpn = scale;
  return true;
}

void TensionCore::boot(uint32_t now_ms) {
  uint8_t record[EEPROM_RECORD_SIZE];
  storage_.read(record, EEPROM_RECORD_SIZE);
  if (!unpack_calibration(record, tare_, scale_mcpn_)) faults_ |= F_CALIBRATION;
  sample_ms_ = last_rx_ms_ = last_control_ms_ = now_ms;
  banner();
}

void TensionCore::banner() {
  writer_.start('B');
  writer_.add_text("TDCM");
  writer_.add_text(TDCM_FIRMWARE_VERSION);
  writer_.add_text(cell_);
  writer_.add_int(CONTROL_PERIOD_MS);
  writer_.add_int(WATCHDOG_MS);
  writer_.add_mn(SETPOINT_MAX_MN);
  writer_.add_mn(TRIP_MN);
  writer_.finish();
  sink_.send(writer_.text(), writer_.size());
}

void TensionCore::ack(char letter) {
  writer_.start('A');
  writer_.add_char(letter);
  writer_.finish();
  sink_.send(writer_.text(), writer_.size());
}

void TensionCore::nack(char letter, Reject reason) {
  writer_.start('N');
  writer_.add_char(letter);
  writer_.add_text(reject_name(reason));
  writer_.finish();
  sink_.send(writer_.text(), writer_.size());
}

void TensionCore::release() {
  mode_ = 'R';
  pulse_us_ = PULSE_RELEASE_US;
  integral_mus_ = 0;
}

void TensionCore::sample(int32_t raw, uint32_t now_ms) {
  raw_ = raw;
  have_sample_ = true;
  sample_ms_ = now_ms;
}

void TensionCore::receive(uint8_t byte, uint32_t now_ms) {
  Reject reason = R_NONE;
  Framer::Event event = framer_.push(byte, reason);
  if (event == Framer::REJECTED) {
    nack('?', reason);
  } else if (event == Framer::LINE) {
    Command command;
    char letter;
    reason = decode_command(framer_.line(), framer_.length(), command, letter);
    if (reason != R_NONE) {
      nack(letter, reason);
      return;
    }
    last_rx_ms_ = now_ms;
    execute(command);
  }
}

void TensionCore::execute(const Command& command) {
  char letter = command.type;
  switch (letter) {
    case 'H':
      return;
    case 'I':
      banner();
      return;
    case 'S':
      setpoint_mn_ = command.mn;
      break;
    case 'M':
      if (command.mode == 'T') {
        if (faults_) return nack(letter, R_FAULT);
        if (mode_ == 'R') {
          mode_ = 'T';
          integral_mus_ = 0;
        }
      } else {
        release();
      }
      break;
    case 'R':
      if (faults_ & TRIP_FAULTS) return nack(letter, R_FAULT);
      roll_target_mrad_ = command.mrad;
      roll_engaged_ = true;
      break;
    case 'E':
      release();
      faults_ |= F_ESTOP;
      break;
    case 'C':
      if (tension_mn_ > TRIP_MN) return nack(letter, R_FAULT);
      faults_ &= F_CALIBRATION;
      break;
    default: {  // 'Z' tare, 'K' calibrate
      if (mode_ == 'T') return nack(letter, R_MODE);
      if (!have_sample_ || (faults_ & F_SENSOR)) return nack(letter, R_FAULT);
      if (letter == 'Z') {
        tare_ = raw_;
      } else {
        int64_t scale = ((int64_t)raw_ - tare_) * 1000000 / command.mn;
        if (scale < SCALE_MIN_MCPN || scale > SCALE_MAX_MCPN) return nack(letter, R_RANGE);
        scale_mcpn_ = (int32_t)scale;
        faults_ &= (uint8_t)~F_CALIBRATION;
      }
      uint8_t record[EEPROM_RECORD_SIZE];
      pack_calibration(tare_, scale_mcpn_, record);
      storage_.write(record, EEPROM_RECORD_SIZE);
      break;
    }
  }
  ack(letter);
}

void TensionCore::tick(uint32_t now_ms) {
  if ((uint32_t)(now_ms - last_control_ms_) < (uint32_t)CONTROL_PERIOD_MS) return;
  last_control_ms_ = now_ms;
  int64_t tension = ((int64_t)raw_ - tare_) * 1000000 / scale_mcpn_;
  tension_mn_ = (int32_t)(tension < -TENSION_LIMIT_MN ? -TENSION_LIMIT_MN
                          : (tension > TENSION_LIMIT_MN ? TENSION_LIMIT_MN : tension));
  if ((uint32_t)(now_ms - sample_ms_) > (uint32_t)SENSOR_TIMEOUT_MS) faults_ |= F_SENSOR;
  if (tension_mn_ > TRIP_MN) faults_ |= F_OVER_TENSION;
  if (mode_ == 'T' && (uint32_t)(now_ms - last_rx_ms_) >= (uint32_t)WATCHDOG_MS) faults_ |= F_WATCHDOG;
  if (faults_ & TRIP_FAULTS) {
    release();
    roll_target_mrad_ = roll_mrad_;  // the roll servo holds where it is
  }
  if (mode_ == 'T') control();
  roll();
  emit();
}

void TensionCore::control() {
  int32_t error = setpoint_mn_ - tension_mn_;
  int32_t proportional = error * KP_US_PER_N / 1000;
  int32_t integral = clamp(integral_mus_ + error * (KI_US_PER_NS * CONTROL_PERIOD_MS) / 1000,
                           -INTEGRAL_LIMIT_MUS, INTEGRAL_LIMIT_MUS);
  int32_t wanted = PULSE_RELEASE_US + proportional + integral / 1000;
  int32_t limited = clamp(clamp(wanted, PULSE_MIN_US, PULSE_MAX_US),
                          pulse_us_ - SLEW_US_PER_TICK, pulse_us_ + SLEW_US_PER_TICK);
  if (!((wanted > limited && error > 0) || (wanted < limited && error < 0))) integral_mus_ = integral;
  pulse_us_ = limited;
}

void TensionCore::roll() {
  roll_mrad_ += clamp(roll_target_mrad_ - roll_mrad_, -ROLL_SLEW_MRAD_PER_TICK,
                      ROLL_SLEW_MRAD_PER_TICK);
}

uint16_t TensionCore::roll_pulse_us() const {
  return (uint16_t)clamp(ROLL_PULSE_CENTER_US + roll_mrad_ * ROLL_US_PER_RAD / 1000,
                         ROLL_PULSE_MIN_US, ROLL_PULSE_MAX_US);
}

void TensionCore::emit() {
  writer_.start('T');
  writer_.add_uint(last_control_ms_);
  writer_.add_int(raw_);
  writer_.add_mn(tension_mn_);
  writer_.add_int(pulse_us_);
  writer_.add_char(mode_);
  writer_.add_hex2(faults_);
  writer_.finish();
  sink_.send(writer_.text(), writer_.size());
  if (!roll_engaged_) return;
  writer_.start('J');
  writer_.add_uint(last_control_ms_);
  writer_.add_mn(roll_target_mrad_);
  writer_.add_mn(roll_mrad_);
  writer_.add_int(roll_pulse_us());
  writer_.finish();
  sink_.send(writer_.text(), writer_.size());
}

}  // namespace tdcm
