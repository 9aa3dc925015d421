/*
 * gyrocal_example.c: example firmware for `gyrocal capture` (part of gyrocal, MIT licence).
 * See gyrocal_example.h; the board layer is board.h.
 */
#include "gyrocal_example.h"

#include "board.h"

static void send_text(example_t *ex, const char *a, const char *b)
{
    char text[GYROCAL_FRAME_MAX_PAYLOAD + 1];
    size_t n = 0u;
    while (*a && n < GYROCAL_FRAME_MAX_PAYLOAD) {
        text[n++] = *a++;
    }
    while (*b && n < GYROCAL_FRAME_MAX_PAYLOAD) {
        text[n++] = *b++;
    }
    text[n] = '\0';
    board_write(ex->frame, gyrocal_frame_text(ex->frame, text));
}

void example_setup(example_t *ex, float sample_rate, float sensitivity, uint16_t accel_sensitivity, int has_temp)
{
    static const char name[] = EXAMPLE_FIRMWARE;
    gyrocal_hello_t hello;
    size_t i;
    gyrocal_session_init(&ex->session, sample_rate, sensitivity, 360.0f);
    ex->calibrated = ex->host_cal = 0;
    ex->send_accel = accel_sensitivity != 0u;
    ex->seq = 0u;
    gyrocal_frame_rx_reset(&ex->rx);
    hello.sample_rate = sample_rate;
    hello.sensitivity = sensitivity;
    hello.rate_unit = GYROCAL_UNIT_DEG_S;
    hello.flags = (uint8_t)((has_temp ? GYROCAL_HELLO_HAS_TEMP : 0u) | (ex->send_accel ? GYROCAL_HELLO_HAS_ACCEL : 0u));
    hello.library = GYROCAL_CAL_VERSION;
    hello.accel_sensitivity = accel_sensitivity;
    for (i = 0; i < sizeof hello.firmware; ++i) {
        hello.firmware[i] = i < sizeof name - 1u ? name[i] : '\0';
    }
    board_write(ex->frame, gyrocal_frame_hello(ex->frame, &hello));
}

static void report(example_t *ex, unsigned events)
{
    static const char *const labels[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    static const char *const reasons[5] = {" accepted", " ignored: wrong angle", " ignored: off axis",
                                           " ignored: too long", " ignored: bad window"};
    gyrocal_session_t *s = &ex->session;
    if (events & GYROCAL_SESSION_TURN) {
        board_write(ex->frame, gyrocal_frame_turn(ex->frame, &s->turn));
        send_text(ex, labels[s->turn.slot], reasons[s->turn.status < 5u ? s->turn.status : 1u]);
    }
    if (events & GYROCAL_SESSION_RESULT) {
        board_write(ex->frame, gyrocal_frame_result(ex->frame, s->status, GYROCAL_METHOD_FIRST_MOMENT,
                                                    (uint8_t)s->iterations, GYROCAL_N_OBS,
                                                    s->status == GYROCAL_OK ? &s->result : 0, s->seq - 1u));
        if (s->status == GYROCAL_OK && !ex->host_cal) { /* the host's calibration, once applied, stays */
            gyrocal_scale_bias_to_affine(&s->result, &ex->cal);
            ex->calibrated = 1;
        }
    }
}

/* The host's write-back: store the request as its own frame (the frame's CRC then checks the read-back), read it
 * back, answer with what the storage holds, and with GYROCAL_SETCAL_APPLY correct the samples with it from now on. */
static void store_calibration(example_t *ex)
{
    gyrocal_set_calibration_t req, back;
    gyrocal_frame_rx_t rx;
    uint8_t page[GYROCAL_FRAME_MAX];
    size_t n, i;
    unsigned type = 0u;
    gyrocal_frame_rx_reset(&rx);
    if (gyrocal_parse_set_calibration(ex->rx.buf + 4, ex->rx.buf[3], &req) != GYROCAL_OK) {
        board_write(ex->frame, gyrocal_frame_calibration_stored(ex->frame, GYROCAL_STORED_INVALID, 0));
        return;
    }
    n = gyrocal_frame_set_calibration(page, &req);
    if (board_store(page, n) == 0 && board_load(page, n) == 0) {
        for (i = 0; i < n; ++i) {
            type = gyrocal_frame_rx_byte(&rx, page[i]);
        }
    }
    if (type != GYROCAL_FRAME_SET_CALIBRATION
        || gyrocal_parse_set_calibration(rx.buf + 4, rx.buf[3], &back) != GYROCAL_OK) {
        board_write(ex->frame, gyrocal_frame_calibration_stored(ex->frame, GYROCAL_STORED_FAILED, 0));
        return;
    }
    if (back.flags & GYROCAL_SETCAL_APPLY) {
        ex->cal = back.cal;
        ex->calibrated = 1;
        ex->host_cal = 1;
    }
    board_write(ex->frame, gyrocal_frame_calibration_stored(ex->frame, GYROCAL_STORED_OK, &back));
}

static void receive(example_t *ex)
{
    uint8_t data[16];
    size_t n, i;
    while ((n = board_receive(data, sizeof data)) > 0u) {
        for (i = 0; i < n; ++i) {
            if (gyrocal_frame_rx_byte(&ex->rx, data[i]) == GYROCAL_FRAME_SET_CALIBRATION) {
                store_calibration(ex);
            }
        }
    }
}

int example_step(example_t *ex)
{
    int16_t raw[3], accel[3] = {0, 0, 0}, temp = GYROCAL_TEMP_NONE;
    uint32_t t_us;
    unsigned events;
    if (board_read(raw, accel, &temp) != 0) {
        board_write(ex->frame, gyrocal_frame_end(ex->frame, ex->seq));
        return 1;
    }
    t_us = board_micros();
    board_write(ex->frame, ex->send_accel ? gyrocal_frame_imu(ex->frame, ex->seq, t_us, raw, accel, temp)
                                          : gyrocal_frame_sample(ex->frame, ex->seq, t_us, raw, temp));
    events = gyrocal_session_add(&ex->session, raw);
    if (events) {
        report(ex, events);
    }
    receive(ex);
#if EXAMPLE_SEND_CALIBRATED
    if (ex->calibrated) {
        float x[3] = {(float)raw[0], (float)raw[1], (float)raw[2]}, w[3];
        gyrocal_correct(&ex->cal, x, w);
        board_write(ex->frame, gyrocal_frame_calibrated(ex->frame, ex->seq, t_us, w));
    }
#endif
    ++ex->seq;
    return 0;
}
