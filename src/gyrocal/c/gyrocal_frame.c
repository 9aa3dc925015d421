/*
 * gyrocal_frame.c: gyrocal frame encoder, and the receiver of host frames (part of gyrocal, MIT licence).
 * See gyrocal_frame.h.
 * Fields are written byte by byte with shifts, so the output is the same on any endianness.
 */
#include "gyrocal_frame.h"

uint16_t gyrocal_crc16(const uint8_t *data, size_t n, uint16_t crc)
{
    size_t i;
    int bit;
    if (data == 0) {
        return crc;
    }
    for (i = 0; i < n; ++i) {
        crc ^= (uint16_t)((uint16_t)data[i] << 8);
        for (bit = 0; bit < 8; ++bit) {
            crc = (crc & 0x8000u) ? (uint16_t)((crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
        }
    }
    return crc;
}

static uint8_t *put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
    return p + 2;
}

static uint8_t *put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
    p[2] = (uint8_t)((v >> 16) & 0xFFu);
    p[3] = (uint8_t)(v >> 24);
    return p + 4;
}

static uint8_t *put_f32(uint8_t *p, float x)
{
    union {
        float f;
        uint32_t u;
    } bits;
    bits.f = x;
    return put_u32(p, bits.u);
}

size_t gyrocal_frame(uint8_t out[GYROCAL_FRAME_MAX], uint8_t type, const uint8_t *payload, size_t len)
{
    size_t i;
    uint16_t crc;
    if (out == 0 || len > GYROCAL_FRAME_MAX_PAYLOAD || (payload == 0 && len > 0u)) {
        return 0u;
    }
    out[0] = GYROCAL_FRAME_SYNC0;
    out[1] = GYROCAL_FRAME_SYNC1;
    out[2] = type;
    out[3] = (uint8_t)len;
    if (payload != out + 4) { /* encoders below build the payload in place */
        for (i = 0; i < len; ++i) {
            out[4 + i] = payload[i];
        }
    }
    crc = gyrocal_crc16(out + 2, len + 2u, 0xFFFFu);
    put_u16(out + 4 + len, crc);
    return len + GYROCAL_FRAME_OVERHEAD;
}

size_t gyrocal_frame_hello(uint8_t out[GYROCAL_FRAME_MAX], const gyrocal_hello_t *hello)
{
    uint8_t *p;
    int i;
    if (out == 0 || hello == 0) {
        return 0u;
    }
    p = out + 4;
    *p++ = GYROCAL_FRAME_PROTOCOL;
    *p++ = hello->flags;
    *p++ = hello->rate_unit;
    *p++ = 0u;
    p = put_f32(p, hello->sample_rate);
    p = put_f32(p, hello->sensitivity);
    p = put_u16(p, hello->library);
    p = put_u16(p, hello->accel_sensitivity);
    for (i = 0; i < 16; ++i) {
        *p++ = (uint8_t)hello->firmware[i];
    }
    return gyrocal_frame(out, GYROCAL_FRAME_HELLO, out + 4, GYROCAL_FRAME_HELLO_LEN);
}

size_t gyrocal_frame_sample(uint8_t out[GYROCAL_FRAME_MAX], uint32_t seq, uint32_t t_us, const int16_t raw[3],
                            int16_t temp_centi)
{
    uint8_t *p;
    int i;
    if (out == 0 || raw == 0) {
        return 0u;
    }
    p = put_u32(out + 4, seq);
    p = put_u32(p, t_us);
    for (i = 0; i < 3; ++i) {
        p = put_u16(p, (uint16_t)raw[i]);
    }
    put_u16(p, (uint16_t)temp_centi);
    return gyrocal_frame(out, GYROCAL_FRAME_SAMPLE, out + 4, GYROCAL_FRAME_SAMPLE_LEN);
}

size_t gyrocal_frame_imu(uint8_t out[GYROCAL_FRAME_MAX], uint32_t seq, uint32_t t_us, const int16_t gyro[3],
                         const int16_t accel[3], int16_t temp_centi)
{
    uint8_t *p;
    int i;
    if (out == 0 || gyro == 0 || accel == 0) {
        return 0u;
    }
    p = put_u32(out + 4, seq);
    p = put_u32(p, t_us);
    for (i = 0; i < 3; ++i) {
        p = put_u16(p, (uint16_t)gyro[i]);
    }
    for (i = 0; i < 3; ++i) {
        p = put_u16(p, (uint16_t)accel[i]);
    }
    put_u16(p, (uint16_t)temp_centi);
    return gyrocal_frame(out, GYROCAL_FRAME_IMU, out + 4, GYROCAL_FRAME_IMU_LEN);
}

