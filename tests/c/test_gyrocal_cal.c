/*
 * Native tests of the C library (gyrocal_cal.h), built by tests/test_c_native.py with
 * -fsanitize=address,undefined so that any out-of-bounds access or undefined behaviour fails the run.
 *
 * References: numbers worked out by hand in each test (identity-like tables, a linear bias in
 * temperature that 3-node Lagrange interpolation reproduces exactly, noise-free observations built
 * from known k and b), and the header's promise that outputs are untouched on failure.
 * Exit status: the number of failed checks (0 = all passed).
 */
#include "gyrocal_cal.h"

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

static int close_to(float a, float b, float tol) { return fabsf(a - b) <= tol * (1.0f + fabsf(b)); }

static const float SENTINEL = -12345.0f;

static void fill(float *x, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        x[i] = SENTINEL;
    }
}

static int untouched(const float *x, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (x[i] != SENTINEL) {
            return 0;
        }
    }
    return 1;
}

static void test_status_codes(void)
{
    /* tests/test_c_native.py ties these to gyrocal.firmware.host.STATUS as well */
    CHECK(GYROCAL_OK == 0 && GYROCAL_E_INPUT == 1 && GYROCAL_E_SINGULAR == 2 && GYROCAL_E_NONPHYSICAL == 3 &&
          GYROCAL_E_NOCONV == 4 && GYROCAL_E_RANGE == 5);
}

static void test_correct(void)
{
    gyrocal_affine_t cal = {{{2.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.5f}, {0.0f, 0.0f, -1.0f}}, {1.0f, 2.0f, 3.0f}};
    float raw[3] = {2.0f, 4.0f, 6.0f}, out[3];
    CHECK(gyrocal_correct(&cal, raw, out) == GYROCAL_OK);
    /* d = raw - offset = (1, 2, 3); out = (2*1, 2 + 0.5*3, -3) */
    CHECK(out[0] == 2.0f && out[1] == 3.5f && out[2] == -3.0f);
    CHECK(gyrocal_correct(&cal, raw, raw) == GYROCAL_OK); /* in place */
    CHECK(raw[0] == 2.0f && raw[1] == 3.5f && raw[2] == -3.0f);
    fill(out, 3);
    CHECK(gyrocal_correct(0, raw, out) == GYROCAL_E_INPUT && untouched(out, 3));
    CHECK(gyrocal_correct(&cal, 0, out) == GYROCAL_E_INPUT && untouched(out, 3));
    CHECK(gyrocal_correct(&cal, raw, 0) == GYROCAL_E_INPUT);
}

static void test_scale_bias_to_affine(void)
{
    gyrocal_scale_bias_t sb = {{1.5f, 2.0f, 0.5f}, {0.1f, -0.2f, 0.3f}};
    gyrocal_affine_t cal;
    CHECK(gyrocal_scale_bias_to_affine(&sb, &cal) == GYROCAL_OK);
    CHECK(cal.matrix[0][0] == 1.5f && cal.matrix[1][1] == 2.0f && cal.matrix[2][2] == 0.5f);
    CHECK(cal.matrix[0][1] == 0.0f && cal.matrix[2][0] == 0.0f);
    CHECK(cal.offset[0] == -0.1f && cal.offset[1] == 0.2f && cal.offset[2] == -0.3f);
    fill(&cal.matrix[0][0], 12);
    sb.k[1] = NAN;
    CHECK(gyrocal_scale_bias_to_affine(&sb, &cal) == GYROCAL_E_INPUT && untouched(&cal.matrix[0][0], 12));
    CHECK(gyrocal_scale_bias_to_affine(0, &cal) == GYROCAL_E_INPUT && untouched(&cal.matrix[0][0], 12));
    CHECK(gyrocal_scale_bias_to_affine(&sb, 0) == GYROCAL_E_INPUT);
}

/* Four nodes; K = identity, B linear in T: B = (0.01 T, -0.02 T, 0.5). Lagrange reproduces it exactly. */
static float temps4[4] = {-10.0f, 10.0f, 30.0f, 50.0f};
static float kg4[4][12];

