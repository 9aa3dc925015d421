/*
 * On-device example for QEMU mps2-an386 (Cortex-M4F): stream six simulated 360 deg turns through the
 * window accumulator, calibrate with Algorithm 1 and with the first-moment estimator, correct a sample
 * and apply a thermal table; then correct one still IMU sample (gyro and accelerometer) with the whole-IMU
 * temperature table of imu_thermal_cal.h. Each library call sits between marker_begin() and marker_end(),
 * which tools/cross_m4.sh finds in QEMU's instruction trace to count executed instructions; the stack
 * below each call is painted first, to measure its peak use.
 *
 * imu_thermal_cal.h is the unedited output of gyrocal for a simulated chamber session (seed 0), made by
 *   gyrocal simulate --protocol multi-position --temp-points -25,0,25,50 -o chamber.csv
 *   gyrocal imu chamber.csv --units deg/s --accel-units m/s^2 -o cal.json
 *   gyrocal export cal.json --format c-header -o tools/m4/imu_thermal_cal.h
 */
#include <stdint.h>

#include "gyrocal_cal.h"
#include "imu_thermal_cal.h"
#include "semihost.h"

#define FS 200.0f           /* sample rate [Hz] */
#define OMEGA 1.04719755f   /* 60 deg/s [rad/s], the servo method's speed */
#define N_TURN 1200         /* one 360 deg turn at 60 deg/s: 6 s */
#define NOISE 0.035f        /* per-sample white noise [rad/s], the servo method's normal level */
#define PAINT 0xC5C5C5C5u

static const float K_TRUE[3] = {1.05f, 0.95f, 1.02f};
static const float B_TRUE[3] = {0.05f, -0.08f, 0.03f};
static uint32_t rng_state = 2463534242u;

#ifdef GYROCAL_HOST
/* Host build: no markers or stack painting, only the results. */
#define marker_begin() ((void)0)
#define marker_end() ((void)0)
#define PAINT_STACK(sp0) ((sp0) = 0u)
#define report(what, stack) ((void)(what), (void)(stack))
static uint32_t stack_used(uint32_t sp0)
{
    return sp0;
}
#else
extern uint32_t _sstack;

__attribute__((noipa)) void marker_begin(void)
{
    __asm volatile("nop");
}

__attribute__((noipa)) void marker_end(void)
{
    __asm volatile("nop\n nop");
}

static inline uint32_t get_sp(void)
{
    uint32_t sp;
    __asm volatile("mov %0, sp" : "=r"(sp));
    return sp;
}

/* Paint the free stack below the caller, leaving a small margin for this code itself. */
#define PAINT_STACK(sp0)                                                      \
    do {                                                                      \
        volatile uint32_t *p_;                                                \
        (sp0) = get_sp();                                                     \
        for (p_ = &_sstack; (uint32_t)p_ < (sp0) - 16u; ++p_) { *p_ = PAINT; } \
    } while (0)

static uint32_t stack_used(uint32_t sp0)
{
    const volatile uint32_t *p = &_sstack;
    while (*p == PAINT) {
        ++p;
    }
    return sp0 - (uint32_t)p;
}
#endif

static float uniform(void) /* xorshift32, [0, 1) */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return (float)(rng_state >> 8) * (1.0f / 16777216.0f);
}

static float noise(void) /* sum of four uniforms: zero mean, standard deviation NOISE */
{
    return (uniform() + uniform() + uniform() + uniform() - 2.0f) * 1.7320508f * NOISE;
}

static void put_u(uint32_t v)
{
    char buf[12];
    int i = 11;
    buf[i] = 0;
    do {
        buf[--i] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v);
    sh_puts(buf + i);
}

static void put_f(float x) /* fixed point, 6 decimals */
{
    uint32_t ip, fp;
    if (x < 0.0f) {
        sh_puts("-");
        x = -x;
    }
    ip = (uint32_t)x;
    fp = (uint32_t)((x - (float)ip) * 1e6f + 0.5f);
    if (fp >= 1000000u) {
        ip++;
        fp -= 1000000u;
    }
    put_u(ip);
    sh_puts(".");
    for (uint32_t d = 100000u; d > 1u && fp < d; d /= 10u) {
        sh_puts("0");
    }
    put_u(fp);
}

