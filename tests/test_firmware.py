"""The shipped C library against the Python implementation, to float32 precision.

The library is compiled with the host C compiler through :func:`gyrocal.firmware.load_library`.
Tolerances are first-order rounding bounds, never fitted to the results: with
``eps`` the float32 machine epsilon, a computation whose inputs and operations are
each rounded to ``eps`` lands within ``C_ROUND * eps`` times a componentwise
(Skeel / Oettli-Prager) condition of the problem, computed from the data in each test.
``C_ROUND = 32`` covers rounding the inputs to float32 (1/2), Gaussian elimination's
backward error on a 6x6 (gamma_3n ~ 18), the stop rule of the iterations (1) and the
final ``sqrt`` and division (2).
"""

from __future__ import annotations

import ctypes
import json
import re
from pathlib import Path

import numpy as np
import pytest

import gyrocal
from gyrocal import firmware
from gyrocal.capture.agreement import C_ROUND, EPS32, accumulator_bound, solution_bound
from gyrocal.errors import DegenerateDesignError, InputError, NonPhysicalEstimateError, OutOfRangeError
from gyrocal.estimators import Algorithm1, FirstMoment
from gyrocal.models import KG_INDEX, Affine, ScaleBias
from gyrocal.observations import ObservationSet, observe
from gyrocal.results.calibration import Calibration
from gyrocal.simulation.windows import paper_observations
from gyrocal.thermal import ThermalCalibration, ThermalRangeWarning, fit_smooth, interpolate, lagrange_weights
from gyrocal.units import unit_factor

EPS = EPS32
DATA = Path(gyrocal.__file__).parent / "data" / "imucal_ferraris"
FS_SESSION = 102.4  # Hz, see the data README


@pytest.fixture(scope="module")
def clib(tmp_path_factory):
    if firmware.find_c_compiler() is None:  # CI installs one: a missing compiler fails, never skips
        pytest.fail("no C compiler found (cc, gcc, clang or $CC); the C library cannot be built on this host")
    return firmware.load_library(tmp_path_factory.mktemp("c-build"))


@pytest.fixture(scope="module")
def session() -> tuple[np.ndarray, dict]:
    """The real hand-turned session: gyro samples (N, 3) [deg/s] and its region list."""
    gyro = np.loadtxt(DATA / "example_ferraris_session.csv", delimiter=",", skiprows=1, usecols=(1, 2, 3))
    regions = json.loads((DATA / "example_ferraris_session_list.json").read_text())
    return gyro, regions


# -- six-observation solvers -----------------------------------------------------------------------------------


solution_tolerance = solution_bound  # the same bound gyrocal capture holds a device's result to


def simulated(rng, n_gyros: int = 4) -> tuple[ObservationSet, np.ndarray, np.ndarray]:
    """The servo method's simulation settings (section III-A), per sample, for a few random gyros."""
    k = rng.uniform(0.8, 1.2, (n_gyros, 3))
    b = rng.uniform(-0.1, 0.1, (n_gyros, 3))
    return paper_observations(k, b, speed=np.pi / 3, rng=rng), k, b


def test_algorithm1_matches_python(clib, rng):
    obs, _, _ = simulated(rng)
    ref = Algorithm1(tol=1e-13).fit_batch(obs)
    for i in range(len(ref)):
        k, b, iterations = clib.algorithm1(obs.mean_sq[i], obs.mean[i], obs.rate[i])
        tol = solution_tolerance(ref.k[i], ref.b[i], obs.mean_sq[i], obs.mean[i], obs.rate[i] ** 2)
        assert np.all(np.abs(np.concatenate([k, b]) - ref.params[i]) <= tol)
        assert 1 <= iterations <= 10  # the servo method of Wang et al., Table I: a handful


def test_first_moment_matches_python(clib, rng):
    obs, _, _ = simulated(rng)
    ref = FirstMoment().fit_batch(obs)
    for i in range(len(ref)):
        k, b, _ = clib.first_moment(obs.mean[i], obs.rate[i])
        tol = solution_tolerance(ref.k[i], ref.b[i], obs.mean[i] ** 2, obs.mean[i], obs.rate[i] ** 2)
        assert np.all(np.abs(np.concatenate([k, b]) - ref.params[i]) <= tol)