static void make_table(void)
{
    int i;
    for (i = 0; i < 4; ++i) {
        memset(kg4[i], 0, sizeof kg4[i]);
        kg4[i][0] = kg4[i][1] = kg4[i][2] = 1.0f;
        kg4[i][9] = 0.01f * temps4[i];
        kg4[i][10] = -0.02f * temps4[i];
        kg4[i][11] = 0.5f;
    }
}

/* The call fails with `want` and leaves its output alone. */
static int fails_untouched(const gyrocal_thermal_t *table, float temp, const float raw[3], unsigned flags,
                           gyrocal_status_t want)
{
    float out[3];
    fill(out, 3);
    return gyrocal_thermal_correct(table, temp, raw, flags, out) == want && untouched(out, 3);
}

static void test_thermal_correct(void)
{
    gyrocal_thermal_t table = {4, temps4, (const float(*)[12])kg4};
    float raw[3] = {1.0f, 2.0f, 3.0f}, out[3], temps_bad[4];
    gyrocal_thermal_t bad = {4, temps_bad, (const float(*)[12])kg4};
    make_table();
    CHECK(gyrocal_thermal_correct(&table, 20.0f, raw, 0u, out) == GYROCAL_OK);
    CHECK(close_to(out[0], 1.0f - 0.2f, 1e-6f) && close_to(out[1], 2.0f + 0.4f, 1e-6f) &&
          close_to(out[2], 2.5f, 1e-6f));
    /* within the margin of an end node: clamped to it without the flag */
    CHECK(gyrocal_thermal_correct(&table, 50.4f, raw, 0u, out) == GYROCAL_OK && close_to(out[0], 0.5f, 1e-6f));
    CHECK(fails_untouched(&table, 60.0f, raw, 0u, GYROCAL_E_RANGE));
    CHECK(gyrocal_thermal_correct(&table, 60.0f, raw, GYROCAL_THERMAL_CLAMP, out) == GYROCAL_OK);
    CHECK(close_to(out[0], 0.5f, 1e-6f));
    CHECK(fails_untouched(&table, NAN, raw, 0u, GYROCAL_E_INPUT));
    CHECK(fails_untouched(&table, 20.0f, raw, 8u, GYROCAL_E_INPUT));
    CHECK(fails_untouched(0, 20.0f, raw, 0u, GYROCAL_E_INPUT));
    CHECK(fails_untouched(&table, 20.0f, 0, 0u, GYROCAL_E_INPUT));
    CHECK(gyrocal_thermal_correct(&table, 20.0f, raw, 0u, 0) == GYROCAL_E_INPUT);
    /* malformed tables: repeated, decreasing and NaN nodes, too few nodes, missing arrays */
    memcpy(temps_bad, temps4, sizeof temps4);
    temps_bad[2] = temps_bad[1];
    CHECK(fails_untouched(&bad, 20.0f, raw, 0u, GYROCAL_E_INPUT));
    temps_bad[2] = 0.0f;
    CHECK(fails_untouched(&bad, 20.0f, raw, 0u, GYROCAL_E_INPUT));
    temps_bad[2] = NAN;
    CHECK(fails_untouched(&bad, 20.0f, raw, 0u, GYROCAL_E_INPUT));
    bad.temps = temps4;
    bad.n = 2;
    CHECK(fails_untouched(&bad, 0.0f, raw, 0u, GYROCAL_E_INPUT));
    bad.n = 4;
    bad.kg = 0;
    CHECK(fails_untouched(&bad, 0.0f, raw, 0u, GYROCAL_E_INPUT));
    bad.kg = (const float(*)[12])kg4;
    bad.temps = 0;
    CHECK(fails_untouched(&bad, 0.0f, raw, 0u, GYROCAL_E_INPUT));
}

static void test_singular_table(void)
{
    static float kg_zero[3][12];
    float t3[3] = {0.0f, 10.0f, 20.0f}, raw[3] = {1.0f, 1.0f, 1.0f};
    gyrocal_thermal_t table = {3, t3, (const float(*)[12])kg_zero};
    CHECK(fails_untouched(&table, 5.0f, raw, 0u, GYROCAL_E_SINGULAR));
}

