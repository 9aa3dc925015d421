/*
 * gyrocal_frame.c: gyrocal frame encoder (part of gyrocal, MIT licence). See gyrocal_frame.h.
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
