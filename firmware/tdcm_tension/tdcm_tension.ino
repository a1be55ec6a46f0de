// tdcm_tension: Arduino UNO tendon-tension controller (protocol v1 with roll, see ../PROTOCOL.md).
//
// Wiring: load cell on an HX711 (DOUT -> D3, SCK -> D2) or an analog amplifier (out -> A0),
// chosen with TDCM_LOAD_CELL below (or -DTDCM_LOAD_CELL=... from the Makefile); the linear
// actuator's servo signal on D9 (Timer1 OC1A, 0.5 us resolution, 50 Hz frame); the roll servo's
// signal on D10 (Timer1 OC1B, same frame).
// All protocol and control logic lives in tension_core.cpp / protocol.cpp (plain C++).
#include <EEPROM.h>

#include "tension_core.h"

#define TDCM_CELL_HX711 1
#define TDCM_CELL_ANALOG 2
#ifndef TDCM_LOAD_CELL
#define TDCM_LOAD_CELL TDCM_CELL_HX711
#endif

const uint8_t PIN_HX711_DOUT = 3;
const uint8_t PIN_HX711_SCK = 2;
const uint8_t PIN_ANALOG = A0;
const uint8_t PIN_SERVO = 9;   // OC1A
const uint8_t PIN_ROLL = 10;   // OC1B
const uint16_t ANALOG_PERIOD_MS = 5;

class EepromStorage : public tdcm::Storage {
 public:
  void read(uint8_t* data, uint8_t size) override {
    for (uint8_t i = 0; i < size; ++i) data[i] = EEPROM.read(i);
  }
  void write(const uint8_t* data, uint8_t size) override {
    for (uint8_t i = 0; i < size; ++i) EEPROM.update(i, data[i]);
  }
};

class SerialSink : public tdcm::LineSink {
 public:
  void send(const char* text, uint8_t size) override { Serial.write(text, size); }
};

EepromStorage storage;
SerialSink sink;
#if TDCM_LOAD_CELL == TDCM_CELL_HX711
tdcm::TensionCore core(storage, sink, "HX711");
#else
tdcm::TensionCore core(storage, sink, "ANALOG");
#endif

// Servo pulses on D9 and D10 with Timer1: fast PWM mode 14, TOP = ICR1, prescaler 8 (0.5 us
// ticks). The roll servo starts at 0 rad, the boot position of the core.
void servo_begin() {
  pinMode(PIN_SERVO, OUTPUT);
  pinMode(PIN_ROLL, OUTPUT);
  TCCR1A = _BV(COM1A1) | _BV(COM1B1) | _BV(WGM11);
  TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS11);
  ICR1 = 40000;  // 20 ms frame
  OCR1A = tdcm::PULSE_RELEASE_US * 2;
  OCR1B = tdcm::ROLL_PULSE_CENTER_US * 2;
}

void servo_write(uint16_t pulse_us, uint16_t roll_pulse_us) {
  OCR1A = pulse_us * 2;
  OCR1B = roll_pulse_us * 2;
}

#if TDCM_LOAD_CELL == TDCM_CELL_HX711
// One conversion if the HX711 has one ready (DOUT low): 24 bits, then 1 pulse = gain 128 ch A.
bool read_cell(int32_t& counts) {
  if (digitalRead(PIN_HX711_DOUT) == HIGH) return false;
  uint32_t value = 0;
  noInterrupts();
  for (uint8_t i = 0; i < 25; ++i) {
    digitalWrite(PIN_HX711_SCK, HIGH);
    delayMicroseconds(1);
    if (i < 24) value = (value << 1) | (digitalRead(PIN_HX711_DOUT) == HIGH ? 1 : 0);
    digitalWrite(PIN_HX711_SCK, LOW);
    delayMicroseconds(1);
  }
  interrupts();
  counts = (int32_t)(value << 8) >> 8;  // sign-extend 24 -> 32 bits
  return true;
}
#else
bool read_cell(int32_t& counts) {
  static uint32_t last_ms = 0;
  uint32_t now = millis();
  if ((uint32_t)(now - last_ms) < ANALOG_PERIOD_MS) return false;
  last_ms = now;
  counts = analogRead(PIN_ANALOG);
  return true;
}
#endif

void setup() {
  servo_begin();  // release first, before anything else can fail
  pinMode(PIN_HX711_SCK, OUTPUT);
  digitalWrite(PIN_HX711_SCK, LOW);
  pinMode(PIN_HX711_DOUT, INPUT);
  Serial.begin(tdcm::BAUD_RATE);
  core.boot(millis());
}

void loop() {
  uint32_t now = millis();
  while (Serial.available() > 0) core.receive((uint8_t)Serial.read(), now);
  int32_t counts;
  if (read_cell(counts)) core.sample(counts, now);
  core.tick(now);
  servo_write(core.pulse_us(), core.roll_pulse_us());
}