static void test_temp_filter(void)
{
    float state = 20.0f;
    CHECK(gyrocal_temp_filter(0, 25.0f, 0.5f) == 25.0f);
    CHECK(gyrocal_temp_filter(&state, 22.0f, 0.5f) == 21.0f && state == 21.0f);
}

static void test_accumulator(void)
{
    gyrocal_accum_t acc;
    gyrocal_obs_t obs;
    float s[3];
    int i;
    gyrocal_accum_reset(&acc);
    for (i = 0; i < 4; ++i) {
        s[0] = (float)i; /* 0, 1, 2, 3: mean 1.5, mean of squares 3.5 */
        s[1] = 10.0f;
        s[2] = -2.0f;
        gyrocal_accum_add(&acc, s);
    }
    CHECK(gyrocal_accum_finish(&acc, 2.0f, &obs) == GYROCAL_OK);
    CHECK(obs.mean[0] == 1.5f && obs.mean[1] == 10.0f && obs.mean[2] == -2.0f);
    CHECK(close_to(obs.mean_sq[0], 3.5f, 1e-6f) && close_to(obs.mean_sq[1], 100.0f, 1e-6f) && obs.rate == 2.0f);
    gyrocal_accum_reset(0); /* no crash */
    gyrocal_accum_add(0, s);
    gyrocal_accum_add(&acc, 0);
    fill(obs.mean, 3);
    CHECK(gyrocal_accum_finish(&acc, NAN, &obs) == GYROCAL_E_INPUT && untouched(obs.mean, 3));
    CHECK(gyrocal_accum_finish(0, 1.0f, &obs) == GYROCAL_E_INPUT && untouched(obs.mean, 3));
    CHECK(gyrocal_accum_finish(&acc, 1.0f, 0) == GYROCAL_E_INPUT);
    gyrocal_accum_reset(&acc);
    gyrocal_accum_add(&acc, s);
    CHECK(gyrocal_accum_finish(&acc, 1.0f, &obs) == GYROCAL_E_INPUT && untouched(obs.mean, 3)); /* one sample */
    s[1] = INFINITY;
    gyrocal_accum_add(&acc, s);
    CHECK(gyrocal_accum_finish(&acc, 1.0f, &obs) == GYROCAL_E_INPUT && untouched(obs.mean, 3));
}

/* Noise-free six turns of speed w about +-x, +-y, +-z: the reading m = g / k - b (eq. 1 inverted). */
static void six_turns(const float k[3], const float b[3], float w, gyrocal_obs_t obs[GYROCAL_N_OBS])
{
    int i, j;
    for (i = 0; i < GYROCAL_N_OBS; ++i) {
        for (j = 0; j < 3; ++j) {
            float g = (j == i / 2) ? (i % 2 ? -w : w) : 0.0f;
            obs[i].mean[j] = g / k[j] - b[j];
            obs[i].mean_sq[j] = obs[i].mean[j] * obs[i].mean[j];
        }
        obs[i].rate = w;
    }
}

