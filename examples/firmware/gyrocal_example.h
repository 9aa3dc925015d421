/*
 * gyrocal_example.h: example firmware for `gyrocal capture` (part of gyrocal, MIT licence).
 *
 * Streams every sample as a gyrocal frame (gyro only, or 6-axis with the accelerometer for the
 * multi-position hand session), runs the six-turn calibration of the servo method of Wang et al. on
 * the device (gyrocal_session), reports each turn and its result, and from then on also sends the
 * corrected samples. It takes the host's calibration (gyrocal capture --write-back), stores it, reads it back,
 * answers with what it read and, when asked, corrects the samples with it. Portable C99: the board layer
 * (board.h) is the only port.
 */
#ifndef GYROCAL_EXAMPLE_H
#define GYROCAL_EXAMPLE_H

#include <stdint.h>

#include "gyrocal_cal.h"
#include "gyrocal_frame.h"
#include "gyrocal_session.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifndef EXAMPLE_FIRMWARE
#define EXAMPLE_FIRMWARE "gyrocal-example"
#endif
#ifndef EXAMPLE_SEND_CALIBRATED
#define EXAMPLE_SEND_CALIBRATED 1 /* after calibrating, send corrected samples too (as in the paper) */
#endif

typedef struct {
    gyrocal_session_t session;
    gyrocal_affine_t cal; /* the device's correction once calibrated */
    int calibrated;
    int host_cal; /* cal is the host's (written back and applied), not the device's own */
    int send_accel; /* 6-axis frames (GYROCAL_FRAME_IMU) instead of sample frames */
    uint32_t seq;
    uint8_t frame[GYROCAL_FRAME_MAX];
    gyrocal_frame_rx_t rx; /* frames from the host */
} example_t;

/* Start: set up the session and send the hello frame. sample_rate [Hz], sensitivity [counts per deg/s];
 * accel_sensitivity [counts per g] sends 6-axis frames with the accelerometer (0: gyro only). */
void example_setup(example_t *ex, float sample_rate, float sensitivity, uint16_t accel_sensitivity, int has_temp);
/* One sample: read, send, calibrate, take what the host sent. Returns 0, or non-zero when the board has no more samples (then it
 * has sent the end frame). */
int example_step(example_t *ex);

#ifdef __cplusplus
}
#endif

#endif