def test_solvers_do_not_depend_on_units(clib, rng):
    """The same turns in deg/s and in rad/s give the same k, and b scaled by the unit factor."""
    obs, _, _ = simulated(rng, 1)
    c = unit_factor("deg/s")
    mean, rate = obs.mean[0], obs.rate[0]
    k_rad, b_rad, _ = clib.first_moment(mean, rate)
    k_deg, b_deg, _ = clib.first_moment(mean / c, rate / c)
    tol = solution_tolerance(k_rad.astype(float), b_rad.astype(float), mean**2, mean, rate**2)
    assert np.all(np.abs(k_deg - k_rad) <= 2 * tol[:3])
    assert np.all(np.abs(b_deg * c - b_rad) <= 2 * tol[3:])


def test_singular_design_is_an_error_in_c_and_python(clib, rng):
    obs, _, _ = simulated(rng, 1)
    mean, sq, rate = obs.mean[0].copy(), obs.mean_sq[0].copy(), obs.rate[0]
    mean[5], sq[5] = mean[4], sq[4]  # -z turn replaced by a copy of +z: two equal rows
    with pytest.raises(DegenerateDesignError, match="GYROCAL_E_SINGULAR"):
        clib.algorithm1(sq, mean, rate)
    with pytest.raises(DegenerateDesignError, match="GYROCAL_E_SINGULAR"):
        clib.first_moment(mean, rate)
    dup = ObservationSet(mean, sq, obs.noise_var[0], rate, obs.count, obs.duration, obs.static)
    with pytest.raises(DegenerateDesignError):
        Algorithm1().fit(dup)


def test_nearly_singular_design_is_refused(clib, rng):
    """Rows equal to within float32 rounding are below the pivot threshold too."""
    obs, _, _ = simulated(rng, 1)
    mean, sq = obs.mean[0].copy(), obs.mean_sq[0].copy()
    mean[5], sq[5] = mean[4] * (1 + 4 * EPS), sq[4] * (1 + 4 * EPS)
    with pytest.raises(DegenerateDesignError):
        clib.algorithm1(sq, mean, obs.rate[0])


def test_negative_k2_is_an_error_in_c_and_python(clib, rng):
    """A reference rate far below the measured one about x makes kx^2 negative."""
    obs, _, _ = simulated(rng, 1)
    rate = obs.rate[0].copy()
    rate[:2] *= 1e-3
    with pytest.raises(NonPhysicalEstimateError, match="GYROCAL_E_NONPHYSICAL"):
        clib.algorithm1(obs.mean_sq[0], obs.mean[0], rate)
    with pytest.raises(NonPhysicalEstimateError, match="GYROCAL_E_NONPHYSICAL"):
        clib.first_moment(obs.mean[0], rate)
    bad = ObservationSet(obs.mean[0], obs.mean_sq[0], obs.noise_var[0], rate, obs.count, obs.duration, obs.static)
    with pytest.raises(NonPhysicalEstimateError):
        Algorithm1().fit(bad)


def test_non_finite_or_zero_rate_is_an_input_error(clib, rng):
    obs, _, _ = simulated(rng, 1)
    rate = obs.rate[0].copy()
    rate[3] = 0.0
    with pytest.raises(InputError, match="GYROCAL_E_INPUT"):
        clib.first_moment(obs.mean[0], rate)


