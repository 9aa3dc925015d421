/*
 * gyrocal_frame.h: gyrocal frames, the binary wire format between a device and `gyrocal capture`
 * (part of gyrocal, MIT licence). docs/capture.md has the byte tables. Frames go from the device to the
 * host, except GYROCAL_FRAME_SET_CALIBRATION (host to device), which gyrocal_frame_rx_byte receives.
 *
 * C99, no dynamic memory, no static data, nothing from libc. Every encoder writes one whole frame
 * into a caller buffer of GYROCAL_FRAME_MAX bytes and returns its length; a NULL pointer (other than
 * the result's parameters and a refusal's stored correction, sent as zeros) writes nothing and returns 0.
 *
 * A frame:  0xA5 0x5A | type (1) | payload length L (1, <= GYROCAL_FRAME_MAX_PAYLOAD) | payload (L) |
 *           CRC-16 (2)
 * The CRC is CRC-16/CCITT-FALSE (polynomial 0x1021, initial value 0xFFFF, no reflection, no final XOR;
 * check value 0x29B1 for the ASCII bytes "123456789") over type, length and payload, sent low byte
 * first. Every multi-byte field is little-endian; floats are IEEE 754 binary32.
 */
#ifndef GYROCAL_FRAME_H
#define GYROCAL_FRAME_H

#include <stddef.h>
#include <stdint.h>

#include "gyrocal_cal.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GYROCAL_FRAME_SYNC0 0xA5u
#define GYROCAL_FRAME_SYNC1 0x5Au
#define GYROCAL_FRAME_PROTOCOL 1u      /* protocol version, sent in the hello frame */
#define GYROCAL_FRAME_OVERHEAD 6u      /* sync (2) + type (1) + length (1) + CRC (2) */
#define GYROCAL_FRAME_MAX_PAYLOAD 64u
#define GYROCAL_FRAME_MAX (GYROCAL_FRAME_OVERHEAD + GYROCAL_FRAME_MAX_PAYLOAD)

/* Frame types and their payload lengths. */
#define GYROCAL_FRAME_HELLO 0x01u       /* what the device is: rates, units, sensitivity, firmware */
#define GYROCAL_FRAME_SAMPLE 0x02u      /* one raw sample in counts, device time stamp, temperature */
#define GYROCAL_FRAME_CALIBRATED 0x03u  /* one corrected sample [rate unit], float32 */
#define GYROCAL_FRAME_TURN 0x04u        /* one turn the device saw, accepted or not */
#define GYROCAL_FRAME_RESULT 0x05u      /* the device's own calibration */
#define GYROCAL_FRAME_TEXT 0x06u        /* a message for the person at the host, UTF-8 */
#define GYROCAL_FRAME_IMU 0x07u         /* one raw 6-axis sample: gyro and accelerometer counts, stamp, temperature */
#define GYROCAL_FRAME_END 0x08u         /* the session is over: the device sends nothing more */
#define GYROCAL_FRAME_SET_CALIBRATION 0x09u    /* host to device: a correction to store (and apply) */
#define GYROCAL_FRAME_CALIBRATION_STORED 0x0Au /* device to host: the correction read back from storage */
#define GYROCAL_FRAME_HELLO_LEN 32u
#define GYROCAL_FRAME_SAMPLE_LEN 16u
#define GYROCAL_FRAME_CALIBRATED_LEN 20u
#define GYROCAL_FRAME_TURN_LEN 32u
#define GYROCAL_FRAME_RESULT_LEN 32u
#define GYROCAL_FRAME_IMU_LEN 22u
#define GYROCAL_FRAME_END_LEN 4u
#define GYROCAL_FRAME_SET_CALIBRATION_LEN 56u
#define GYROCAL_FRAME_CALIBRATION_STORED_LEN 56u
#define GYROCAL_FRAME_SET_CALIBRATION_SIZE (GYROCAL_FRAME_OVERHEAD + GYROCAL_FRAME_SET_CALIBRATION_LEN)
#define GYROCAL_FRAME_SAMPLE_SIZE (GYROCAL_FRAME_OVERHEAD + GYROCAL_FRAME_SAMPLE_LEN)
#define GYROCAL_FRAME_IMU_SIZE (GYROCAL_FRAME_OVERHEAD + GYROCAL_FRAME_IMU_LEN)

