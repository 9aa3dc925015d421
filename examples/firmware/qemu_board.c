/*
 * qemu_board.c: a board layer for QEMU's mps2-an386 (Cortex-M4F), used by tools/cross_m4.sh to run the
 * example firmware on an emulated microcontroller. The "gyro" plays the paper's six turns (60 deg/s,
 * 200 Hz, MPU-6050 counts at 131 LSB per deg/s, white noise from a fixed xorshift); the "UART" prints
 * every byte as hex through semihosting. Built with -DGYROCAL_HOST it runs on the host with the same
 * output, so the two can be compared byte for byte.
 */
#include <stdint.h>

#include "board.h"
#include "gyrocal_example.h"
#include "semihost.h"

#define FS 200.0f
#define SENS 131.0f
#define TURN_N 1200u   /* 360 deg at 60 deg/s: 6 s */
#define WAIT_N 600u    /* 3 s between turns */
#define LEAD_N 400u    /* 2 s still at the start */

static const float K_TRUE[3] = {1.02f, 0.98f, 1.01f};  /* deg/s true = k (counts/SENS + b) */
static const float B_TRUE[3] = {1.5f, -2.0f, 0.8f};     /* [deg/s] */
static uint32_t rng_state = 2463534242u, n_sample;
static char line[2 * GYROCAL_FRAME_MAX + 2];

static float noise(void) /* xorshift32; sum of four uniforms: zero mean, std 0.6 deg/s */
{
    float s = 0.0f;
    for (int i = 0; i < 4; ++i) {
        rng_state ^= rng_state << 13;
        rng_state ^= rng_state >> 17;
        rng_state ^= rng_state << 5;
        s += (float)(rng_state >> 8) * (1.0f / 16777216.0f);
    }
    return (s - 2.0f) * 1.7320508f * 0.6f;
}

int board_read(int16_t raw[3], int16_t accel[3], int16_t *temp_centi)
{
    uint32_t i = n_sample, period = TURN_N + WAIT_N, turn;
    float w[3] = {0.0f, 0.0f, 0.0f};
    if (i >= LEAD_N + 6u * period) {
        return 1;
    }
    if (i >= LEAD_N && (i - LEAD_N) % period < TURN_N) {
        turn = (i - LEAD_N) / period;
        w[turn / 2u] = (turn % 2u) ? -60.0f : 60.0f;
    }
    for (int a = 0; a < 3; ++a) {
        float counts = (w[a] / K_TRUE[a] - B_TRUE[a] + noise()) * SENS;
        raw[a] = (int16_t)(counts < 0.0f ? counts - 0.5f : counts + 0.5f);
    }
    accel[0] = accel[1] = 0; /* flat on a table: 1 g on z (16384 counts per g), sent only in 6-axis mode */
    accel[2] = 16384;
    *temp_centi = 2500;
    ++n_sample;
    return 0;
}

void board_write(const uint8_t *data, size_t n)
{
    static const char hex[] = "0123456789abcdef";
    size_t i;
    for (i = 0; i < n && i < GYROCAL_FRAME_MAX; ++i) {
        line[2 * i] = hex[data[i] >> 4];
        line[2 * i + 1] = hex[data[i] & 0xFu];
    }
    line[2 * i] = '\n';
    line[2 * i + 1] = '\0';
    sh_puts(line);
}

uint32_t board_micros(void)
{
    return n_sample * 5000u;
}

uint32_t board_millis(void)
{
    return board_micros() / 1000u;
}

size_t board_receive(uint8_t *data, size_t cap) /* this demo has no host to listen to */
{
    (void)data;
    (void)cap;
    return 0u;
}

static uint8_t flash_page[GYROCAL_FRAME_MAX]; /* RAM stands in for the flash page */

int board_store(const uint8_t *data, size_t n)
{
    size_t i;
    if (n > sizeof flash_page) {
        return 1;
    }
    for (i = 0; i < n; ++i) {
        flash_page[i] = data[i];
    }
    return 0;
}

int board_load(uint8_t *data, size_t n)
{
    size_t i;
    if (n > sizeof flash_page) {
        return 1;
    }
    for (i = 0; i < n; ++i) {
        data[i] = flash_page[i];
    }
    return 0;
}

int main(void)
{
    static example_t ex;
    example_setup(&ex, FS, SENS, 0u, 1);
    while (example_step(&ex) == 0) {
    }
    return 0;
}