def test_never_nan_parameters_on_arbitrary_input(clib, rng):
    """Random designs, many of them absurd: the C solvers return finite parameters or an error code."""
    outcomes = set()
    for _ in range(300):
        scale = 10.0 ** rng.uniform(-3, 3)
        mean = rng.normal(0, scale, (6, 3)) * (rng.random((6, 3)) < 0.8)
        sq = mean**2 + rng.exponential(scale**2, (6, 3)) * rng.random()
        rate = np.abs(rng.normal(0, scale, 6)) + 1e-6
        for solve, args in ((clib.algorithm1, (sq, mean, rate)), (clib.first_moment, (mean, rate))):
            try:
                k, b, _ = solve(*args)
            except gyrocal.GyrocalError as exc:
                outcomes.add(type(exc).__name__)
                continue
            outcomes.add("ok")
            assert np.all(np.isfinite(k)) and np.all(k > 0) and np.all(np.isfinite(b))
    assert {"ok", "NonPhysicalEstimateError"} <= outcomes


# -- streaming accumulators ------------------------------------------------------------------------------------


accumulator_tolerance = accumulator_bound  # the same bound gyrocal capture holds a device's turn means to


def test_accumulator_matches_observe_on_real_session(clib, session):
    """Every region of the real session, in its own deg/s, streamed sample by sample."""
    gyro, regions = session
    for name, reg in regions.items():
        x = gyro[reg["start"]: reg["end"]]
        mean, mean_sq, count = clib.accumulate(x)
        ref = observe(x, FS_SESSION, "static")
        mean_tol, sq_tol = accumulator_tolerance(x)
        assert count == len(x), name
        assert np.all(np.abs(mean - ref.mean) <= mean_tol), name
        assert np.all(np.abs(mean_sq - ref.mean_sq) <= sq_tol), name


def test_accumulator_matches_observe_on_a_long_biased_window(clib, rng):
    """A long window (100 s at 200 Hz) whose bias dwarfs its noise."""
    x = 3.0 + rng.normal(0, 1e-3, (20_000, 3))
    mean, mean_sq, _ = clib.accumulate(x)
    ref = observe(x, 200.0, "static")
    mean_tol, sq_tol = accumulator_tolerance(x)
    assert np.all(np.abs(mean - ref.mean) <= mean_tol)
    assert np.all(np.abs(mean_sq - ref.mean_sq) <= sq_tol)


def test_accumulator_needs_two_samples(clib):
    with pytest.raises(InputError, match="GYROCAL_E_INPUT"):
        clib.accumulate(np.ones((1, 3)))


# -- corrections -----------------------------------------------------------------------------------------------


def correction_tolerance(matrix, offset, raw) -> np.ndarray:
    """Bound on ``matrix @ (raw - offset)`` in float32: eps times the sizes of every term."""
    return C_ROUND * EPS * ((np.abs(raw) + np.abs(offset)) @ np.abs(matrix).T)


@pytest.fixture(scope="module")
def session_calibration(session) -> Calibration:
    """The Python first-moment fit of the real session: six static poses and three 360 deg turns."""
    gyro, regions = session
    rad = gyro * unit_factor("deg/s")
    windows = []
    for name, reg in regions.items():
        x = rad[reg["start"]: reg["end"]]
        windows.append(observe(x, FS_SESSION, "angle", angle=2 * np.pi) if name.endswith("rot")
                       else observe(x, FS_SESSION, "static"))
    fit = FirstMoment().fit(ObservationSet.from_observations(windows))
    return Calibration(fit.model, input_units="deg/s", output_units="deg/s", method="first-moment",
                       covariance=fit.covariance, noise_std=fit.noise_std)


def test_correction_matches_python_on_real_session(clib, session, session_calibration):
    gyro, _ = session
    matrix, offset = session_calibration.correction
    out = clib.correct(matrix, offset, gyro)
    ref = session_calibration.correct(gyro)
    assert np.all(np.abs(out - ref) <= correction_tolerance(matrix, offset, gyro))


def test_affine_correction_matches_python(clib, rng):
    model = Affine(K=np.eye(3) + rng.normal(0, 0.02, (3, 3)), B=rng.normal(0, 0.05, 3))
    raw = rng.normal(0, 2.0, (200, 3))
    out = clib.correct(model.matrix, model.offset, raw)
    assert np.all(np.abs(out - model.correct(raw)) <= correction_tolerance(model.matrix, model.offset, raw))