/* Units of rates in hello, turn, result and calibrated frames. */
#define GYROCAL_UNIT_RAD_S 0u
#define GYROCAL_UNIT_DEG_S 1u
/* Hello flags. */
#define GYROCAL_HELLO_HAS_TEMP 1u
#define GYROCAL_HELLO_HAS_ACCEL 2u /* samples come as GYROCAL_FRAME_IMU, with the accelerometer */
/* Temperature field of a sample frame when the device has no thermometer. */
#define GYROCAL_TEMP_NONE INT16_MIN
/* Result methods. */
#define GYROCAL_METHOD_FIRST_MOMENT 0u
#define GYROCAL_METHOD_ALGORITHM1 1u

typedef struct {
    float sample_rate;  /* nominal [Hz] */
    float sensitivity;  /* counts per rate unit (LSB per deg/s for deg/s) */
    uint8_t rate_unit;  /* GYROCAL_UNIT_* */
    uint8_t flags;      /* GYROCAL_HELLO_* */
    uint16_t library;   /* GYROCAL_CAL_VERSION of the gyrocal C library the firmware was built with */
    char firmware[16];  /* firmware name and version, NUL-padded (need not be terminated) */
    uint16_t accel_sensitivity; /* accelerometer counts per g (16384 for an MPU-6050 at +-2 g); 0 without one */
} gyrocal_hello_t;

/* Slots of the six turns, in the servo method's order (+x, -x, +y, -y, +z, -z). */
typedef struct {
    uint32_t start;     /* first sample (the sample frames' seq) */
    uint32_t stop;      /* one past the last sample */
    float rate;         /* reference rate of the window [rate unit]: turn angle / duration */
    float angle;        /* angle turned, integrated with the nominal sensitivity [deg] */
    float mean[3];      /* window mean [counts] */
    uint8_t slot;       /* 0..5: +x, -x, +y, -y, +z, -z */
    uint8_t status;     /* 0 accepted, else a GYROCAL_TURN_* reason */
} gyrocal_turn_t;

#define GYROCAL_TURN_ACCEPTED 0u
#define GYROCAL_TURN_WRONG_ANGLE 1u
#define GYROCAL_TURN_OFF_AXIS 2u
#define GYROCAL_TURN_TOO_LONG 3u
#define GYROCAL_TURN_BAD_WINDOW 4u /* the accumulator refused the window (gyrocal_accum_finish) */

/* A correction sent by the host (GYROCAL_FRAME_SET_CALIBRATION) and echoed by the device, as it read it back
 * from its storage (GYROCAL_FRAME_CALIBRATION_STORED): w = cal.matrix (raw - cal.offset), raw and offset in
 * counts, w in rate_unit. */
typedef struct {
    uint32_t seq;       /* the host's request number, echoed so that an answer matches its request */
    uint8_t flags;      /* GYROCAL_SETCAL_* */
    uint8_t rate_unit;  /* GYROCAL_UNIT_* of the corrected rates */
    gyrocal_affine_t cal;
} gyrocal_set_calibration_t;

/* Set-calibration flags. */
#define GYROCAL_SETCAL_APPLY 1u /* correct the samples from now on (else only store, for the next start) */
/* Status of a calibration-stored frame. */
#define GYROCAL_STORED_OK 0u      /* stored, and what follows is what the storage holds now */
#define GYROCAL_STORED_INVALID 1u /* refused: a value not finite, or an unknown unit; nothing stored */
#define GYROCAL_STORED_FAILED 2u  /* the storage did not take it, or did not read back a valid record */

/* Receiver of host frames, fed byte by byte (a UART interrupt, a poll loop). */
typedef struct {
    uint8_t buf[GYROCAL_FRAME_MAX]; /* the frame so far: buf[2] its type, buf[3] its length, payload at buf + 4 */
    uint8_t len;
} gyrocal_frame_rx_t;