size_t gyrocal_frame_calibrated(uint8_t out[GYROCAL_FRAME_MAX], uint32_t seq, uint32_t t_us, const float w[3])
{
    uint8_t *p;
    int i;
    if (out == 0 || w == 0) {
        return 0u;
    }
    p = put_u32(out + 4, seq);
    p = put_u32(p, t_us);
    for (i = 0; i < 3; ++i) {
        p = put_f32(p, w[i]);
    }
    return gyrocal_frame(out, GYROCAL_FRAME_CALIBRATED, out + 4, GYROCAL_FRAME_CALIBRATED_LEN);
}

size_t gyrocal_frame_turn(uint8_t out[GYROCAL_FRAME_MAX], const gyrocal_turn_t *turn)
{
    uint8_t *p;
    int i;
    if (out == 0 || turn == 0) {
        return 0u;
    }
    p = put_u32(out + 4, turn->start);
    p = put_u32(p, turn->stop);
    p = put_f32(p, turn->rate);
    p = put_f32(p, turn->angle);
    for (i = 0; i < 3; ++i) {
        p = put_f32(p, turn->mean[i]);
    }
    *p++ = turn->slot;
    *p++ = turn->status;
    put_u16(p, 0u);
    return gyrocal_frame(out, GYROCAL_FRAME_TURN, out + 4, GYROCAL_FRAME_TURN_LEN);
}

size_t gyrocal_frame_result(uint8_t out[GYROCAL_FRAME_MAX], gyrocal_status_t status, uint8_t method,
                            uint8_t iterations, uint8_t n_turns, const gyrocal_scale_bias_t *sb, uint32_t seq)
{
    uint8_t *p;
    int i;
    if (out == 0) {
        return 0u;
    }
    p = out + 4;
    *p++ = (uint8_t)status;
    *p++ = method;
    *p++ = iterations;
    *p++ = n_turns;
    for (i = 0; i < 3; ++i) {
        p = put_f32(p, sb ? sb->k[i] : 0.0f);
    }
    for (i = 0; i < 3; ++i) {
        p = put_f32(p, sb ? sb->b[i] : 0.0f);
    }
    put_u32(p, seq);
    return gyrocal_frame(out, GYROCAL_FRAME_RESULT, out + 4, GYROCAL_FRAME_RESULT_LEN);
}

size_t gyrocal_frame_text(uint8_t out[GYROCAL_FRAME_MAX], const char *text)
{
    size_t n = 0u;
    if (out == 0 || text == 0) {
        return 0u;
    }
    while (n < GYROCAL_FRAME_MAX_PAYLOAD && text[n] != '\0') {
        out[4 + n] = (uint8_t)text[n];
        ++n;
    }
    return gyrocal_frame(out, GYROCAL_FRAME_TEXT, out + 4, n);
}

size_t gyrocal_frame_end(uint8_t out[GYROCAL_FRAME_MAX], uint32_t n_samples)
{
    if (out == 0) {
        return 0u;
    }
    put_u32(out + 4, n_samples);
    return gyrocal_frame(out, GYROCAL_FRAME_END, out + 4, GYROCAL_FRAME_END_LEN);
}

/* seq, flags, rate unit, a byte (the status of an answer, 0 in a request), a reserved byte, matrix row by row,
 * offset: both frames have this layout, so an echo is the request with its status filled in. */
static size_t put_calibration(uint8_t out[GYROCAL_FRAME_MAX], uint8_t type, uint8_t status,
                              const gyrocal_set_calibration_t *c)
{
    uint8_t *p = put_u32(out + 4, c ? c->seq : 0u);
    int i, j;
    *p++ = c ? c->flags : 0u;
    *p++ = c ? c->rate_unit : 0u;
    *p++ = status;
    *p++ = 0u;
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j) {
            p = put_f32(p, c ? c->cal.matrix[i][j] : 0.0f);
        }
    }
    for (i = 0; i < 3; ++i) {
        p = put_f32(p, c ? c->cal.offset[i] : 0.0f);
    }
    return gyrocal_frame(out, type, out + 4, GYROCAL_FRAME_SET_CALIBRATION_LEN);
}