static void put_vec(const char *name, const float v[3])
{
    static const char hex[] = "0123456789abcdef";
    sh_puts(name);
    for (int i = 0; i < 3; ++i) {
        sh_puts(i ? ", " : " = [");
        put_f(v[i]);
    }
    sh_puts("]  bits");
    for (int i = 0; i < 3; ++i) { /* the exact float32, to compare the M4 with the host */
        union { float f; uint32_t u; } x = {v[i]};
        char buf[10] = {' ', 0, 0, 0, 0, 0, 0, 0, 0, 0};
        for (int d = 0; d < 8; ++d) {
            buf[1 + d] = hex[(x.u >> (28 - 4 * d)) & 0xFu];
        }
        sh_puts(buf);
    }
    sh_puts("\n");
}

#ifndef GYROCAL_HOST
static void report(const char *what, uint32_t stack)
{
    sh_puts("stack ");
    sh_puts(what);
    sh_puts(" = ");
    put_u(stack);
    sh_puts(" B\n");
}
#endif

static int check(const char *name, const gyrocal_scale_bias_t *sb, int status, int iterations)
{
    int ok = status == GYROCAL_OK;
    sh_puts(name);
    sh_puts(": status ");
    put_u((uint32_t)status);
    sh_puts(", iterations ");
    put_u((uint32_t)iterations);
    sh_puts("\n");
    if (ok) {
        put_vec("  k", sb->k);
        put_vec("  b [rad/s]", sb->b);
        for (int i = 0; i < 3; ++i) {
            float dk = sb->k[i] - K_TRUE[i], db = sb->b[i] - B_TRUE[i];
            ok = ok && dk < 0.01f && dk > -0.01f && db < 0.01f && db > -0.01f;
        }
    }
    return ok;
}

static const float T_NODES[5] = {-20.0f, 0.0f, 20.0f, 40.0f, 60.0f};
static const float T_KG[5][12] = {
    {1.010f, 0.990f, 1.020f, 0.001f, -0.002f, 0.003f, 0.001f, -0.001f, 0.002f, 0.020f, -0.010f, 0.005f},
    {1.005f, 0.995f, 1.015f, 0.001f, -0.002f, 0.003f, 0.001f, -0.001f, 0.002f, 0.015f, -0.008f, 0.004f},
    {1.000f, 1.000f, 1.010f, 0.001f, -0.002f, 0.003f, 0.001f, -0.001f, 0.002f, 0.010f, -0.006f, 0.003f},
    {0.996f, 1.004f, 1.006f, 0.001f, -0.002f, 0.003f, 0.001f, -0.001f, 0.002f, 0.006f, -0.004f, 0.002f},
    {0.993f, 1.007f, 1.003f, 0.001f, -0.002f, 0.003f, 0.001f, -0.001f, 0.002f, 0.003f, -0.002f, 0.001f},
};

/* One still sample of chamber.csv at 25 degC (its first at that plateau, board level): gyro converted from
 * deg/s to rad/s (the table's gyro input units), accelerometer in m/s^2. */
#define IMU_TEMP 25.0f
static const float IMU_GYRO_RAW[3] = {0.304058667f * 0.0174532925f, -3.11546143f * 0.0174532925f,
                                      -2.90567856f * 0.0174532925f};
static const float IMU_ACCEL_RAW[3] = {0.152001582f, -0.0686048951f, 10.0401464f};

/* Correct the sample with GYROCAL_IMU_THERMAL; ok when the corrected specific force has gravity's magnitude
 * (within 0.1 m/s^2: one sample's accelerometer noise is 0.02 m/s^2 per axis) and the corrected rate is
 * near zero (within 0.2 rad/s: 0.035 rad/s of noise per axis). */
