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
// Board layer: the four functions of board.h, below.

#include <Wire.h>

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
