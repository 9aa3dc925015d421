/*
 * gyrocal_session.h: the six-turn calibration of the servo method of Wang et al. run on the device
 * (part of gyrocal, MIT licence).
 *
 * Feed every raw sample [counts] to gyrocal_session_add. The session learns the standstill reading,
 * finds each whole turn (from the moment the rate leaves the standstill band, with GYROCAL_SESSION_PRE_S
 * to twice that of standstill before it, to GYROCAL_SESSION_QUIET_S of standstill after it), reduces it
 * with the window accumulator and files it by axis and sense (+x, -x, +y, -y, +z, -z); a later turn of the same slot
 * replaces an earlier one. Once all six slots are filled it calibrates with the first-moment estimator
 * (gyrocal_first_moment) and again after every later accepted turn.
 *
 * Each turn's reference rate is its angle over its duration, turn_angle * sample_rate / count [deg/s],
 * so the windows are whole turns and static margins inside them cost noise, not bias. Rates are in
 * deg/s throughout; k comes out in deg/s per count and b in counts.
 *
 * The window before the start is sized in time, not in samples, so that the part of a slow ramp
 * under the band is inside it at any sample rate: two window accumulators run while still, restarted
 * in turn every GYROCAL_SESSION_PRE_S, and the older one becomes the turn's window. A window never
 * reaches back past the end of the previous turn.
 *
 * C99, float32, no dynamic memory, no static data; about 450 bytes of state.
 */
#ifndef GYROCAL_SESSION_H
#define GYROCAL_SESSION_H

#include <stdint.h>

#include "gyrocal_cal.h"
#include "gyrocal_frame.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifndef GYROCAL_SESSION_PRE_S
#define GYROCAL_SESSION_PRE_S 0.5f /* [s] kept before a detected start (up to twice that): the ramp under the band */
#endif
#define GYROCAL_SESSION_THRESHOLD_DEG_S 10.0f /* rate off the standstill reading that counts as turning */
#define GYROCAL_SESSION_SETTLE_S 0.5f         /* standstill at power-up that gives the first standstill reading */
#define GYROCAL_SESSION_QUIET_S 0.5f          /* standstill that ends a turn */
#define GYROCAL_SESSION_MAX_S 60.0f           /* longest turn */
#define GYROCAL_SESSION_START_N 3u            /* samples above the band that start a turn */
#define GYROCAL_SESSION_ANGLE_TOL 0.25f       /* relative tolerance of the integrated angle */
#define GYROCAL_SESSION_MIN_ON_AXIS 0.906f    /* cos 25 deg: the turn's axis within 25 deg of a body axis */

/* Events returned by gyrocal_session_add (bit flags). */
#define GYROCAL_SESSION_TURN 1u   /* a turn ended: session->turn describes it */
#define GYROCAL_SESSION_RESULT 2u /* a calibration was computed: session->status, ->result, ->iterations */

typedef struct {
    /* configuration */
    float sample_rate;  /* [Hz] */
    float sensitivity;  /* [counts per deg/s] */
    float turn_angle;   /* angle of every turn [deg] */
    float threshold;    /* [counts] */
    uint32_t settle_n, quiet_n, max_n;
    uint32_t pre_n;     /* GYROCAL_SESSION_PRE_S in samples */
    /* state */
    uint32_t seq;       /* samples seen so far */
    uint8_t phase;      /* 0 settling, 1 still, 2 turning */
    uint8_t have;       /* bit i: slot i holds an accepted turn */
    uint8_t cur;        /* acc[cur] is the window of the turn under way */
    uint32_t still;     /* still samples since acc[0] restarted, modulo 2 pre_n (acc[1] restarts at pre_n) */
    uint32_t run;       /* samples in a row above the band (still) or inside it (turning) */
    float base[3];      /* standstill reading [counts] */
    float pre_base[2][3]; /* the standstill reading when acc[0], acc[1] restarted */
    gyrocal_accum_t acc[2];
    gyrocal_obs_t obs[GYROCAL_N_OBS];
    /* outputs */
    gyrocal_turn_t turn;
    gyrocal_scale_bias_t result;
    gyrocal_status_t status;
    int iterations;
} gyrocal_session_t;

/* sample_rate [Hz], sensitivity [counts per deg/s], turn_angle [deg] (360 for the paper's turns). */
gyrocal_status_t gyrocal_session_init(gyrocal_session_t *s, float sample_rate, float sensitivity, float turn_angle);

/* One raw sample [counts]; returns GYROCAL_SESSION_* event flags (0 for most samples, and for NULL pointers). */
unsigned gyrocal_session_add(gyrocal_session_t *s, const int16_t raw[3]);

#ifdef __cplusplus
}
#endif

#endif /* GYROCAL_SESSION_H */