def thermal_table(rng, units: str = "deg/s") -> ThermalCalibration:
    """The full-temperature-range method, Table 1 temperatures; Kg a smooth trend around an identity-like gyro plus fit noise."""
    temps = np.arange(-40.0, 51.0, 10.0)
    u = (temps[:, None] - 5.0) / 45.0
    base = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    kg = base + rng.normal(0, 0.01, 12) + u * rng.normal(0, 0.01, 12) + u**2 * rng.normal(0, 0.005, 12)
    kg = kg + rng.normal(0, 1e-3, kg.shape)  # per-point fit noise: not a quadratic, so the stencil matters
    return ThermalCalibration(temps=temps, kg=kg, smooth=fit_smooth(temps, kg), input_units=units, output_units=units)


def _k_matrix(v9: np.ndarray) -> np.ndarray:
    """K (..., 3, 3) from the first nine Kg elements (the full-temperature-range method, eq. 11)."""
    K = np.zeros(v9.shape[:-1] + (3, 3))
    for e, (row, col) in enumerate(KG_INDEX):
        K[..., row, col] = v9[..., e]
    return K


def thermal_tolerance(tc, temp, raw, w) -> np.ndarray:
    """Bound for ``w = K(T)^-1 (raw - B(T))`` in float32, through ``|K^-1|``.

    Kg(T) is off by ~eps * sum_i |L_i| |Kg_i| (rounding of the interpolation) plus
    ~eps * max|T| * |dKg/dT| (rounding of T and of the differences T - T_i).
    """
    kg = tc.kg_user
    idx, wts = lagrange_weights(tc.temps, temp)
    size = np.einsum("nk,nkj->nj", np.abs(wts), np.abs(kg[idx]))
    lo, hi = np.clip(temp - 1e-3, *tc.range), np.clip(temp + 1e-3, *tc.range)
    slope = np.abs(interpolate(tc.temps, kg, hi) - interpolate(tc.temps, kg, lo)) / (hi - lo)[:, None]
    size = size + np.abs(tc.temps).max() * slope
    kg_t = interpolate(tc.temps, kg, temp)
    terms = np.einsum("nij,nj->ni", _k_matrix(size[:, :9]), np.abs(w)) + np.abs(raw) + size[:, 9:]
    return C_ROUND * EPS * np.einsum("nij,nj->ni", np.abs(np.linalg.inv(_k_matrix(kg_t[:, :9]))), terms)


def python_thermal(tc, temp, raw, out_of_range="refuse") -> np.ndarray:
    """gyrocal.thermal's compensation, from and to the table's user units."""
    c, d = unit_factor(tc.input_units), unit_factor(tc.output_units)
    return tc.compensate(raw * c, temp, out_of_range=out_of_range) / d


def thermal_temperatures(tc, rng) -> np.ndarray:
    """Nodes, the first and last intervals, midpoints and random points, all inside the range."""
    t = tc.temps
    mids = (t[:-1] + t[1:]) / 2
    return np.concatenate([t, mids, t[:-1] + 1e-3, t[1:] - 1e-3, rng.uniform(t[0], t[-1], 40)])


@pytest.mark.parametrize("units", ["deg/s", "rad/s"])
def test_thermal_matches_python(clib, rng, units):
    tc = thermal_table(rng, units)
    temp = thermal_temperatures(tc, rng)
    raw = rng.normal(0, 100.0 if units == "deg/s" else 2.0, (len(temp), 3))
    ref = python_thermal(tc, temp, raw)
    out = clib.thermal_correct(tc.temps, tc.kg_user, temp, raw)
    assert np.all(np.abs(out - ref) <= thermal_tolerance(tc, temp, raw, ref))


