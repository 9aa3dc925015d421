/*
 * gyrocal_cal.h: gyroscope calibration on a microcontroller (part of gyrocal, MIT licence).
 *
 * C99, float32 arithmetic, no dynamic memory, nothing from libc beyond <math.h>.
 * All state lives in caller-owned structs; the library has no static data.
 *
 * Model convention (the same as the Python package):
 *
 *     w_true = matrix * (raw - offset)
 *
 * raw and offset in the sensor's units, matrix maps them to the output units.
 * The servo method of Wang et al. (eq. 1) writes g = diag(k) (m + b): matrix = diag(k), offset = -b.
 * The full-temperature-range method (eq. 12) writes w = K w~ + B: matrix = K^-1, offset = B.
 *
 * Every function that can fail returns a gyrocal_status_t. On failure the outputs are left
 * untouched, so a caller never sees NaN parameters; the one exception is the iteration count of
 * the solvers, which is written on GYROCAL_E_NOCONV too (how far they went). A NULL pointer
 * argument, a NaN or infinite input, or a malformed table (fewer than 3 nodes, nodes not strictly
 * increasing or not finite) gives GYROCAL_E_INPUT. Functions without a status (the accumulator,
 * the temperature filter) do nothing with a NULL pointer.
 */
#ifndef GYROCAL_CAL_H
#define GYROCAL_CAL_H

#include <stdint.h>

/* Version of this library's interface and table layout. Headers exported by gyrocal
 * (gyrocal export --format c-header) check it, so a table never meets a library it was
 * not made for; gyrocal.firmware.header.C_LIBRARY_VERSION holds the same number. */
#define GYROCAL_CAL_VERSION 2

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    GYROCAL_OK = 0,
    GYROCAL_E_INPUT = 1,       /* NaN/inf input, too few samples or table nodes, bad flags */
    GYROCAL_E_SINGULAR = 2,    /* a pivot fell below GYROCAL_PIVOT_RTOL: the design cannot fix the parameters */
    GYROCAL_E_NONPHYSICAL = 3, /* an estimated k^2 <= 0 (wrong reference rate or units?) */
    GYROCAL_E_NOCONV = 4,      /* no convergence within GYROCAL_MAX_ITER iterations */
    GYROCAL_E_RANGE = 5        /* temperature outside the table and GYROCAL_THERMAL_CLAMP not given */
} gyrocal_status_t;

/* Six observations: the G-optimal design of the servo method of Wang et al. (+x, -x, +y, -y, +z, -z turns). */
#define GYROCAL_N_OBS 6
/* Relative pivot threshold of the 6x6 and 3x3 eliminations (on rate-normalised entries). */
#ifndef GYROCAL_PIVOT_RTOL
#define GYROCAL_PIVOT_RTOL 1e-5f
#endif
/* Stop when sum|delta beta| <= GYROCAL_REL_TOL * sum|beta| (beta normalised by the largest rate):
 * 16 float32 epsilons, the float32 stand-in for the servo method's absolute 1e-6. */
#ifndef GYROCAL_REL_TOL
#define GYROCAL_REL_TOL 1.9073486e-06f
#endif
#ifndef GYROCAL_MAX_ITER
#define GYROCAL_MAX_ITER 50
#endif

/* Canonical correction w = matrix (raw - offset). */
typedef struct {
    float matrix[3][3];
    float offset[3];
} gyrocal_affine_t;

/* A whole IMU (gyrocal imu): both sensors' corrections and the gyro's sensitivity to acceleration,
 *     a_true = accel.matrix (accel_raw - accel.offset),
 *     w_true = gyro.matrix (gyro_raw - gyro.offset - g_sens a_true);
 * g_sens in gyro input units per accelerometer output unit, all zeros when none was fitted. */
#define GYROCAL_CAL_HAS_IMU 1
typedef struct {
    gyrocal_affine_t gyro;
    gyrocal_affine_t accel;
    float g_sens[3][3];
} gyrocal_imu_t;

/* One sensor's correction as polynomials in temperature (gyrocal imu's smooth model, accelerometer.thermal):
 *     out = matrix(T) (raw - offset(T)),   entry_e(T) = sum_p coefs[e][p] u^p,
 *     u = (clamp(T, tmin, tmax) - centre) / scale,
 * entries e: the 9 matrix elements row-major, then the 3 offsets; entries a model lacks are zero polynomials.
 * The temperature is always clamped to [tmin, tmax] (the calibrated points): a polynomial is not extrapolated. */
#define GYROCAL_CAL_HAS_IMU_THERMAL 1
#define GYROCAL_POLY_MAX_ORDER 3
typedef struct {
    float tmin, tmax, centre, scale;
    float coefs[12][GYROCAL_POLY_MAX_ORDER + 1];
} gyrocal_poly_affine_t;

/* A whole IMU across temperature: both sensors as gyrocal_poly_affine_t (no g-sensitivity term). */
typedef struct {
    gyrocal_poly_affine_t gyro;
    gyrocal_poly_affine_t accel;
} gyrocal_imu_thermal_t;

/* Parameters of the servo method of Wang et al.: g = diag(k) (m + b); b in the sensor's units, added to the reading. */
typedef struct {
    float k[3];
    float b[3];
} gyrocal_scale_bias_t;

