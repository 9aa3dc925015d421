/*
 * gyrocal_session.c: on-device six-turn calibration (part of gyrocal, MIT licence). See gyrocal_session.h.
 */
#include "gyrocal_session.h"

#include <math.h>

enum { SETTLING = 0, STILL = 1, TURNING = 2 };

static void to_float(const int16_t raw[3], float x[3])
{
    int i;
    for (i = 0; i < 3; ++i) {
        x[i] = (float)raw[i];
    }
}

/* Standstill again (after settling or a turn): both pre-windows start afresh. */
static void enter_still(gyrocal_session_t *s)
{
    int i, j;
    for (j = 0; j < 2; ++j) {
        gyrocal_accum_reset(&s->acc[j]);
        for (i = 0; i < 3; ++i) {
            s->pre_base[j][i] = s->base[i];
        }
    }
    s->phase = STILL;
    s->still = 0u;
    s->run = 0u;
}

gyrocal_status_t gyrocal_session_init(gyrocal_session_t *s, float sample_rate, float sensitivity, float turn_angle)
{
    if (s == 0 || !(sample_rate > 0.0f && sensitivity > 0.0f && turn_angle > 0.0f && isfinite(sample_rate) &&
          isfinite(sensitivity) && isfinite(turn_angle))) {
        return GYROCAL_E_INPUT;
    }
    s->sample_rate = sample_rate;
    s->sensitivity = sensitivity;
    s->turn_angle = turn_angle;
    s->threshold = GYROCAL_SESSION_THRESHOLD_DEG_S * sensitivity;
    s->settle_n = (uint32_t)(GYROCAL_SESSION_SETTLE_S * sample_rate) + 1u;
    if (s->settle_n < 2u) {
        s->settle_n = 2u; /* a window needs two samples */
    }
    s->quiet_n = (uint32_t)(GYROCAL_SESSION_QUIET_S * sample_rate) + 1u;
    s->max_n = (uint32_t)(GYROCAL_SESSION_MAX_S * sample_rate);
    s->pre_n = (uint32_t)(GYROCAL_SESSION_PRE_S * sample_rate) + 1u;
    s->seq = 0u;
    s->phase = SETTLING;
    s->have = 0u;
    s->cur = 0u;
    s->still = s->run = 0u;
    s->status = GYROCAL_E_INPUT; /* no result yet */
    s->iterations = 0;
    gyrocal_accum_reset(&s->acc[0]);
    return GYROCAL_OK;
}

static float off_base(const gyrocal_session_t *s, const int16_t raw[3], float d[3])
{
    float mag = 0.0f;
    int i;
    for (i = 0; i < 3; ++i) {
        d[i] = (float)raw[i] - s->base[i];
        if (fabsf(d[i]) > mag) {
            mag = fabsf(d[i]);
        }
    }
    return mag;
}

/* A still sample goes into both pre-windows; each restarts every 2 pre_n samples, pre_n apart. */
static void add_still(gyrocal_session_t *s, const int16_t raw[3])
{
    float x[3];
    int i, j;
    to_float(raw, x);
    for (j = 0; j < 2; ++j) {
        if (s->still == (uint32_t)j * s->pre_n) {
            gyrocal_accum_reset(&s->acc[j]);
            for (i = 0; i < 3; ++i) {
                s->pre_base[j][i] = s->base[i];
            }
        }
        gyrocal_accum_add(&s->acc[j], x);
    }
    s->still = (s->still + 1u) % (2u * s->pre_n);
}

/* A turn starts: the older pre-window (pre_n to 2 pre_n samples) becomes its window. */
static void start_turn(gyrocal_session_t *s)
{
    int i;
    s->cur = (uint8_t)(s->acc[1].count > s->acc[0].count ? 1 : 0);
    for (i = 0; i < 3; ++i) {
        s->base[i] = s->pre_base[s->cur][i]; /* the ramp under the band has not moved it */
    }
    s->phase = TURNING;
    s->run = 0u;
}

