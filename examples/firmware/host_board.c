/*
 * host_board.c: a fake board layer for host tests. It plays a recorded or simulated session given as
 * arrays and collects everything the firmware sends in a buffer; example_run() drives the example
 * firmware over the whole session. example_host_input() gives it bytes from the host (a write-back) to
 * receive once a given sample has been read; the storage is a RAM page, example_page() reads it. Built into a shared library by tests/test_capture_firmware.py.
 */
#include "board.h"
#include "gyrocal_example.h"

static const int16_t *g_raw, *g_accel, *g_temp;
static const uint32_t *g_t_us;
static uint32_t g_n, g_i;
static uint8_t *g_out;
static size_t g_cap, g_len, g_dropped;
static const uint8_t *g_in;
static size_t g_in_n, g_in_pos;
static uint32_t g_in_at;
static uint8_t g_page[256];
static size_t g_page_n;

int board_read(int16_t raw[3], int16_t accel[3], int16_t *temp_centi)
{
    int i;
    if (g_i >= g_n) {
        return 1;
    }
    for (i = 0; i < 3; ++i) {
        raw[i] = g_raw[3 * g_i + i];
        if (g_accel) {
            accel[i] = g_accel[3 * g_i + i];
        }
    }
    *temp_centi = g_temp ? g_temp[g_i] : GYROCAL_TEMP_NONE;
    ++g_i;
    return 0;
}

void board_write(const uint8_t *data, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        if (g_len < g_cap) {
            g_out[g_len++] = data[i];
        } else {
            ++g_dropped;
        }
    }
}

uint32_t board_micros(void)
{
    return g_t_us[g_i - 1u]; /* the stamp of the sample just read */
}

size_t board_receive(uint8_t *data, size_t cap)
{
    size_t n = 0u;
    while (g_in && g_i > g_in_at && g_in_pos < g_in_n && n < cap) {
        data[n++] = g_in[g_in_pos++];
    }
    return n;
}

int board_store(const uint8_t *data, size_t n)
{
    size_t i;
    if (n > sizeof g_page) {
        return 1;
    }
    for (i = 0; i < n; ++i) {
        g_page[i] = data[i];
    }
    g_page_n = n;
    return 0;
}

int board_load(uint8_t *data, size_t n)
{
    size_t i;
    if (n > g_page_n) {
        return 1;
    }
    for (i = 0; i < n; ++i) {
        data[i] = g_page[i];
    }
    return 0;
}

/* Bytes from the host, received from sample `at` on (read by the next example_run; NULL: none). */
void example_host_input(const uint8_t *in, size_t n, uint32_t at)
{
    g_in = in;
    g_in_n = n;
    g_in_pos = 0u;
    g_in_at = at;
}

/* The storage page: copies up to cap bytes into out, returns how many it holds. */
size_t example_page(uint8_t *out, size_t cap)
{
    size_t i;
    for (i = 0; i < g_page_n && i < cap; ++i) {
        out[i] = g_page[i];
    }
    return g_page_n;
}

uint32_t board_millis(void)
{
    return board_micros() / 1000u;
}

/* Run the example firmware over n samples (accel may be NULL: gyro only); returns the bytes sent, or 0 if
 * `out` was too small. */
size_t example_run(const int16_t *raw, const int16_t *accel, const uint32_t *t_us, const int16_t *temp, uint32_t n,
                   float sample_rate, float sensitivity, uint16_t accel_sensitivity, uint8_t *out, size_t cap)
{
    static example_t ex;
    g_raw = raw;
    g_accel = accel;
    g_t_us = t_us;
    g_temp = temp;
    g_n = n;
    g_i = 0u;
    g_out = out;
    g_cap = cap;
    g_len = g_dropped = 0u;
    example_setup(&ex, sample_rate, sensitivity, accel ? accel_sensitivity : 0u, temp != 0);
    while (example_step(&ex) == 0) {
    }
    return g_dropped ? 0u : g_len;
}
