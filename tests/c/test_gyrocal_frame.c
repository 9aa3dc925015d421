/*
 * Native tests of the frame encoder (gyrocal_frame.h) and the on-device session (gyrocal_session.h), built by
 * tests/test_c_native.py with -fsanitize=address,undefined.
 *
 * References: the CRC-16/CCITT-FALSE check value 0x29B1 of "123456789" (the CRC catalogue's), a sample
 * frame, a 6-axis (IMU) frame and an end frame written out by hand from docs/capture.md's byte tables, and noise-free six-turn
 * sessions (200 Hz, and 1 kHz with 1 s ramps) built from a known k and b, which the session must find to the readings' rounding.
 * Exit status: the number of failed checks (0 = all passed).
 */
#include "gyrocal_frame.h"
#include "gyrocal_session.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static int failures = 0;

#define CHECK(cond)                                                                   \
    do {                                                                              \
        if (!(cond)) {                                                                \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);  \
            ++failures;                                                               \
        }                                                                             \
    } while (0)

static void test_crc_and_sample_frame(void)
{
    static const uint8_t check[9] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    /* seq 1, t 5000 us, raw (1, -2, 300), temperature 25.00 degC */
    static const uint8_t payload[16] = {1, 0, 0, 0, 0x88, 0x13, 0, 0, 1, 0, 0xFE, 0xFF, 0x2C, 0x01, 0xC4, 0x09};
    const int16_t raw[3] = {1, -2, 300};
    uint8_t out[GYROCAL_FRAME_MAX], head[2 + 16];
    uint16_t crc;
    CHECK(gyrocal_crc16(check, 9, 0xFFFFu) == 0x29B1u);
    CHECK(gyrocal_frame_sample(out, 1u, 5000u, raw, 2500) == GYROCAL_FRAME_SAMPLE_SIZE);
    CHECK(out[0] == 0xA5u && out[1] == 0x5Au && out[2] == GYROCAL_FRAME_SAMPLE && out[3] == 16u);
    CHECK(memcmp(out + 4, payload, 16) == 0);
    head[0] = GYROCAL_FRAME_SAMPLE;
    head[1] = 16u;
    memcpy(head + 2, payload, 16);
    crc = gyrocal_crc16(head, sizeof head, 0xFFFFu);
    CHECK(out[20] == (crc & 0xFFu) && out[21] == (crc >> 8));
}

static void test_imu_and_end_frames(void)
{
    /* seq 2, t 10000 us, gyro (1, -2, 300), accel (-16384, 0, 8192), no temperature */
    static const uint8_t payload[22] = {2, 0, 0, 0, 0x10, 0x27, 0, 0, 1, 0, 0xFE, 0xFF, 0x2C, 0x01,
                                        0x00, 0xC0, 0, 0, 0x00, 0x20, 0x00, 0x80};
    static const uint8_t end[4] = {0x39, 0x30, 0, 0}; /* 12345 samples */
    const int16_t gyro[3] = {1, -2, 300}, accel[3] = {-16384, 0, 8192};
    uint8_t out[GYROCAL_FRAME_MAX], head[2 + 22];
    uint16_t crc;
    CHECK(gyrocal_frame_imu(out, 2u, 10000u, gyro, accel, GYROCAL_TEMP_NONE) == GYROCAL_FRAME_IMU_SIZE);
    CHECK(out[0] == 0xA5u && out[1] == 0x5Au && out[2] == GYROCAL_FRAME_IMU && out[3] == 22u);
    CHECK(memcmp(out + 4, payload, 22) == 0);
    head[0] = GYROCAL_FRAME_IMU;
    head[1] = 22u;
    memcpy(head + 2, payload, 22);
    crc = gyrocal_crc16(head, sizeof head, 0xFFFFu);
    CHECK(out[26] == (crc & 0xFFu) && out[27] == (crc >> 8));
    CHECK(gyrocal_frame_end(out, 12345u) == GYROCAL_FRAME_OVERHEAD + 4u);
    CHECK(out[2] == GYROCAL_FRAME_END && out[3] == 4u && memcmp(out + 4, end, 4) == 0);
    CHECK(gyrocal_frame_imu(out, 0u, 0u, gyro, 0, 0) == 0u && gyrocal_frame_imu(out, 0u, 0u, 0, accel, 0) == 0u);
    CHECK(gyrocal_frame_imu(0, 0u, 0u, gyro, accel, 0) == 0u && gyrocal_frame_end(0, 1u) == 0u);
}

