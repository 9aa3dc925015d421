/*
 * gyrocal_cal.c: gyroscope calibration on a microcontroller (part of gyrocal, MIT licence).
 * See gyrocal_cal.h for the conventions. Float32 throughout; float literals carry the f suffix
 * so that no double arithmetic is pulled in on a single-precision FPU.
 */
#include "gyrocal_cal.h"

#include <math.h>

#define N6 GYROCAL_N_OBS

static int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* Gaussian elimination with partial pivoting, in place: a is n x n (row-major), b is n x nrhs.
 * A pivot below GYROCAL_PIVOT_RTOL times the largest |a_ij| means a singular system. */
static gyrocal_status_t solve(float *a, float *b, int n, int nrhs)
{
    float amax = 0.0f;
    int i, j, c, p;
    for (i = 0; i < n * n; ++i) {
        if (fabsf(a[i]) > amax) {
            amax = fabsf(a[i]);
        }
    }
    for (c = 0; c < n; ++c) {
        p = c;
        for (i = c + 1; i < n; ++i) {
            if (fabsf(a[i * n + c]) > fabsf(a[p * n + c])) {
                p = i;
            }
        }
        /* The negated test also catches NaN. */
        if (!(fabsf(a[p * n + c]) > GYROCAL_PIVOT_RTOL * amax)) {
            return GYROCAL_E_SINGULAR;
        }
        if (p != c) {
            for (j = 0; j < n; ++j) {
                float t = a[c * n + j];
                a[c * n + j] = a[p * n + j];
                a[p * n + j] = t;
            }
            for (j = 0; j < nrhs; ++j) {
                float t = b[c * nrhs + j];
                b[c * nrhs + j] = b[p * nrhs + j];
                b[p * nrhs + j] = t;
            }
        }
        for (i = c + 1; i < n; ++i) {
            float f = a[i * n + c] / a[c * n + c];
            for (j = c + 1; j < n; ++j) {
                a[i * n + j] -= f * a[c * n + j];
            }
            for (j = 0; j < nrhs; ++j) {
                b[i * nrhs + j] -= f * b[c * nrhs + j];
            }
        }
    }
    for (c = n - 1; c >= 0; --c) {
        for (j = 0; j < nrhs; ++j) {
            float s = b[c * nrhs + j];
            for (i = c + 1; i < n; ++i) {
                s -= a[c * n + i] * b[i * nrhs + j];
            }
            b[c * nrhs + j] = s / a[c * n + c];
        }
    }
    return GYROCAL_OK;
}

gyrocal_status_t gyrocal_correct(const gyrocal_affine_t *cal, const float raw[3], float out[3])
{
    float d[3];
    int i;
    if (cal == 0 || raw == 0 || out == 0) {
        return GYROCAL_E_INPUT;
    }
    for (i = 0; i < 3; ++i) {
        d[i] = raw[i] - cal->offset[i];
    }
    for (i = 0; i < 3; ++i) {
        out[i] = cal->matrix[i][0] * d[0] + cal->matrix[i][1] * d[1] + cal->matrix[i][2] * d[2];
    }
    return GYROCAL_OK;
}

gyrocal_status_t gyrocal_imu_correct(const gyrocal_imu_t *imu, const float gyro_raw[3], const float accel_raw[3],
                                     float w_out[3], float a_out[3])
{
    float a[3], g[3];
    int i;
    if (imu == 0 || gyro_raw == 0 || accel_raw == 0 || w_out == 0 || a_out == 0) {
        return GYROCAL_E_INPUT;
    }
    gyrocal_correct(&imu->accel, accel_raw, a);
    for (i = 0; i < 3; ++i) {
        /* the raw gyro less the part the specific force puts into it */
        g[i] = gyro_raw[i] - (imu->g_sens[i][0] * a[0] + imu->g_sens[i][1] * a[1] + imu->g_sens[i][2] * a[2]);
    }
    gyrocal_correct(&imu->gyro, g, w_out);
    for (i = 0; i < 3; ++i) {
        a_out[i] = a[i];
    }
    return GYROCAL_OK;
}