/* CRC-16/CCITT-FALSE of n bytes, continuing from crc (start with 0xFFFF). */
uint16_t gyrocal_crc16(const uint8_t *data, size_t n, uint16_t crc);

/* Wrap payload[0..len) in a frame of `type`; len <= GYROCAL_FRAME_MAX_PAYLOAD (else returns 0). */
size_t gyrocal_frame(uint8_t out[GYROCAL_FRAME_MAX], uint8_t type, const uint8_t *payload, size_t len);

size_t gyrocal_frame_hello(uint8_t out[GYROCAL_FRAME_MAX], const gyrocal_hello_t *hello);
/* temp_centi: temperature [0.01 degC], or GYROCAL_TEMP_NONE. */
size_t gyrocal_frame_sample(uint8_t out[GYROCAL_FRAME_MAX], uint32_t seq, uint32_t t_us, const int16_t raw[3],
                            int16_t temp_centi);
/* gyro, accel: [counts]; temp_centi as for a sample frame. */
size_t gyrocal_frame_imu(uint8_t out[GYROCAL_FRAME_MAX], uint32_t seq, uint32_t t_us, const int16_t gyro[3],
                         const int16_t accel[3], int16_t temp_centi);
size_t gyrocal_frame_calibrated(uint8_t out[GYROCAL_FRAME_MAX], uint32_t seq, uint32_t t_us, const float w[3]);
size_t gyrocal_frame_turn(uint8_t out[GYROCAL_FRAME_MAX], const gyrocal_turn_t *turn);
/* The device's calibration: status, method, iterations, turns used, k [rate unit per count], b [counts],
 * and the sample that completed it (the first one the result corrects). */
size_t gyrocal_frame_result(uint8_t out[GYROCAL_FRAME_MAX], gyrocal_status_t status, uint8_t method,
                            uint8_t iterations, uint8_t n_turns, const gyrocal_scale_bias_t *sb, uint32_t seq);
/* A NUL-terminated message, cut at GYROCAL_FRAME_MAX_PAYLOAD bytes. */
size_t gyrocal_frame_text(uint8_t out[GYROCAL_FRAME_MAX], const char *text);
/* The end of the session (a recorded or simulated one; a live board never ends): n_samples sample or IMU
 * frames were sent in all. The host knows it has everything once it has read this frame. */
size_t gyrocal_frame_end(uint8_t out[GYROCAL_FRAME_MAX], uint32_t n_samples);
/* The host's request to store a correction (what gyrocal capture --write-back sends). */
size_t gyrocal_frame_set_calibration(uint8_t out[GYROCAL_FRAME_MAX], const gyrocal_set_calibration_t *set);
/* The device's answer: status GYROCAL_STORED_*, and the correction read back from storage (NULL: zeros, for a
 * refusal). */
size_t gyrocal_frame_calibration_stored(uint8_t out[GYROCAL_FRAME_MAX], uint8_t status,
                                        const gyrocal_set_calibration_t *stored);
/* The payload of a set-calibration frame (len bytes) into *out: GYROCAL_E_INPUT for a wrong length, a value not
 * finite or an unknown unit (then *out is untouched). */
gyrocal_status_t gyrocal_parse_set_calibration(const uint8_t *payload, size_t len, gyrocal_set_calibration_t *out);

void gyrocal_frame_rx_reset(gyrocal_frame_rx_t *rx);
/* Take one byte; returns the type of the frame it completes when its CRC is good (its payload at rx->buf + 4,
 * rx->buf[3] bytes, valid until the next call), else 0. Bytes that make no frame (a length too large, a bad CRC)
 * are dropped up to the next sync among them, so the search goes on from there. */
unsigned gyrocal_frame_rx_byte(gyrocal_frame_rx_t *rx, uint8_t byte);

#ifdef __cplusplus
}
#endif

#endif /* GYROCAL_FRAME_H */