def test_thermal_out_of_range_refused_or_clamped_like_python(clib, rng):
    tc = thermal_table(rng)
    lo, hi = tc.range
    temp = np.array([lo - 15.0, lo - 0.75, hi + 0.6, hi + 35.0])  # beyond the 0.5 degC margin
    raw = rng.normal(0, 50.0, (len(temp), 3))
    for i in range(len(temp)):
        with pytest.raises(OutOfRangeError, match="GYROCAL_E_RANGE"):
            clib.thermal_correct(tc.temps, tc.kg_user, temp[i:i + 1], raw[i:i + 1])
    with pytest.warns(ThermalRangeWarning):
        ref = python_thermal(tc, temp, raw, "clamp")
    out = clib.thermal_correct(tc.temps, tc.kg_user, temp, raw, clamp=True)
    edge = np.clip(temp, *tc.range)
    assert np.all(np.abs(out - ref) <= thermal_tolerance(tc, edge, raw, ref))
    # inside the margin both clamp silently, without being asked
    near = np.array([lo - 0.4, hi + 0.3])
    ref = python_thermal(tc, near, raw[:2])
    out = clib.thermal_correct(tc.temps, tc.kg_user, near, raw[:2])
    assert np.all(np.abs(out - ref) <= thermal_tolerance(tc, np.clip(near, lo, hi), raw[:2], ref))


# -- headers ---------------------------------------------------------------------------------------------------

DRIVER = """
#include "{header}"
void apply_header(const float raw[3], float out[3]) {{ gyrocal_correct(&GYROCAL_CALIBRATION, raw, out); }}
"""
THERMAL_DRIVER = """
#include "{header}"
int apply_thermal(float temp, const float raw[3], unsigned flags, float out[3])
{{
    return gyrocal_thermal_correct(&GYROCAL_THERMAL, temp, raw, flags, out);
}}
"""


def _build_driver(tmp_path, header_text: str, driver: str, name: str):
    (tmp_path / f"{name}.h").write_text(header_text)
    src = tmp_path / f"{name}_driver.c"
    src.write_text(driver.format(header=f"{name}.h"))
    return firmware.load_library(tmp_path / "build", extra_sources=[src], include_dirs=[tmp_path]).dll


def _literals(text: str, name: str) -> np.ndarray:
    body = text[text.index(name):]
    body = body[: body.index(";")]
    return np.array([float(v) for v in re.findall(r"([-+0-9.e]+)f\b", body)])


def test_c_header_is_read_by_the_library(clib, tmp_path, session, session_calibration):
    gyro, _ = session
    text = session_calibration.c_header()
    dll = _build_driver(tmp_path, text, DRIVER, "gyrocal_calibration")
    raw = np.ascontiguousarray(gyro[::50], dtype=np.float32)
    out = np.empty_like(raw)
    fptr = ctypes.POINTER(ctypes.c_float)
    for i in range(len(raw)):
        dll.apply_header(raw[i].ctypes.data_as(fptr), out[i].ctypes.data_as(fptr))
    matrix, offset = session_calibration.correction
    ref = session_calibration.correct(raw.astype(float))
    assert np.all(np.abs(out - ref) <= correction_tolerance(matrix, offset, raw))


def test_c_header_documents_convention_units_parameters_and_provenance(session_calibration):
    text = session_calibration.c_header()
    comment = text[: text.index("*/")]
    assert "w_true = matrix @ (raw - offset)" in comment
    assert "raw and offset in deg/s" in comment and "w_true in deg/s" in comment
    for name, value, sigma in zip(("kx", "ky", "kz", "bx", "by", "bz"), session_calibration.model.params,
                                  session_calibration.std):
        line = next(ln for ln in comment.splitlines() if re.search(rf"\b{name} =", ln))
        assert f"{value: .9e}" in line and f"+- {sigma:.3e}" in line
    assert "method first-moment" in comment and f"gyrocal {gyrocal.__version__}" in comment
    # every number reads back to the float32 of the correction, exactly
    matrix, offset = session_calibration.correction
    values = _literals(text, "GYROCAL_CALIBRATION =")
    assert np.array_equal(values.astype(np.float32), np.concatenate([matrix.ravel(), offset]).astype(np.float32))


def test_c_header_without_covariance_says_so():
    cal = Calibration(ScaleBias(k=[1.0, 1.01, 0.99], b=[0.01, 0.0, -0.02]), method="algorithm1")
    text = cal.c_header()
    assert text.count("not estimated") == 6
    assert "rad/s" in text