/* The turn's slot and status, from the angle turned about each axis v [deg]. */
static void judge_turn(const gyrocal_session_t *s, gyrocal_turn_t *t, const float v[3], uint32_t count)
{
    int i, ax = 0;
    float norm2 = 0.0f;
    for (i = 0; i < 3; ++i) {
        norm2 += v[i] * v[i];
        if (fabsf(v[i]) > fabsf(v[ax])) {
            ax = i;
        }
    }
    t->angle = sqrtf(norm2);
    t->slot = (uint8_t)(2 * ax + (v[ax] < 0.0f ? 1 : 0));
    if (count >= s->max_n) {
        t->status = GYROCAL_TURN_TOO_LONG;
    } else if (fabsf(t->angle - s->turn_angle) > GYROCAL_SESSION_ANGLE_TOL * s->turn_angle) {
        t->status = GYROCAL_TURN_WRONG_ANGLE;
    } else if (fabsf(v[ax]) < GYROCAL_SESSION_MIN_ON_AXIS * t->angle) {
        t->status = GYROCAL_TURN_OFF_AXIS;
    } else {
        t->status = GYROCAL_TURN_ACCEPTED;
    }
}

/* A turn ends: check it, file it, and calibrate when the six slots are full. */
static unsigned end_turn(gyrocal_session_t *s)
{
    gyrocal_turn_t *t = &s->turn;
    const gyrocal_accum_t *acc = &s->acc[s->cur];
    gyrocal_obs_t obs;
    float v[3], scale = 1.0f / (s->sensitivity * s->sample_rate), n = (float)acc->count;
    int i;
    unsigned events = GYROCAL_SESSION_TURN;
    for (i = 0; i < 3; ++i) { /* sum of (reading - base) over the window [counts], to [deg] */
        v[i] = ((acc->first[i] - s->base[i]) * n + (acc->s1[i] + acc->c1[i])) * scale;
    }
    t->start = s->seq + 1u - acc->count;
    t->stop = s->seq + 1u;
    t->rate = s->turn_angle * s->sample_rate / n;
    judge_turn(s, t, v, acc->count);
    if (gyrocal_accum_finish(acc, t->rate, &obs) != GYROCAL_OK) {
        t->status = GYROCAL_TURN_BAD_WINDOW; /* obs unset: the means are not reported */
        t->mean[0] = t->mean[1] = t->mean[2] = 0.0f;
    } else {
        for (i = 0; i < 3; ++i) {
            t->mean[i] = obs.mean[i];
        }
    }
    if (t->status == GYROCAL_TURN_ACCEPTED) {
        s->obs[t->slot] = obs;
        s->have = (uint8_t)(s->have | (1u << t->slot));
        if (s->have == 0x3Fu) {
            gyrocal_scale_bias_t sb;
            int it = 0;
            s->status = gyrocal_first_moment(s->obs, &sb, &it);
            s->iterations = it;
            if (s->status == GYROCAL_OK) {
                s->result = sb;
            }
            events |= GYROCAL_SESSION_RESULT;
        }
    }
    enter_still(s);
    return events;
}

/* Power-up standstill: its mean is the first standstill reading. */
static void add_settling(gyrocal_session_t *s, const int16_t raw[3])
{
    float x[3];
    int i;
    to_float(raw, x);
    gyrocal_accum_add(&s->acc[0], x);
    if (s->acc[0].count >= s->settle_n) {
        gyrocal_obs_t obs;
        if (gyrocal_accum_finish(&s->acc[0], 1.0f, &obs) != GYROCAL_OK) {
            gyrocal_accum_reset(&s->acc[0]); /* settle again */
            return;
        }
        for (i = 0; i < 3; ++i) {
            s->base[i] = obs.mean[i];
        }
        enter_still(s);
    }
}

unsigned gyrocal_session_add(gyrocal_session_t *s, const int16_t raw[3])
{
    float d[3], x[3];
    unsigned events = 0u;
    int i;
    if (s == 0 || raw == 0) {
        return 0u;
    }
    if (s->phase == SETTLING) {
        add_settling(s, raw);
    } else if (s->phase == STILL) {
        add_still(s, raw);
        if (off_base(s, raw, d) > s->threshold) {
            if (++s->run >= GYROCAL_SESSION_START_N) {
                start_turn(s);
            }
        } else {
            float alpha = 1.0f / (float)s->settle_n; /* follow a slowly drifting standstill reading */
            s->run = 0u;
            for (i = 0; i < 3; ++i) {
                s->base[i] += alpha * d[i];
            }
        }
    } else {
        float mag = off_base(s, raw, d);
        to_float(raw, x);
        gyrocal_accum_add(&s->acc[s->cur], x);
        s->run = mag > s->threshold ? 0u : s->run + 1u;
        if (s->run >= s->quiet_n || s->acc[s->cur].count >= s->max_n) {
            events = end_turn(s);
        }
    }
    ++s->seq;
    return events;
}