gyrocal_status_t gyrocal_poly_correct(const gyrocal_poly_affine_t *p, float temp, const float raw[3], float out[3])
{
    float v[12], d[3], u;
    int e, k, i;
    if (p == 0 || raw == 0 || out == 0 || !isfinite(temp) || !finite3(raw) || !isfinite(p->tmin) ||
        !isfinite(p->tmax) || !(p->tmin <= p->tmax) || !isfinite(p->centre) || !(p->scale > 0.0f)) {
        return GYROCAL_E_INPUT;
    }
    temp = temp < p->tmin ? p->tmin : (temp > p->tmax ? p->tmax : temp);
    u = (temp - p->centre) / p->scale;
    for (e = 0; e < 12; ++e) {
        /* Horner's rule, highest power first */
        float acc = p->coefs[e][GYROCAL_POLY_MAX_ORDER];
        for (k = GYROCAL_POLY_MAX_ORDER - 1; k >= 0; --k) {
            acc = acc * u + p->coefs[e][k];
        }
        v[e] = acc;
    }
    for (i = 0; i < 3; ++i) {
        d[i] = raw[i] - v[9 + i];
    }
    for (i = 0; i < 3; ++i) {
        out[i] = v[3 * i] * d[0] + v[3 * i + 1] * d[1] + v[3 * i + 2] * d[2];
    }
    return GYROCAL_OK;
}

gyrocal_status_t gyrocal_imu_thermal_correct(const gyrocal_imu_thermal_t *imu, float temp, const float gyro_raw[3],
                                             const float accel_raw[3], float w_out[3], float a_out[3])
{
    float a[3], w[3];
    gyrocal_status_t s;
    int i;
    if (imu == 0 || gyro_raw == 0 || accel_raw == 0 || w_out == 0 || a_out == 0) {
        return GYROCAL_E_INPUT;
    }
    s = gyrocal_poly_correct(&imu->accel, temp, accel_raw, a);
    if (s == GYROCAL_OK) {
        s = gyrocal_poly_correct(&imu->gyro, temp, gyro_raw, w);
    }
    if (s != GYROCAL_OK) {
        return s;
    }
    for (i = 0; i < 3; ++i) {
        a_out[i] = a[i];
        w_out[i] = w[i];
    }
    return GYROCAL_OK;
}

gyrocal_status_t gyrocal_scale_bias_to_affine(const gyrocal_scale_bias_t *sb, gyrocal_affine_t *out)
{
    int i, j;
    if (sb == 0 || out == 0 || !finite3(sb->k) || !finite3(sb->b)) {
        return GYROCAL_E_INPUT;
    }
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j) {
            out->matrix[i][j] = (i == j) ? sb->k[i] : 0.0f;
        }
        out->offset[i] = -sb->b[i];
    }
    return GYROCAL_OK;
}

/* Position in K (the full-temperature-range method, eq. 11) of the Kg elements 0..8 (eq. 14), as row * 3 + column. */
static const uint8_t KG_SLOT[9] = {0, 4, 8, 1, 2, 3, 5, 6, 7};

float gyrocal_temp_filter(float *state, float temp, float alpha)
{
    if (state == 0) {
        return temp;
    }
    *state += alpha * (temp - *state);
    return *state;
}

