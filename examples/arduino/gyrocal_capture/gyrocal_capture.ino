// gyrocal_capture.ino: the gyrocal example firmware on an Arduino with an MPU-6050 / MPU-9250 on I2C.
//
// Streams gyrocal frames at 200 Hz over the USB serial port, runs the six-turn calibration of the
// servo method of Wang et al. on the board, and reports its result; read it with
//     gyrocal capture --port /dev/ttyACM0 --baud 115200 -o rec.csv --guide servo
// With SEND_ACCEL true it sends 6-axis frames (gyro and accelerometer) for the multi-position hand session:
//     gyrocal capture --port /dev/ttyACM0 --baud 115200 -o imu.csv --guide multi-position
// (28 bytes per sample instead of 22: with the corrected samples the board sends after calibrating, 200 Hz
// fills 94 % of 115200 baud; set SAMPLE_RATE to 100 or the baud rate to 230400 if samples go missing).
//
// The portable files come from the gyrocal repository; copy them next to this sketch first:
//     bash examples/arduino/make_sketch.sh            (from the repository root)
// Wiring (3.3 V boards, or a 5 V board with a level-shifting breakout): VCC, GND, SDA, SCL; AD0 low.
// Board layer: the functions of board.h, below. `gyrocal capture ... --write-back` sends the accepted
// calibration back; the board keeps it in EEPROM (AVR boards; elsewhere in RAM until a port adds its flash).

#include <Wire.h>
#if defined(ARDUINO_ARCH_AVR)
#include <EEPROM.h>
#endif

extern "C" {
#include "board.h"
#include "gyrocal_example.h"
}

static const uint8_t MPU = 0x68;         // I2C address with AD0 low
static const float SAMPLE_RATE = 200.0f; // [Hz]
static const float SENSITIVITY = 131.0f; // LSB per deg/s at +-250 deg/s (GYRO_CONFIG = 0)
static const bool SEND_ACCEL = false;    // true: 6-axis frames with the accelerometer
static const uint16_t ACCEL_SENSITIVITY = 16384; // LSB per g at +-2 g (ACCEL_CONFIG = 0)
static const uint32_t PERIOD_US = (uint32_t)(1e6f / SAMPLE_RATE);
static uint32_t next_us;
static example_t ex;

static void mpu_write(uint8_t reg, uint8_t value)
{
    Wire.beginTransmission(MPU);
    Wire.write(reg);
    Wire.write(value);
    Wire.endTransmission();
}

static int16_t read16(void)
{
    int16_t hi = Wire.read();
    return (int16_t)((hi << 8) | Wire.read());
}

extern "C" int board_read(int16_t raw[3], int16_t accel[3], int16_t *temp_centi)
{
    while ((int32_t)(micros() - next_us) < 0) {
    }
    next_us += PERIOD_US;
    Wire.beginTransmission(MPU);
    Wire.write(0x3B); // ACCEL_XOUT_H .. ACCEL_ZOUT_L, TEMP_OUT_H/L, GYRO_XOUT_H .. GYRO_ZOUT_L: one burst
    Wire.endTransmission(false);
    Wire.requestFrom(MPU, (uint8_t)14);
    for (int i = 0; i < 3; ++i) {
        accel[i] = read16();
    }
    int16_t t = read16();
    for (int i = 0; i < 3; ++i) {
        raw[i] = read16();
    }
    *temp_centi = (int16_t)(t / 3.4f + 3653.0f); // MPU-6050: degC = t / 340 + 36.53
    return 0;
}

extern "C" void board_write(const uint8_t *data, size_t n)
{
    Serial.write(data, n);
}

extern "C" uint32_t board_micros(void)
{
    return micros();
}

extern "C" uint32_t board_millis(void)
{
    return millis();
}

extern "C" size_t board_receive(uint8_t *data, size_t cap)
{
    size_t n = 0;
    while (n < cap && Serial.available() > 0) {
        data[n++] = (uint8_t)Serial.read();
    }
    return n;
}

#if defined(ARDUINO_ARCH_AVR)
static const int STORE_AT = 0; // EEPROM address of the calibration record
#else
static uint8_t page[GYROCAL_FRAME_MAX]; // stands in for a flash page
#endif

extern "C" int board_store(const uint8_t *data, size_t n)
{
#if defined(ARDUINO_ARCH_AVR)
    if (STORE_AT + n > EEPROM.length()) {
        return 1;
    }
    for (size_t i = 0; i < n; ++i) {
        EEPROM.update(STORE_AT + (int)i, data[i]); // update: unchanged bytes are not rewritten (wear)
    }
#else
    if (n > sizeof page) {
        return 1;
    }
    memcpy(page, data, n);
#endif
    return 0;
}

extern "C" int board_load(uint8_t *data, size_t n)
{
#if defined(ARDUINO_ARCH_AVR)
    if (STORE_AT + n > EEPROM.length()) {
        return 1;
    }
    for (size_t i = 0; i < n; ++i) {
        data[i] = EEPROM.read(STORE_AT + (int)i);
    }
#else
    if (n > sizeof page) {
        return 1;
    }
    memcpy(data, page, n);
#endif
    return 0;
}

void setup()
{
    Serial.begin(115200);
    Wire.begin();
    Wire.setClock(400000);
    mpu_write(0x6B, 0x00); // PWR_MGMT_1: wake up
    mpu_write(0x1A, 0x03); // CONFIG: 44 Hz low-pass
    mpu_write(0x1B, 0x00); // GYRO_CONFIG: +-250 deg/s
    mpu_write(0x1C, 0x00); // ACCEL_CONFIG: +-2 g
    delay(100);
    example_setup(&ex, SAMPLE_RATE, SENSITIVITY, SEND_ACCEL ? ACCEL_SENSITIVITY : 0, 1);
    next_us = micros();
}

void loop()
{
    example_step(&ex);
}