static void test_solvers(void)
{
    const float k[3] = {1.02f, 0.97f, 1.01f}, b[3] = {0.03f, -0.02f, 0.01f};
    gyrocal_obs_t obs[GYROCAL_N_OBS];
    gyrocal_scale_bias_t out;
    int it = -1, j;
    six_turns(k, b, 1.0471976f, obs);
    CHECK(gyrocal_first_moment(obs, &out, &it) == GYROCAL_OK && it >= 1);
    for (j = 0; j < 3; ++j) {
        CHECK(close_to(out.k[j], k[j], 1e-5f) && close_to(out.b[j], b[j], 1e-4f));
    }
    CHECK(gyrocal_algorithm1(obs, &out, 0) == GYROCAL_OK); /* noise-free: mean of squares = squared mean */
    for (j = 0; j < 3; ++j) {
        CHECK(close_to(out.k[j], k[j], 1e-5f) && close_to(out.b[j], b[j], 1e-4f));
    }
    fill(out.k, 3);
    fill(out.b, 3);
    CHECK(gyrocal_first_moment(0, &out, &it) == GYROCAL_E_INPUT && untouched(out.k, 3));
    CHECK(gyrocal_algorithm1(obs, 0, &it) == GYROCAL_E_INPUT);
    for (j = 0; j < GYROCAL_N_OBS; ++j) { /* every turn about x: y and z cannot be fixed */
        obs[j] = obs[j % 2];
    }
    CHECK(gyrocal_first_moment(obs, &out, &it) == GYROCAL_E_SINGULAR && untouched(out.k, 3) && untouched(out.b, 3));
    six_turns(k, b, 1.0471976f, obs);
    obs[3].rate = -1.0f;
    CHECK(gyrocal_algorithm1(obs, &out, &it) == GYROCAL_E_INPUT && untouched(out.k, 3));
}

static void test_poly_correct(void)
{
    /* matrix(T) = diag(1 + u, 2, 3 - u^3), offset(T) = (u^2, 0, 1), u = (T - 10) / 20, T clamped to [-10, 50] */
    gyrocal_imu_thermal_t imu;
    float raw[3] = {1.0f, 2.0f, 3.0f}, out[3], w[3], a[3];
    int e, k;
    for (e = 0; e < 12; ++e) {
        for (k = 0; k <= GYROCAL_POLY_MAX_ORDER; ++k) {
            imu.accel.coefs[e][k] = 0.0f;
        }
    }
    imu.accel.tmin = -10.0f;
    imu.accel.tmax = 50.0f;
    imu.accel.centre = 10.0f;
    imu.accel.scale = 20.0f;
    imu.accel.coefs[0][0] = 1.0f;
    imu.accel.coefs[0][1] = 1.0f;
    imu.accel.coefs[4][0] = 2.0f;
    imu.accel.coefs[8][0] = 3.0f;
    imu.accel.coefs[8][3] = -1.0f;
    imu.accel.coefs[9][2] = 1.0f;
    imu.accel.coefs[11][0] = 1.0f;
    imu.gyro = imu.accel;
    CHECK(gyrocal_poly_correct(&imu.accel, 30.0f, raw, out) == GYROCAL_OK); /* u = 1 */
    CHECK(close_to(out[0], 0.0f, 1e-6f) && close_to(out[1], 4.0f, 1e-6f) && close_to(out[2], 4.0f, 1e-6f));
    CHECK(gyrocal_poly_correct(&imu.accel, 90.0f, raw, out) == GYROCAL_OK); /* clamped to 50: u = 2 */
    CHECK(close_to(out[0], -9.0f, 1e-6f) && close_to(out[2], -10.0f, 1e-6f));
    CHECK(gyrocal_imu_thermal_correct(&imu, 30.0f, raw, raw, w, a) == GYROCAL_OK);
    CHECK(close_to(w[1], 4.0f, 1e-6f) && close_to(a[2], 4.0f, 1e-6f));
    fill(out, 3);
    CHECK(gyrocal_poly_correct(&imu.accel, NAN, raw, out) == GYROCAL_E_INPUT && untouched(out, 3));
    CHECK(gyrocal_poly_correct(0, 30.0f, raw, out) == GYROCAL_E_INPUT && untouched(out, 3));
    imu.gyro.scale = 0.0f;
    fill(w, 3);
    fill(a, 3);
    CHECK(gyrocal_imu_thermal_correct(&imu, 30.0f, raw, raw, w, a) == GYROCAL_E_INPUT && untouched(w, 3) &&
          untouched(a, 3));
}

int main(void)
{
    test_status_codes();
    test_correct();
    test_scale_bias_to_affine();
    test_thermal_correct();
    test_poly_correct();
    test_singular_table();
    test_temp_filter();
    test_accumulator();
    test_solvers();
    if (failures) {
        fprintf(stderr, "%d check(s) failed\n", failures);
    }
    return failures;
}