/* Temperature table of the full-temperature-range method: n >= 3 strictly increasing nodes [degC] and one Kg 12-vector per
 * node, eq. 14 order [Kxx,Kyy,Kzz,Kyx,Kzx,Kxy,Kzy,Kxz,Kyz,Bx,By,Bz]; K maps output units to
 * sensor units, B is in sensor units. */
typedef struct {
    uint16_t n;
    const float *temps;
    const float (*kg)[12];
} gyrocal_thermal_t;

/* Flags of gyrocal_thermal_correct. */
#define GYROCAL_THERMAL_CLAMP 1u /* clamp the temperature to the table instead of failing */
/* Temperatures this close to the end nodes [degC] are clamped to them without GYROCAL_THERMAL_CLAMP:
 * a node is the mean of noisy readings (gyrocal.thermal.lagrange.RANGE_MARGIN). */
#define GYROCAL_THERMAL_MARGIN 0.5f

/* Streaming window accumulator: compensated sums of deviations from the first sample. */
typedef struct {
    float first[3];
    float s1[3], c1[3]; /* sum of d = x - first, and its Neumaier compensation */
    float s2[3], c2[3]; /* sum of d^2, and its compensation */
    uint32_t count;
} gyrocal_accum_t;

/* One window reduced for calibration: means [sensor units], means of squares [sensor units^2],
 * and the reference rate magnitude [output units], e.g. 2*pi/T for a full turn lasting T. */
typedef struct {
    float mean[3];
    float mean_sq[3];
    float rate;
} gyrocal_obs_t;

/* w = matrix (raw - offset); out may be raw. NaN readings give NaN rates (checking each sample
 * would cost more than the correction). */
gyrocal_status_t gyrocal_correct(const gyrocal_affine_t *cal, const float raw[3], float out[3]);

/* Both sensors of a whole IMU (see gyrocal_imu_t): a_out first, then w_out with the g-sensitivity term;
 * a_out and w_out may be the inputs. */
gyrocal_status_t gyrocal_imu_correct(const gyrocal_imu_t *imu, const float gyro_raw[3], const float accel_raw[3],
                                     float w_out[3], float a_out[3]);

/* out = matrix(T) (raw - offset(T)) of a gyrocal_poly_affine_t; out may be raw. GYROCAL_E_INPUT on a NaN or
 * infinite temperature or reading, tmin > tmax or a scale that is not positive. */
gyrocal_status_t gyrocal_poly_correct(const gyrocal_poly_affine_t *p, float temp, const float raw[3], float out[3]);

/* Both sensors of a gyrocal_imu_thermal_t at temperature temp [degC]; the outputs may be the inputs. */
gyrocal_status_t gyrocal_imu_thermal_correct(const gyrocal_imu_thermal_t *imu, float temp, const float gyro_raw[3],
                                             const float accel_raw[3], float w_out[3], float a_out[3]);

/* The canonical form of the servo method's parameters (Wang et al.): matrix = diag(k), offset = -b. */
gyrocal_status_t gyrocal_scale_bias_to_affine(const gyrocal_scale_bias_t *sb, gyrocal_affine_t *out);

/* w = K(T)^-1 (raw - B(T)), Kg(T) by 3-node Lagrange interpolation (the full-temperature-range method, eq. 21-22) over nodes
 * s, s+1, s+2 with s = clamp(i - 2, 0, n - 3) and i the first node >= T. */
gyrocal_status_t gyrocal_thermal_correct(const gyrocal_thermal_t *table, float temp, const float raw[3],
                                         unsigned flags, float out[3]);

/* One step of a first-order low-pass of the temperature reading [degC] before gyrocal_thermal_correct,
 * so that readings in whole degrees do not make the corrected output jump. alpha = 1 - expf(-dt / tau)
 * for sample interval dt and time constant tau (GYROCAL_THERMAL_TEMP_TAU_S in exported headers);
 * set *state to the first reading before the first call. Returns the filtered temperature (temp itself
 * when state is NULL). */
float gyrocal_temp_filter(float *state, float temp, float alpha);

void gyrocal_accum_reset(gyrocal_accum_t *acc);
void gyrocal_accum_add(gyrocal_accum_t *acc, const float sample[3]);
/* Window mean and mean of squares; `rate` is stored as the observation's reference. A window with a
 * NaN or infinite sample gives GYROCAL_E_INPUT here. */
gyrocal_status_t gyrocal_accum_finish(const gyrocal_accum_t *acc, float rate, gyrocal_obs_t *obs);

/* The servo method of Wang et al., Algorithm 1 on exactly six observations (regressors: means of squares and means). */
gyrocal_status_t gyrocal_algorithm1(const gyrocal_obs_t obs[GYROCAL_N_OBS], gyrocal_scale_bias_t *out,
                                    int *iterations);

/* First-moment estimator on exactly six rotation observations: sum_j k_j^2 (mean_j + b_j)^2 = rate^2,
 * solved exactly (Newton on beta0). */
gyrocal_status_t gyrocal_first_moment(const gyrocal_obs_t obs[GYROCAL_N_OBS], gyrocal_scale_bias_t *out,
                                      int *iterations);

#ifdef __cplusplus
}
#endif

#endif /* GYROCAL_CAL_H */