gyrocal_status_t gyrocal_thermal_correct(const gyrocal_thermal_t *table, float temp, const float raw[3],
                                         unsigned flags, float out[3])
{
    float k[9], d[3], w[3];
    const float *t;
    int n, i, s, e;
    if (table == 0 || table->temps == 0 || table->kg == 0 || raw == 0 || out == 0 || table->n < 3 ||
        !isfinite(temp) || !finite3(raw) || (flags & ~GYROCAL_THERMAL_CLAMP)) {
        return GYROCAL_E_INPUT;
    }
    n = table->n;
    t = table->temps;
    /* a malformed table (repeated, decreasing or non-finite nodes) would divide by zero below */
    for (i = 0; i < n; ++i) {
        if (!isfinite(t[i]) || (i > 0 && !(t[i] > t[i - 1]))) {
            return GYROCAL_E_INPUT;
        }
    }
    if (temp < t[0] || temp > t[n - 1]) {
        if (!(flags & GYROCAL_THERMAL_CLAMP) && (temp < t[0] - GYROCAL_THERMAL_MARGIN ||
                                                  temp > t[n - 1] + GYROCAL_THERMAL_MARGIN)) {
            return GYROCAL_E_RANGE;
        }
        temp = temp < t[0] ? t[0] : t[n - 1];
    }
    for (i = 0; i < n && t[i] < temp; ++i) {
    }
    s = i - 2;
    s = s < 0 ? 0 : (s > n - 3 ? n - 3 : s);
    t += s;
    /* the full-temperature-range method, eq. 22: the three Lagrange basis values at temp */
    w[0] = (temp - t[1]) * (temp - t[2]) / ((t[0] - t[1]) * (t[0] - t[2]));
    w[1] = (temp - t[2]) * (temp - t[0]) / ((t[1] - t[2]) * (t[1] - t[0]));
    w[2] = (temp - t[0]) * (temp - t[1]) / ((t[2] - t[0]) * (t[2] - t[1]));
    for (e = 0; e < 12; ++e) {
        /* the full-temperature-range method, eq. 21 */
        float v = w[0] * table->kg[s][e] + w[1] * table->kg[s + 1][e] + w[2] * table->kg[s + 2][e];
        if (e < 9) {
            k[KG_SLOT[e]] = v;
        } else {
            d[e - 9] = raw[e - 9] - v;
        }
    }
    /* w = K^-1 (raw - B) without forming the inverse */
    if (solve(k, d, 3, 1) != GYROCAL_OK) {
        return GYROCAL_E_SINGULAR;
    }
    for (i = 0; i < 3; ++i) {
        out[i] = d[i];
    }
    return GYROCAL_OK;
}

void gyrocal_accum_reset(gyrocal_accum_t *acc)
{
    if (acc == 0) {
        return;
    }
    acc->count = 0u; /* the sums are cleared by the next sample, see gyrocal_accum_add */
}

/* Neumaier's compensated sum: the error stays at a few ulps whatever the window length. */
static void comp_add(float *sum, float *comp, float x)
{
    float t = *sum + x;
    if (fabsf(*sum) >= fabsf(x)) {
        *comp += (*sum - t) + x;
    } else {
        *comp += (x - t) + *sum;
    }
    *sum = t;
}

void gyrocal_accum_add(gyrocal_accum_t *acc, const float sample[3])
{
    int i;
    if (acc == 0 || sample == 0) {
        return;
    }
    if (acc->count == 0u) {
        /* Cleared here rather than in reset: a zeroing loop would compile to a call to memset. */
        for (i = 0; i < 3; ++i) {
            acc->first[i] = sample[i];
            acc->s1[i] = acc->c1[i] = acc->s2[i] = acc->c2[i] = 0.0f;
        }
    }
    /* Deviations from the first sample keep a large bias out of the sums of squares. */
    for (i = 0; i < 3; ++i) {
        float d = sample[i] - acc->first[i];
        comp_add(&acc->s1[i], &acc->c1[i], d);
        comp_add(&acc->s2[i], &acc->c2[i], d * d);
    }
    acc->count++;
}

