/*
 * gyrocal_session.c: on-device six-turn calibration (part of gyrocal, MIT licence). See gyrocal_session.h.
 */
#include "gyrocal_session.h"

#include <math.h>

enum { SETTLING = 0, STILL = 1, TURNING = 2 };

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
    s->quiet_n = (uint32_t)(GYROCAL_SESSION_QUIET_S * sample_rate) + 1u;
    s->max_n = (uint32_t)(GYROCAL_SESSION_MAX_S * sample_rate);
    s->seq = 0u;
    s->phase = SETTLING;
    s->have = 0u;
    s->ring_pos = s->ring_len = 0u;
    s->start = s->run = 0u;
    s->status = GYROCAL_E_INPUT; /* no result yet */
    s->iterations = 0;
    gyrocal_accum_reset(&s->acc);
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

static void add_to_turn(gyrocal_session_t *s, const int16_t raw[3])
{
    float x[3], d[3];
    int i;
    off_base(s, raw, d);
    for (i = 0; i < 3; ++i) {
        x[i] = (float)raw[i];
        s->sum[i] += d[i];
    }
    gyrocal_accum_add(&s->acc, x);
}

/* A turn starts: its window begins with the samples kept in the ring. */
static void start_turn(gyrocal_session_t *s)
{
    uint16_t i, first = (uint16_t)((s->ring_pos + GYROCAL_SESSION_PRE - s->ring_len) % GYROCAL_SESSION_PRE);
    gyrocal_accum_reset(&s->acc);
    s->sum[0] = s->sum[1] = s->sum[2] = 0.0f;
    s->start = s->seq + 1u - s->ring_len;
    for (i = 0; i < s->ring_len; ++i) {
        add_to_turn(s, s->ring[(first + i) % GYROCAL_SESSION_PRE]);
    }
    s->phase = TURNING;
    s->run = 0u;
}

/* A turn ends: check it, file it, and calibrate when the six slots are full. */
static unsigned end_turn(gyrocal_session_t *s)
{
    gyrocal_turn_t *t = &s->turn;
    gyrocal_obs_t obs;
    float v[3], norm2 = 0.0f, scale = 1.0f / (s->sensitivity * s->sample_rate);
    int i, ax = 0;
    unsigned events = GYROCAL_SESSION_TURN;
    for (i = 0; i < 3; ++i) {
        v[i] = s->sum[i] * scale; /* angle turned about each axis [deg] */
        norm2 += v[i] * v[i];
        if (fabsf(v[i]) > fabsf(v[ax])) {
            ax = i;
        }
    }
    t->start = s->start;
    t->stop = s->seq + 1u;
    t->angle = sqrtf(norm2);
    t->rate = s->turn_angle * s->sample_rate / (float)s->acc.count;
    t->slot = (uint8_t)(2 * ax + (v[ax] < 0.0f ? 1 : 0));
    gyrocal_accum_finish(&s->acc, t->rate, &obs);
    for (i = 0; i < 3; ++i) {
        t->mean[i] = obs.mean[i];
    }
    if (s->acc.count >= s->max_n) {
        t->status = GYROCAL_TURN_TOO_LONG;
    } else if (fabsf(t->angle - s->turn_angle) > GYROCAL_SESSION_ANGLE_TOL * s->turn_angle) {
        t->status = GYROCAL_TURN_WRONG_ANGLE;
    } else if (fabsf(v[ax]) < GYROCAL_SESSION_MIN_ON_AXIS * t->angle) {
        t->status = GYROCAL_TURN_OFF_AXIS;
    } else {
        t->status = GYROCAL_TURN_ACCEPTED;
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
    s->phase = STILL;
    s->ring_len = 0u;
    s->run = 0u;
    return events;
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
        for (i = 0; i < 3; ++i) {
            x[i] = (float)raw[i];
        }
        gyrocal_accum_add(&s->acc, x);
        if (s->acc.count >= s->settle_n) {
            gyrocal_obs_t obs;
            gyrocal_accum_finish(&s->acc, 1.0f, &obs);
            for (i = 0; i < 3; ++i) {
                s->base[i] = obs.mean[i];
            }
            s->phase = STILL;
        }
    } else if (s->phase == STILL) {
        for (i = 0; i < 3; ++i) {
            s->ring[s->ring_pos][i] = raw[i];
        }
        s->ring_pos = (uint16_t)((s->ring_pos + 1u) % GYROCAL_SESSION_PRE);
        if (s->ring_len < GYROCAL_SESSION_PRE) {
            ++s->ring_len;
        }
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
        add_to_turn(s, raw);
        s->run = mag > s->threshold ? 0u : s->run + 1u;
        if (s->run >= s->quiet_n || s->acc.count >= s->max_n) {
            events = end_turn(s);
        }
    }
    ++s->seq;
    return events;
}