static void test_null_and_limits(void)
{
    uint8_t out[GYROCAL_FRAME_MAX];
    char longer[100];
    memset(longer, 'a', sizeof longer - 1);
    longer[sizeof longer - 1] = '\0';
    CHECK(gyrocal_frame_sample(0, 0u, 0u, 0, 0) == 0u);
    CHECK(gyrocal_frame_hello(out, 0) == 0u && gyrocal_frame_turn(out, 0) == 0u && gyrocal_frame_text(out, 0) == 0u);
    CHECK(gyrocal_frame(out, 1u, out, GYROCAL_FRAME_MAX_PAYLOAD + 1u) == 0u);
    CHECK(gyrocal_frame_text(out, longer) == GYROCAL_FRAME_MAX); /* cut at the payload limit, in bounds */
    CHECK(gyrocal_frame_result(out, GYROCAL_E_SINGULAR, 0u, 0u, 6u, 0, 7u) == GYROCAL_FRAME_OVERHEAD + 32u);
    CHECK(gyrocal_session_init(0, 200.0f, 131.0f, 360.0f) == GYROCAL_E_INPUT);
    CHECK(gyrocal_session_add(0, 0) == 0u);
}

/* Noise-free readings [counts] of true rate w [deg/s] about one axis: raw = w / k - b. */
static void reading(const float k[3], const float b[3], int axis, float w, int16_t raw[3])
{
    int i;
    for (i = 0; i < 3; ++i) {
        float c = (i == axis ? w : 0.0f) / k[i] - b[i];
        raw[i] = (int16_t)(c < 0.0f ? c - 0.5f : c + 0.5f);
    }
}

/* Rate [deg/s] n samples into a turn of ramp_n samples up, plateau_n at w, ramp_n down (0 after it). */
static float profile(int n, int ramp_n, int plateau_n, float w)
{
    if (n < ramp_n) {
        return w * ((float)n + 0.5f) / (float)ramp_n;
    }
    if (n < ramp_n + plateau_n) {
        return w;
    }
    n -= ramp_n + plateau_n;
    return n < ramp_n ? w * ((float)(ramp_n - n) - 0.5f) / (float)ramp_n : 0.0f;
}

/* The six turns at 60 deg/s (360 deg each, with ramp_s ramps) and 3 s still between, at fs [Hz]:
 * every turn accepted, one result, and k, b of the noise-free readings to rounding. */
static void six_turns(float fs, float ramp_s)
{
    static gyrocal_session_t s;
    const float k[3] = {1.0f / 131.0f, 1.02f / 131.0f, 0.98f / 131.0f}; /* deg/s per count */
    const float b[3] = {200.0f, -150.0f, 80.0f};                        /* counts */
    const int ramp_n = (int)(ramp_s * fs + 0.5f), plateau_n = (int)((6.0f - ramp_s) * fs + 0.5f);
    int16_t raw[3];
    unsigned events, turns = 0u, results = 0u;
    int turn, n;
    CHECK(gyrocal_session_init(&s, fs, 131.0f, 360.0f) == GYROCAL_OK);
    for (n = 0; n < (int)(2.0f * fs); ++n) { /* 2 s still */
        reading(k, b, 0, 0.0f, raw);
        gyrocal_session_add(&s, raw);
    }
    for (turn = 0; turn < 6; ++turn) {
        for (n = 0; n < 2 * ramp_n + plateau_n + (int)(3.0f * fs); ++n) {
            reading(k, b, turn / 2, profile(n, ramp_n, plateau_n, (turn % 2) ? -60.0f : 60.0f), raw);
            events = gyrocal_session_add(&s, raw);
            if (events & GYROCAL_SESSION_TURN) {
                ++turns;
                CHECK(s.turn.status == GYROCAL_TURN_ACCEPTED && s.turn.slot == (uint8_t)turn);
            }
            results += (events & GYROCAL_SESSION_RESULT) ? 1u : 0u;
        }
    }
    CHECK(turns == 6u && results == 1u && s.status == GYROCAL_OK);
    /* rounding the readings to counts moves k by about 0.5 / 7860 at most; a window that missed the
     * ramp under the 10 deg/s band (about 0.5 deg of 360 at 1 kHz with 1 s ramps) moves it by 1.5e-3 */
    for (n = 0; n < 3; ++n) {
        CHECK(fabsf(s.result.k[n] / k[n] - 1.0f) < 2e-4f);
        CHECK(fabsf(s.result.b[n] - b[n]) < 1.0f);
    }
}