gyrocal_status_t gyrocal_accum_finish(const gyrocal_accum_t *acc, float rate, gyrocal_obs_t *obs)
{
    float mean[3], mean_sq[3];
    float n;
    int i;
    if (acc == 0 || obs == 0) {
        return GYROCAL_E_INPUT;
    }
    n = (float)acc->count; /* exact up to 2^24 samples */
    if (acc->count < 2u || !isfinite(rate) || rate < 0.0f) {
        return GYROCAL_E_INPUT;
    }
    for (i = 0; i < 3; ++i) {
        float m1 = (acc->s1[i] + acc->c1[i]) / n;
        float var = (acc->s2[i] + acc->c2[i]) / n - m1 * m1;
        mean[i] = acc->first[i] + m1;
        mean_sq[i] = mean[i] * mean[i] + (var > 0.0f ? var : 0.0f);
    }
    if (!finite3(mean) || !finite3(mean_sq)) {
        return GYROCAL_E_INPUT;
    }
    for (i = 0; i < 3; ++i) {
        obs->mean[i] = mean[i];
        obs->mean_sq[i] = mean_sq[i];
    }
    obs->rate = rate;
    return GYROCAL_OK;
}

/* beta0 implied by beta (the servo method of Wang et al., eq. 3): sum beta_{j+3}^2 / (4 beta_j). */
static float gamma_of(const float beta[N6])
{
    return beta[3] * beta[3] / (4.0f * beta[0]) + beta[4] * beta[4] / (4.0f * beta[1])
           + beta[5] * beta[5] / (4.0f * beta[2]);
}

static int k2_positive(const float beta[N6])
{
    return beta[0] > 0.0f && beta[1] > 0.0f && beta[2] > 0.0f;
}

/* Solve X u = Y and X v = 1 for the six-observation design (the servo method of Wang et al., eq. 6-7), with the
 * regressors (mean of squares, or squared mean, then mean) and Y = rate^2, all divided by
 * the largest rate r (or r^2) so that the pivot test and the stop rule do not depend on units. */
static gyrocal_status_t six_solve(const gyrocal_obs_t obs[N6], int squared_mean, float u[N6], float v[N6],
                                  float *r_out)
{
    float x[N6 * N6], rhs[N6 * 2];
    float r = 0.0f;
    int i, j;
    for (i = 0; i < N6; ++i) {
        if (!finite3(obs[i].mean) || !finite3(obs[i].mean_sq) || !(obs[i].rate > 0.0f) || !isfinite(obs[i].rate)) {
            return GYROCAL_E_INPUT;
        }
        if (obs[i].rate > r) {
            r = obs[i].rate;
        }
    }
    for (i = 0; i < N6; ++i) {
        for (j = 0; j < 3; ++j) {
            float m = obs[i].mean[j] / r;
            x[i * N6 + j] = squared_mean ? m * m : obs[i].mean_sq[j] / r / r;
            x[i * N6 + 3 + j] = m;
        }
        rhs[i * 2] = (obs[i].rate / r) * (obs[i].rate / r);
        rhs[i * 2 + 1] = 1.0f;
    }
    /* Six equations, six unknowns: (X^T X)^-1 X^T is X^-1, so solve X directly (better conditioned). */
    if (solve(x, rhs, N6, 2) != GYROCAL_OK) {
        return GYROCAL_E_SINGULAR;
    }
    for (i = 0; i < N6; ++i) {
        u[i] = rhs[i * 2];
        v[i] = rhs[i * 2 + 1];
    }
    *r_out = r;
    return GYROCAL_OK;
}

/* The servo method's return step: k = sqrt(beta_1..3), b = beta_4..6 / (2 beta_1..3), undoing the rate scaling. */
static gyrocal_status_t finish_kb(const float beta[N6], float r, gyrocal_scale_bias_t *out)
{
    float k[3], b[3];
    int j;
    if (!k2_positive(beta)) {
        return GYROCAL_E_NONPHYSICAL;
    }
    for (j = 0; j < 3; ++j) {
        k[j] = sqrtf(beta[j]);
        b[j] = r * beta[j + 3] / (2.0f * beta[j]);
    }
    if (!finite3(k) || !finite3(b)) {
        return GYROCAL_E_NONPHYSICAL;
    }
    for (j = 0; j < 3; ++j) {
        out->k[j] = k[j];
        out->b[j] = b[j];
    }
    return GYROCAL_OK;
}

