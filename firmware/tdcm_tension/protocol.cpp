#include "protocol.h"

#include <string.h>

namespace tdcm {

namespace {

const char* const kRejectNames[] = {"", "NOISE", "PARTIAL", "LONG", "CHARS", "FRAME",
                                    "CKSUM", "VER", "TYPE", "FIELDS", "RANGE", "MODE", "FAULT"};

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Parse "(-)?(0|[1-9][0-9]{0,2})\.[0-9]{3}" into thousandths (mN, mrad); false on bad syntax
// (negative zero included).
bool parse_mn(const char* s, uint8_t n, int32_t& out) {
  uint8_t i = 0;
  bool negative = false;
  if (i < n && s[i] == '-') { negative = true; ++i; }
  uint8_t start = i;
  int32_t whole = 0;
  while (i < n && is_digit(s[i])) { whole = whole * 10 + (s[i] - '0'); ++i; }
  uint8_t digits = i - start;
  if (digits == 0 || digits > 3 || (digits > 1 && s[start] == '0')) return false;
  if (i + 4 != n || s[i] != '.') return false;
  int32_t frac = 0;
  for (uint8_t k = i + 1; k < n; ++k) {
    if (!is_digit(s[k])) return false;
    frac = frac * 10 + (s[k] - '0');
  }
  out = whole * 1000 + frac;
  if (negative) {
    if (out == 0) return false;
    out = -out;
  }
  return true;
}

}  // namespace

const char* reject_name(Reject reason) { return kRejectNames[reason]; }

Reject decode_command(const char* line, uint8_t len, Command& out, char& letter) {
  letter = '?';
  if (len > MAX_LINE) return R_LONG;
  for (uint8_t i = 0; i < len; ++i) {
    if (line[i] < 0x20 || line[i] > 0x7E) return R_CHARS;
  }
  if (len < 4 || line[0] != '$' || line[len - 3] != '*') return R_FRAME;
  for (uint8_t i = 1; i < len - 3; ++i) {
    if (line[i] == '*' || line[i] == '$') return R_FRAME;
  }
  int hi = hex_value(line[len - 2]), lo = hex_value(line[len - 1]);
  if (hi < 0 || lo < 0) return R_FRAME;
  const char* body = line + 1;
  uint8_t body_len = len - 4;
  uint8_t sum = 0;
  for (uint8_t i = 0; i < body_len; ++i) sum ^= (uint8_t)body[i];
  if (sum != (uint8_t)(hi * 16 + lo)) return R_CKSUM;

  // Split the body into at most 8 fields (more is always a FIELDS error below).
  const uint8_t kMaxFields = 8;
  uint8_t start[kMaxFields], size[kMaxFields], count = 0;
  uint8_t field_start = 0;
  bool too_many = false;
  for (uint8_t i = 0; i <= body_len; ++i) {
    if (i == body_len || body[i] == ',') {
      if (count < kMaxFields) {
        start[count] = field_start;
        size[count] = i - field_start;
        ++count;
      } else {
        too_many = true;
      }
      field_start = i + 1;
    }
  }
  // Version: [1-9][0-9]{0,2}
  const char* v = body + start[0];
  if (size[0] < 1 || size[0] > 3 || v[0] < '1' || v[0] > '9') return R_FRAME;
  int32_t version = 0;
  for (uint8_t i = 0; i < size[0]; ++i) {
    if (!is_digit(v[i])) return R_FRAME;
    version = version * 10 + (v[i] - '0');
  }
  if (version != PROTOCOL_VERSION) return R_VER;
  if (count < 2 || size[1] != 1 || strchr("SMHZKECIR", body[start[1]]) == nullptr) return R_TYPE;
  char type = body[start[1]];
  letter = type;
  for (uint8_t f = 2; f < count; ++f) {
    if (size[f] == 0) return R_FIELDS;
  }
  uint8_t fields = too_many ? kMaxFields : count - 2;
  out.type = type;
  out.mode = 0;
  out.mn = 0;
  out.mrad = 0;
  if (strchr("HZECI", type) != nullptr) return fields == 0 ? R_NONE : R_FIELDS;
  if (fields != 1) return R_FIELDS;
  const char* a = body + start[2];
  if (type == 'M') {
    if (size[2] != 1 || (a[0] != 'R' && a[0] != 'T')) return R_FIELDS;
    out.mode = a[0];
    return R_NONE;
  }
  if (type == 'R') {
    if (!parse_mn(a, size[2], out.mrad)) return R_FIELDS;
    return (out.mrad < -ROLL_MAX_MRAD || out.mrad > ROLL_MAX_MRAD) ? R_RANGE : R_NONE;
  }
  if (!parse_mn(a, size[2], out.mn)) return R_FIELDS;
  int32_t low = type == 'S' ? 0 : CAL_LOAD_MIN_MN;
  int32_t high = type == 'S' ? SETPOINT_MAX_MN : CAL_LOAD_MAX_MN;
  if (out.mn < low || out.mn > high) return R_RANGE;
  return R_NONE;
}

Framer::Event Framer::push(uint8_t byte, Reject& reason) {
  if (byte == '$') {
    bool cut = in_frame_;
    buffer_[0] = '$';
    length_ = 1;
    in_frame_ = true;
    skipping_ = false;
    if (cut) {
      reason = R_PARTIAL;
      return REJECTED;
    }
    return NOTHING;
  }
  if (byte == '\n') {
    skipping_ = false;
    if (!in_frame_) return NOTHING;
    in_frame_ = false;
    buffer_[length_] = 0;
    return LINE;
  }
  if (!in_frame_) return NOTHING;
  if (length_ >= MAX_LINE) {
    in_frame_ = false;
    skipping_ = true;
    reason = R_LONG;
    return REJECTED;
  }
  buffer_[length_++] = (char)byte;
  return NOTHING;
}

void Writer::put(char c) {
  if (length_ < sizeof(buffer_) - 1) buffer_[length_++] = c;
}

void Writer::put_digits(uint32_t value) {
  char digits[10];
  uint8_t n = 0;
  do {
    digits[n++] = (char)('0' + value % 10);
    value /= 10;
  } while (value != 0);
  while (n) put(digits[--n]);
}

void Writer::start(char type) {
  length_ = 0;
  put('$');
  put_digits(PROTOCOL_VERSION);
  put(',');
  put(type);
}

void Writer::add_text(const char* text) {
  put(',');
  while (*text) put(*text++);
}

void Writer::add_char(char value) {
  put(',');
  put(value);
}

void Writer::add_uint(uint32_t value) {
  put(',');
  put_digits(value);
}

void Writer::add_int(int32_t value) {
  put(',');
  if (value < 0) put('-');
  put_digits(value < 0 ? (uint32_t)(-(int64_t)value) : (uint32_t)value);
}

void Writer::add_mn(int32_t millinewtons) {
  put(',');
  if (millinewtons < 0) put('-');
  uint32_t magnitude =
      millinewtons < 0 ? (uint32_t)(-(int64_t)millinewtons) : (uint32_t)millinewtons;
  put_digits(magnitude / 1000);
  uint16_t frac = magnitude % 1000;
  put('.');
  put((char)('0' + frac / 100));
  put((char)('0' + frac / 10 % 10));
  put((char)('0' + frac % 10));
}

void Writer::add_hex2(uint8_t value) {
  static const char kHex[] = "0123456789ABCDEF";
  put(',');
  put(kHex[value >> 4]);
  put(kHex[value & 15]);
}

void Writer::finish() {
  uint8_t sum = 0;
  for (uint8_t i = 1; i < length_; ++i) sum ^= (uint8_t)buffer_[i];
  static const char kHex[] = "0123456789ABCDEF";
  put('*');
  put(kHex[sum >> 4]);
  put(kHex[sum & 15]);
  put('\n');
  buffer_[length_] = 0;
}

}  // namespace tdcm