static void test_set_calibration_round_trip(void)
{
    /* seq 7, apply, deg/s; matrix[0][0] = 1.0f (00 00 80 3F), offset[2] = -2.5f (00 00 20 C0) */
    static const uint8_t head[8] = {7, 0, 0, 0, GYROCAL_SETCAL_APPLY, GYROCAL_UNIT_DEG_S, 0, 0};
    static const uint8_t one[4] = {0x00, 0x00, 0x80, 0x3F}, minus[4] = {0x00, 0x00, 0x20, 0xC0};
    gyrocal_set_calibration_t set = {7u, GYROCAL_SETCAL_APPLY, GYROCAL_UNIT_DEG_S,
                                     {{{1.0f, 0.01f, -0.02f}, {0.0f, 0.98f, 0.0f}, {1e-3f, 0.0f, 7.6e-3f}},
                                      {1.5f, 12.0f, -2.5f}}};
    gyrocal_set_calibration_t got;
    gyrocal_frame_rx_t rx;
    uint8_t out[GYROCAL_FRAME_MAX], echo[GYROCAL_FRAME_MAX], bad[GYROCAL_FRAME_MAX];
    size_t n, i;
    unsigned type = 0u, seen = 0u;
    n = gyrocal_frame_set_calibration(out, &set);
    CHECK(n == GYROCAL_FRAME_SET_CALIBRATION_SIZE && out[2] == GYROCAL_FRAME_SET_CALIBRATION && out[3] == 56u);
    CHECK(memcmp(out + 4, head, 8) == 0 && memcmp(out + 12, one, 4) == 0 && memcmp(out + 56, minus, 4) == 0);
    /* noise, a false sync, then a frame with a flipped bit (dropped), then the good one */
    memcpy(bad, out, n);
    bad[20] ^= 0x10u;
    gyrocal_frame_rx_reset(&rx);
    for (i = 0; i < 3; ++i) {
        seen |= gyrocal_frame_rx_byte(&rx, i == 1u ? 0xA5u : 0x00u);
    }
    for (i = 0; i < n; ++i) {
        seen |= gyrocal_frame_rx_byte(&rx, bad[i]);
    }
    for (i = 0; i < n; ++i) {
        type = gyrocal_frame_rx_byte(&rx, out[i]);
        CHECK(i + 1u == n || type == 0u);
    }
    CHECK(seen == 0u && type == GYROCAL_FRAME_SET_CALIBRATION);
    /* a false start whose length byte is the real frame's sync: the receiver finds that sync again */
    seen = gyrocal_frame_rx_byte(&rx, 0xA5u) | gyrocal_frame_rx_byte(&rx, 0x5Au) | gyrocal_frame_rx_byte(&rx, 7u);
    for (i = 0; i < n; ++i) {
        type = gyrocal_frame_rx_byte(&rx, out[i]);
    }
    CHECK(seen == 0u && type == GYROCAL_FRAME_SET_CALIBRATION);
    CHECK(gyrocal_parse_set_calibration(rx.buf + 4, rx.buf[3], &got) == GYROCAL_OK);
    CHECK(memcmp(&got.cal, &set.cal, sizeof set.cal) == 0 && got.seq == 7u && got.flags == set.flags);
    /* the echo is the request with another type and its status byte */
    CHECK(gyrocal_frame_calibration_stored(echo, GYROCAL_STORED_OK, &got) == n);
    CHECK(echo[2] == GYROCAL_FRAME_CALIBRATION_STORED && memcmp(echo + 3, out + 3, n - 5u) == 0);
    CHECK(gyrocal_frame_calibration_stored(echo, GYROCAL_STORED_FAILED, 0) == n && echo[10] == 2u && echo[12] == 0u);
    /* refused: a NaN, an unknown unit, a wrong length, NULL; *out untouched */
    memset(&got, 0, sizeof got);
    memcpy(bad, out, n);
    bad[15] = 0x7Fu;
    bad[14] = 0xC0u;
    CHECK(gyrocal_parse_set_calibration(bad + 4, 56u, &got) == GYROCAL_E_INPUT && got.seq == 0u);
    memcpy(bad, out, n);
    bad[9] = 2u;
    CHECK(gyrocal_parse_set_calibration(bad + 4, 56u, &got) == GYROCAL_E_INPUT && got.seq == 0u);
    CHECK(gyrocal_parse_set_calibration(out + 4, 55u, &got) == GYROCAL_E_INPUT);
    CHECK(gyrocal_parse_set_calibration(0, 56u, &got) == GYROCAL_E_INPUT);
    CHECK(gyrocal_frame_set_calibration(out, 0) == 0u && gyrocal_frame_rx_byte(0, 0xA5u) == 0u);
}

static void test_session_finds_the_six_turns(void)
{
    six_turns(200.0f, 0.0f);
    six_turns(200.0f, 0.3f);
    six_turns(1000.0f, 1.0f); /* slow ramps at a high rate: the window before the start is sized in time */
}

static void test_session_at_a_low_rate(void)
{
    static gyrocal_session_t s;
    const int16_t raw[3] = {1, 2, 3};
    int n;
    CHECK(gyrocal_session_init(&s, 1.0f, 131.0f, 360.0f) == GYROCAL_OK);
    for (n = 0; n < 3; ++n) {
        gyrocal_session_add(&s, raw);
    }
    CHECK(s.phase == 1u && s.base[0] == 1.0f && s.base[2] == 3.0f); /* settled on two samples, not one */
}

int main(void)
{
    test_crc_and_sample_frame();
    test_imu_and_end_frames();
    test_null_and_limits();
    test_session_finds_the_six_turns();
    test_set_calibration_round_trip();
    test_session_at_a_low_rate();
    return failures;
}