gyrocal_status_t gyrocal_algorithm1(const gyrocal_obs_t obs[GYROCAL_N_OBS], gyrocal_scale_bias_t *out,
                                    int *iterations)
{
    float u[N6], v[N6], beta[N6], r;
    int it, j;
    gyrocal_status_t st = (obs == 0 || out == 0) ? GYROCAL_E_INPUT : six_solve(obs, 0, u, v, &r);
    if (st != GYROCAL_OK) {
        return st;
    }
    for (j = 0; j < N6; ++j) {
        beta[j] = u[j]; /* beta0 = 0: the initial estimate */
    }
    /* beta(n+1) = X^-1 (Y - gamma(beta(n))) = u - gamma v, the servo method of Wang et al., Algorithm 1 */
    for (it = 1; it <= GYROCAL_MAX_ITER; ++it) {
        float g, delta = 0.0f, size = 0.0f;
        if (!k2_positive(beta)) {
            return GYROCAL_E_NONPHYSICAL;
        }
        g = gamma_of(beta);
        for (j = 0; j < N6; ++j) {
            float nb = u[j] - g * v[j];
            delta += fabsf(nb - beta[j]);
            size += fabsf(nb);
            beta[j] = nb;
        }
        if (delta <= GYROCAL_REL_TOL * size) {
            if (iterations) {
                *iterations = it;
            }
            return finish_kb(beta, r, out);
        }
    }
    if (iterations) {
        *iterations = GYROCAL_MAX_ITER;
    }
    return GYROCAL_E_NOCONV;
}

gyrocal_status_t gyrocal_first_moment(const gyrocal_obs_t obs[GYROCAL_N_OBS], gyrocal_scale_bias_t *out,
                                      int *iterations)
{
    float u[N6], v[N6], beta[N6], r, b0 = 0.0f, vsum = 0.0f;
    int it, j;
    gyrocal_status_t st = (obs == 0 || out == 0) ? GYROCAL_E_INPUT : six_solve(obs, 1, u, v, &r);
    if (st != GYROCAL_OK) {
        return st;
    }
    for (j = 0; j < N6; ++j) {
        vsum += fabsf(v[j]);
    }
    /* beta = u - beta0 v solves the six linear equations for any beta0; Newton on
     * f(beta0) = gamma(u - beta0 v) - beta0 picks the one consistent with eq. 3. */
    for (it = 1; it <= GYROCAL_MAX_ITER; ++it) {
        float f, fp = -1.0f, step, size = 0.0f;
        for (j = 0; j < N6; ++j) {
            beta[j] = u[j] - b0 * v[j];
            size += fabsf(beta[j]);
        }
        if (!k2_positive(beta)) {
            return GYROCAL_E_NONPHYSICAL;
        }
        f = gamma_of(beta) - b0;
        for (j = 0; j < 3; ++j) {
            float h = beta[j + 3] / (2.0f * beta[j]); /* d gamma / d beta_{j+3}; -h^2 is d gamma / d beta_j */
            fp += h * h * v[j] - h * v[j + 3];
        }
        if (!(fabsf(fp) > 0.0f)) {
            if (iterations) {
                *iterations = it;
            }
            return GYROCAL_E_NOCONV;
        }
        step = f / fp;
        b0 -= step;
        if (fabsf(step) * vsum <= GYROCAL_REL_TOL * size) {
            for (j = 0; j < N6; ++j) {
                beta[j] = u[j] - b0 * v[j];
            }
            if (iterations) {
                *iterations = it;
            }
            return finish_kb(beta, r, out);
        }
    }
    if (iterations) {
        *iterations = GYROCAL_MAX_ITER;
    }
    return GYROCAL_E_NOCONV;
}