def test_thermal_header_is_read_by_the_library(clib, tmp_path, rng):
    tc = thermal_table(rng)
    text = tc.c_header()
    assert "Kxx, Kyy, Kzz, Kyx, Kzx, Kxy, Kzy, Kxz, Kyz, Bx, By, Bz" in text
    assert "s = clamp(i - 2, 0, n - 3)" in text
    dll = _build_driver(tmp_path, text, THERMAL_DRIVER, "gyrocal_thermal")
    dll.apply_thermal.argtypes = [ctypes.c_float, ctypes.POINTER(ctypes.c_float), ctypes.c_uint,
                                  ctypes.POINTER(ctypes.c_float)]
    temp = thermal_temperatures(tc, rng)
    raw = np.ascontiguousarray(rng.normal(0, 100.0, (len(temp), 3)), dtype=np.float32)
    out = np.empty_like(raw)
    fptr = ctypes.POINTER(ctypes.c_float)
    for i in range(len(temp)):
        assert dll.apply_thermal(float(temp[i]), raw[i].ctypes.data_as(fptr), 0, out[i].ctypes.data_as(fptr)) == 0
    ref = python_thermal(tc, temp, raw.astype(float))
    assert np.all(np.abs(out - ref) <= thermal_tolerance(tc, temp, raw, ref))
    assert dll.apply_thermal(60.0, raw[0].ctypes.data_as(fptr), 0, out[0].ctypes.data_as(fptr)) == 5  # E_RANGE


def test_thermal_header_refuses_a_short_table():
    class Table:
        temps = np.array([0.0, 10.0])
        kg_user = np.zeros((2, 12))
        input_units = output_units = "deg/s"
        range = (0.0, 10.0)
        temp_tau = 0.0

    with pytest.raises(InputError, match="at least|>= 3"):
        firmware.thermal_header(Table())


def test_headers_carry_their_prefix_and_check_the_library_version(clib, tmp_path, rng):
    """Two sensors' tables in one translation unit compile side by side; a header made for another
    library version stops the build. Reference: the C compiler itself, and gyrocal_cal.h's own macro."""
    header = (firmware.c_source_dir() / "gyrocal_cal.h").read_text()
    version = re.search(r"#define GYROCAL_CAL_VERSION (\d+)", header)
    assert version is not None and int(version.group(1)) == firmware.C_LIBRARY_VERSION
    tc = thermal_table(rng)
    cal = Calibration(ScaleBias(k=[1.0, 1.01, 0.99], b=[0.01, 0.0, -0.02]), "deg/s", "deg/s")
    (tmp_path / "imu1.h").write_text(cal.c_header(prefix="imu1"))
    (tmp_path / "imu2.h").write_text(cal.c_header(prefix="imu2"))
    (tmp_path / "imu2_thermal.h").write_text(tc.c_header(prefix="imu2"))
    driver = tmp_path / "two.c"
    driver.write_text('#include "imu1.h"\n#include "imu2.h"\n#include "imu2_thermal.h"\n'
                      "void both(const float raw[3], float a[3], float b[3])\n"
                      "{ gyrocal_correct(&IMU1_CALIBRATION, raw, a); gyrocal_correct(&IMU2_CALIBRATION, raw, b); }\n"
                      "int n2(void) { return IMU2_THERMAL_N; }\n")
    dll = firmware.load_library(tmp_path / "build", extra_sources=[driver], include_dirs=[tmp_path]).dll
    assert dll.n2() == len(tc.temps)
    stale = cal.c_header(prefix="old").replace("#define OLD_CALIBRATION_LIB_VERSION 2",
                                               "#define OLD_CALIBRATION_LIB_VERSION 1")
    (tmp_path / "old.h").write_text(stale)
    (tmp_path / "old.c").write_text('#include "old.h"\nint unused_old(void) { return 0; }\n')
    with pytest.raises(firmware.CCompileError, match="written for gyrocal_cal.h version"):
        firmware.load_library(tmp_path / "build2", extra_sources=[tmp_path / "old.c"], include_dirs=[tmp_path])