static int imu_thermal_example(void)
{
    float w[3], a[3], a2 = 0.0f, w2 = 0.0f;
    uint32_t sp0;
    int st;
    (void)GYROCAL_CALIBRATION; /* the header's other tables: not used here */
    (void)GYROCAL_IMU;
    PAINT_STACK(sp0);
    marker_begin();
    st = gyrocal_imu_thermal_correct(&GYROCAL_IMU_THERMAL, IMU_TEMP, IMU_GYRO_RAW, IMU_ACCEL_RAW, w, a);
    marker_end();
    report("gyrocal_imu_thermal_correct", stack_used(sp0));
    sh_puts("imu_thermal_correct: status ");
    put_u((uint32_t)st);
    sh_puts("\n");
    put_vec("  w [rad/s] (still sample, 25 degC)", w);
    put_vec("  a [m/s^2] (still sample, 25 degC)", a);
    for (int i = 0; i < 3; ++i) {
        a2 += a[i] * a[i];
        w2 += w[i] * w[i];
    }
    return st == GYROCAL_OK && a2 > 9.70665f * 9.70665f && a2 < 9.90665f * 9.90665f && w2 < 0.04f;
}

int main(void)
{
    static gyrocal_obs_t obs[GYROCAL_N_OBS];
    static gyrocal_accum_t acc;
    gyrocal_scale_bias_t a1, fm;
    gyrocal_affine_t cal;
    const gyrocal_thermal_t table = {5, T_NODES, T_KG};
    float sample[3], w[3];
    uint32_t sp0;
    int st1, st2, st3, it1 = 0, it2 = 0, ok;

    /* Six turns, +x -x +y -y +z -z, each about a slightly misaligned axis. */
    for (int o = 0; o < GYROCAL_N_OBS; ++o) {
        int ax = o / 2;
        float dir[3] = {0.02f, -0.015f, 0.01f}, s = (o % 2) ? -OMEGA : OMEGA;
        dir[ax] = 0.99966f; /* |dir| = 1 */
        gyrocal_accum_reset(&acc);
        for (int n = 0; n < N_TURN; ++n) {
            for (int i = 0; i < 3; ++i) {
                sample[i] = s * dir[i] / K_TRUE[i] - B_TRUE[i] + noise(); /* the servo method of Wang et al., eq. 1, inverted */
            }
            if (o == 0 && n == 0) {
                PAINT_STACK(sp0);
                marker_begin();
                gyrocal_accum_add(&acc, sample);
                marker_end();
                report("gyrocal_accum_add", stack_used(sp0));
            } else {
                gyrocal_accum_add(&acc, sample);
            }
        }
        gyrocal_accum_finish(&acc, OMEGA, &obs[o]);
    }

    PAINT_STACK(sp0);
    marker_begin();
    st1 = gyrocal_algorithm1(obs, &a1, &it1);
    marker_end();
    report("gyrocal_algorithm1", stack_used(sp0));

    PAINT_STACK(sp0);
    marker_begin();
    st2 = gyrocal_first_moment(obs, &fm, &it2);
    marker_end();
    report("gyrocal_first_moment", stack_used(sp0));

    gyrocal_scale_bias_to_affine(&fm, &cal);
    PAINT_STACK(sp0);
    marker_begin();
    gyrocal_correct(&cal, obs[0].mean, w);
    marker_end();
    report("gyrocal_correct", stack_used(sp0));

    PAINT_STACK(sp0);
    marker_begin();
    st3 = gyrocal_thermal_correct(&table, 27.5f, obs[0].mean, 0u, w);
    marker_end();
    report("gyrocal_thermal_correct", stack_used(sp0));

    sh_puts("true k = [1.05, 0.95, 1.02], b = [0.05, -0.08, 0.03] rad/s\n");
    ok = check("algorithm1", &a1, st1, it1);
    ok = check("first_moment", &fm, st2, it2) && ok;
    ok = ok && st3 == GYROCAL_OK;
    put_vec("thermal_correct(+x turn mean, 27.5 degC)", w);
    ok = imu_thermal_example() && ok;
    sh_puts(ok ? "RESULT OK\n" : "RESULT FAILED\n");
    return ok ? 0 : 1;
}