size_t gyrocal_frame_set_calibration(uint8_t out[GYROCAL_FRAME_MAX], const gyrocal_set_calibration_t *set)
{
    if (out == 0 || set == 0) {
        return 0u;
    }
    return put_calibration(out, GYROCAL_FRAME_SET_CALIBRATION, 0u, set);
}

size_t gyrocal_frame_calibration_stored(uint8_t out[GYROCAL_FRAME_MAX], uint8_t status,
                                        const gyrocal_set_calibration_t *stored)
{
    if (out == 0) {
        return 0u;
    }
    return put_calibration(out, GYROCAL_FRAME_CALIBRATION_STORED, status, stored);
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* The float at p; *bad is set when it is a NaN or an infinity (all exponent bits set: no libc needed). */
static float get_f32(const uint8_t *p, int *bad)
{
    union {
        float f;
        uint32_t u;
    } bits;
    bits.u = get_u32(p);
    if ((bits.u & 0x7F800000u) == 0x7F800000u) {
        *bad = 1;
    }
    return bits.f;
}

gyrocal_status_t gyrocal_parse_set_calibration(const uint8_t *payload, size_t len, gyrocal_set_calibration_t *out)
{
    gyrocal_set_calibration_t c;
    const uint8_t *p;
    int i, j, bad = 0;
    if (payload == 0 || out == 0 || len != GYROCAL_FRAME_SET_CALIBRATION_LEN) {
        return GYROCAL_E_INPUT;
    }
    c.seq = get_u32(payload);
    c.flags = payload[4];
    c.rate_unit = payload[5];
    p = payload + 8;
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j, p += 4) {
            c.cal.matrix[i][j] = get_f32(p, &bad);
        }
    }
    for (i = 0; i < 3; ++i, p += 4) {
        c.cal.offset[i] = get_f32(p, &bad);
    }
    if (bad || c.rate_unit > GYROCAL_UNIT_DEG_S) {
        return GYROCAL_E_INPUT;
    }
    *out = c;
    return GYROCAL_OK;
}

void gyrocal_frame_rx_reset(gyrocal_frame_rx_t *rx)
{
    if (rx != 0) {
        rx->len = 0u;
    }
}

/* The bytes held did not make a frame (a length too large, a CRC that does not match): keep them from the next sync
 * on, as the host's decoder does, so a false start does not swallow the frame that follows it. */
static void rx_resync(gyrocal_frame_rx_t *rx)
{
    uint8_t i, j;
    do {
        for (i = 1u; i < rx->len; ++i) {
            if (rx->buf[i] == GYROCAL_FRAME_SYNC0 && (i + 1u == rx->len || rx->buf[i + 1u] == GYROCAL_FRAME_SYNC1)) {
                break;
            }
        }
        for (j = 0u; i < rx->len; ++i, ++j) {
            rx->buf[j] = rx->buf[i];
        }
        rx->len = j;
    } while (rx->len >= 4u && rx->buf[3] > GYROCAL_FRAME_MAX_PAYLOAD);
}

unsigned gyrocal_frame_rx_byte(gyrocal_frame_rx_t *rx, uint8_t byte)
{
    size_t n;
    uint16_t crc;
    if (rx == 0) {
        return 0u;
    }
    if (rx->len >= GYROCAL_FRAME_MAX || (rx->len == 0u && byte != GYROCAL_FRAME_SYNC0)) {
        rx->len = 0u;
        return 0u;
    }
    if (rx->len == 1u && byte != GYROCAL_FRAME_SYNC1) {
        rx->len = byte == GYROCAL_FRAME_SYNC0 ? 1u : 0u; /* A5 A5 5A: the second A5 may start the frame */
        return 0u;
    }
    rx->buf[rx->len++] = byte;
    if (rx->len == 4u && rx->buf[3] > GYROCAL_FRAME_MAX_PAYLOAD) {
        rx_resync(rx);
        return 0u;
    }
    n = rx->len < 4u ? GYROCAL_FRAME_MAX : (size_t)rx->buf[3] + GYROCAL_FRAME_OVERHEAD;
    if (rx->len < n) {
        return 0u;
    }
    crc = gyrocal_crc16(rx->buf + 2, n - 4u, 0xFFFFu);
    if (rx->buf[n - 2u] != (crc & 0xFFu) || rx->buf[n - 1u] != (crc >> 8)) {
        rx_resync(rx);
        return 0u;
    }
    rx->len = 0u;
    return rx->buf[2];
}