def test_library_source_uses_nothing_beyond_math_h():
    source = (firmware.c_source_dir() / "gyrocal_cal.c").read_text() + (firmware.c_source_dir() / "gyrocal_cal.h").read_text()
    includes = set(re.findall(r"#include\s*[<\"]([^>\"]+)", source))
    assert includes == {"math.h", "stdint.h", "gyrocal_cal.h"}
    assert not re.search(r"\b(malloc|calloc|realloc|free|printf|memcpy|memset)\s*\(", source)


def test_compile_error_is_reported_with_the_compiler_message(clib, tmp_path):
    broken = tmp_path / "broken.c"
    broken.write_text("int broken(void) { return undeclared_name; }\n")
    with pytest.raises(firmware.CCompileError, match="undeclared_name"):
        firmware.load_library(tmp_path / "build", extra_sources=[broken])


def test_missing_compiler_is_a_missing_dependency(monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.setenv("CC", "no-such-cc")
    assert firmware.find_c_compiler() is None
    with pytest.raises(gyrocal.errors.MissingDependencyError, match="no C compiler found"):
        firmware.build_library(tmp_path)


def test_temperature_filter_matches_the_forward_low_pass_and_removes_the_steps(clib):
    """Readings in whole degrees through gyrocal_temp_filter: scipy's first-order filter, to float32."""
    from scipy.signal import lfilter

    fs, tau = 100.0, 20.0
    t = np.arange(0, 600, 1 / fs)
    reading = np.round(20.0 + 0.02 * t)  # a slow soak read in whole degrees: 12 steps of 1 degC
    out = clib.temp_filter(reading, fs, tau)
    a = np.exp(-1 / (fs * tau))
    ref, _ = lfilter([1 - a], [1, -a], reading, zi=[a * reading[0]])
    assert np.max(np.abs(out - ref)) < 1e-4  # float32 state over 60,000 steps near 30 degC
    # a 1 degC step of the reading moves the filtered temperature by at most 2 alpha (lag < 1 degC) per sample
    assert np.max(np.abs(np.diff(out))) < 2 * (1 - a) < 0.01


def test_c_and_python_share_the_range_margin():
    from gyrocal.thermal.lagrange import RANGE_MARGIN

    header = (firmware.c_source_dir() / "gyrocal_cal.h").read_text()
    margin = re.search(r"#define GYROCAL_THERMAL_MARGIN ([0-9.]+)f", header)
    assert margin is not None and float(margin.group(1)) == RANGE_MARGIN


def test_c_and_python_unpack_kg_the_same_way():
    """The C library's KG_SLOT (gyrocal_cal.c) against gyrocal.models.KG_INDEX: Kg element e sits at
    row * 3 + column of K in both."""
    source = (firmware.c_source_dir() / "gyrocal_cal.c").read_text()
    slots = re.search(r"KG_SLOT\[9\]\s*=\s*\{([^}]*)\}", source)
    assert slots is not None
    assert [int(v) for v in slots.group(1).split(",")] == [3 * r + c for r, c in KG_INDEX]


def test_accumulator_mean_stays_within_a_few_ulps_on_a_long_offset_window(clib):
    """Reference: the float64 mean. A window whose first sample is 0 and the rest about 61 deg/s (a turn entered
    from rest): the sum of 200,000 deviations reaches 1.2e7, where one float32 addition rounds by up to 0.5;
    Neumaier's compensated sum keeps the mean within 2 float32 ulps of itself, a plain sum is 30x further off."""
    x = np.full((200_000, 3), 61.0) + np.random.default_rng(7).normal(0, 1.0, (200_000, 3))
    x[0] = 0.0
    x32 = x.astype(np.float32)
    mean, _, _ = clib.accumulate(x32)
    ref = x32.astype(np.float64).mean(axis=0)
    assert np.all(np.abs(mean - ref) <= 2 * np.finfo(np.float32).eps * np.abs(ref)), mean - ref
