// Protocol v1 (with the roll servo extension) of the tension device (see firmware/PROTOCOL.md): framing, strict command
// decoding and reply encoding. Plain C++11, no Arduino headers; mirrors
// tdcm_ros/device/protocol.py decision for decision.
#ifndef TDCM_PROTOCOL_H
#define TDCM_PROTOCOL_H

#include <stdint.h>

#include "config.h"

namespace tdcm {

enum Reject : uint8_t {
  R_NONE = 0, R_NOISE, R_PARTIAL, R_LONG, R_CHARS, R_FRAME, R_CKSUM, R_VER, R_TYPE,
  R_FIELDS, R_RANGE, R_MODE, R_FAULT
};

// The code sent in a NACK ("CKSUM", ...).
const char* reject_name(Reject reason);

struct Command {
  char type;      // one of S M H Z K E C I R
  char mode;      // 'R' or 'T' for M
  int32_t mn;     // millinewtons for S and K
  int32_t mrad;   // milliradians for R
};

// Decode one frame ('$' .. checksum, no '\n'). Returns R_NONE and fills `out`, or the reason;
// `letter` is the command letter when known, else '?'.
Reject decode_command(const char* line, uint8_t len, Command& out, char& letter);

// Byte-stream framer: a '$' always starts a new frame.
class Framer {
 public:
  enum Event : uint8_t { NOTHING, LINE, REJECTED };
  // Feed one byte. LINE: a frame is in line()/length(). REJECTED: `reason` says why.
  Event push(uint8_t byte, Reject& reason);
  const char* line() const { return buffer_; }
  uint8_t length() const { return length_; }

 private:
  char buffer_[MAX_LINE + 1];
  uint8_t length_ = 0;
  bool in_frame_ = false;
  bool skipping_ = false;
};

// Reply builder: start(type), add fields, finish() -> "$1,<type>,...*HH\n" in text()/size().
class Writer {
 public:
  void start(char type);
  void add_text(const char* text);
  void add_char(char value);
  void add_int(int32_t value);
  void add_uint(uint32_t value);
  void add_mn(int32_t millinewtons);   // "-12.345" (also milliradians: "-1.571")
  void add_hex2(uint8_t value);
  void finish();
  const char* text() const { return buffer_; }
  uint8_t size() const { return length_; }

 private:
  void put(char c);
  void put_digits(uint32_t value);
  char buffer_[MAX_LINE + 2];
  uint8_t length_ = 0;
};

}  // namespace tdcm

#endif
