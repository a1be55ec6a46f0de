// Host harness for the firmware core: reads a script on stdin, writes the device's lines on
// stdout. Used by test/firmware (g++) with the transcripts in test/device/transcripts.
//
//   eeprom <tare> <scale_mcpn>   store a valid calibration record (before boot)
//   boot                         boot at the current time (t = 0 at start)
//   sensor <counts> | sensor off the load cell delivers this reading every ms, or nothing
//   rx <hex>                     bytes from the host arrive now
//   adv <ms>                     advance time 1 ms at a time (sample, then tick)
//   mark                         print "%%" (separates the output of transcript steps)
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../tdcm_tension/tension_core.h"

namespace {

class RamStorage : public tdcm::Storage {
 public:
  RamStorage() { memset(bytes, 0xFF, sizeof(bytes)); }
  void read(uint8_t* data, uint8_t size) override { memcpy(data, bytes, size); }
  void write(const uint8_t* data, uint8_t size) override { memcpy(bytes, data, size); }
  uint8_t bytes[tdcm::EEPROM_RECORD_SIZE];
};

class StdoutSink : public tdcm::LineSink {
 public:
  void send(const char* text, uint8_t size) override { fwrite(text, 1, size, stdout); }
};

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

int main() {
  RamStorage storage;
  StdoutSink sink;
  tdcm::TensionCore core(storage, sink, "SIM");
  uint32_t now = 0;
  bool sensor_on = false;
  int32_t sensor = 0;
  char line[4096];
  while (fgets(line, sizeof(line), stdin) != nullptr) {
    line[strcspn(line, "\r\n")] = 0;
    char* arg = strchr(line, ' ');
    if (arg != nullptr) *arg++ = 0;
    if (strcmp(line, "eeprom") == 0) {
      long tare = 0, scale = 0;
      if (arg == nullptr || sscanf(arg, "%ld %ld", &tare, &scale) != 2) return 2;
      tdcm::pack_calibration((int32_t)tare, (int32_t)scale, storage.bytes);
    } else if (strcmp(line, "boot") == 0) {
      core.boot(now);
    } else if (strcmp(line, "sensor") == 0 && arg != nullptr) {
      sensor_on = strcmp(arg, "off") != 0;
      sensor = (int32_t)strtol(arg, nullptr, 10);
    } else if (strcmp(line, "rx") == 0 && arg != nullptr) {
      for (size_t i = 0; arg[i] && arg[i + 1]; i += 2) {
        int hi = hex_digit(arg[i]), lo = hex_digit(arg[i + 1]);
        if (hi < 0 || lo < 0) return 2;
        core.receive((uint8_t)(hi * 16 + lo), now);
      }
    } else if (strcmp(line, "adv") == 0 && arg != nullptr) {
      for (long ms = strtol(arg, nullptr, 10); ms > 0; --ms) {
        ++now;
        if (sensor_on) core.sample(sensor, now);
        core.tick(now);
      }
    } else if (strcmp(line, "mark") == 0) {
      fputs("%%\n", stdout);
    } else {
      fprintf(stderr, "unknown harness command: %s\n", line);
      return 2;
    }
  }
  return 0;
}
