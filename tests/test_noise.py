"""Noise figures read off the Allan deviation of simulated logs at rest, with their intervals.

Independent references: the Allan variance in closed form for white + Gauss-Markov + random
walk noise (IEEE Std 952 annex C / Stable32 noise models), the known white-noise density of
the simulation, and the non-overlapping Allan-deviation spread 1/sqrt(2(K-1)) for the
width of the edf-based intervals (which allantools computes by Greenhall's algorithm).
"""

import json
import math
import warnings

import numpy as np
import pytest

from gyrocal.errors import FileFormatError, InputError, UnitError
from gyrocal.models import ScaleBias
from gyrocal.noise import NoiseWarning, characterise, characterise_recording
from gyrocal.noise.document import load_noise, noise_density_arg, save_noise
from gyrocal.recording import Recording
from gyrocal.simulation import VirtualGyro

# IEEE Std 952-1997, Annex C: a flicker floor of the Allan deviation sits at sqrt(2 ln 2 / pi) B = 0.6643 B
FLICKER_FLOOR = math.sqrt(2 * math.log(2) / math.pi)

FS, HOURS = 100.0, 3.0
SIGMA, BI_STD, BI_TAU, RRW = 0.01, 2e-4, 100.0, 2e-5


def _avar_theory(tau):
    """Allan variance of white noise + first-order Gauss-Markov bias + rate random walk."""
    white = SIGMA**2 / FS / tau
    r = tau / BI_TAU
    var_mean = 2 * BI_STD**2 / r * (1 - (1 - np.exp(-r)) / r)  # variance of a tau-average
    cov_next = BI_STD**2 / r**2 * (1 - np.exp(-r)) ** 2  # covariance of adjacent averages
    return white + var_mean - cov_next + RRW**2 * tau / 3


def _rel_sd(tau):
    """Relative sd of an Allan deviation from T / tau non-overlapping clusters (conservative)."""
    clusters = HOURS * 3600 / tau
    return 1.0 / np.sqrt(2 * (clusters - 1))


@pytest.fixture(scope="module")
def report():
    rng = np.random.default_rng(20261122)
    gyro = VirtualGyro(ScaleBias(np.ones(3), np.zeros(3)), noise_std=SIGMA, bias_instability=BI_STD, bias_tau=BI_TAU,
                       rate_random_walk=RRW)
    m = gyro.measure(np.zeros((int(FS * HOURS * 3600), 3)), FS, rng)
    return characterise(m, FS)


def test_adev_follows_theory(report):
    theory = np.sqrt(_avar_theory(report.gyro.taus))
    ok = report.gyro.taus < report.gyro.taus[-1] / 10  # enough clusters for a tight check
    adev = report.gyro.adev[:3, ok]
    assert np.all(np.abs(adev / theory[ok] - 1) < 4 * _rel_sd(report.gyro.taus[ok]) + 0.02)


def test_density_is_the_white_noise_and_inside_its_interval(report):
    d = report.gyro.density
    expect = SIGMA / math.sqrt(FS)
    half = (d.high - d.low) / 2
    # read on the -1/2 line at short tau, where white noise dominates to < 1 %; 4 interval half-widths + 1 %
    assert np.all(np.abs(d.value - expect) < 4 * half + 0.01 * expect), (d.value, half)
    np.testing.assert_allclose(report.noise_std, SIGMA, rtol=0.02)
    assert np.all(d.low < d.value) and np.all(d.value < d.high)


def test_bias_instability_is_the_floor_over_0664(report):
    theory = np.sqrt(_avar_theory(report.gyro.taus))
    floor = theory.min() / FLICKER_FLOOR
    b = report.gyro.bias_instability
    tol = 4 * _rel_sd(b.tau[:3])
    assert np.all(np.abs(b.value[:3] / floor - 1) < tol), (b.value, floor, tol)
    # the overlapping estimator's interval is narrower than the non-overlapping spread, not wildly so
    rel = (b.high[:3] - b.low[:3]) / 2 / b.value[:3]
    assert np.all(rel < _rel_sd(b.tau[:3]) * 1.2) and np.all(rel > _rel_sd(b.tau[:3]) / 3), rel


def test_random_walk_on_the_plus_half_line(report):
    w = report.gyro.random_walk
    for a in range(3):
        tau = w.tau[a]
        expect = math.sqrt(_avar_theory(tau)) * math.sqrt(3 / tau)
        assert abs(w.value[a] / expect - 1) < 4 * _rel_sd(tau), (a, tau, w.value[a], expect)
        assert w.low[a] < w.value[a] < w.high[a]
    assert np.all(np.isnan(report.gyro.random_walk_bound))  # seen, so no bound


def test_sensor_row_pools_the_axes(report):
    g = report.gyro
    np.testing.assert_allclose(g.adev[3], np.sqrt(np.mean(g.adev[:3] ** 2, axis=0)))
    assert abs(g.density.value[3] / (SIGMA / math.sqrt(FS)) - 1) < 0.01
    assert g.density.edf[3] > 2 * g.density.edf[0]  # three axes' worth of data


def test_density_intervals_cover_the_truth_at_their_level():
    """Coverage over seeds: about 68 % of 1-sigma intervals hold the true density (white noise)."""
    rng = np.random.default_rng(7)
    hits = []
    for _ in range(80):
        r = characterise(rng.standard_normal((3000, 3)) * SIGMA, FS)
        d = r.gyro.density
        truth = SIGMA / math.sqrt(FS)
        hits.extend((d.low[:3] <= truth) & (truth <= d.high[:3]))
    rate, n = np.mean(hits), len(hits)
    assert abs(rate - r.confidence) < 4 * math.sqrt(r.confidence * (1 - r.confidence) / n), rate


def test_white_noise_only_reports_no_floor_and_bounds_the_walk(rng):
    r = characterise(rng.standard_normal((20000, 3)) * 0.01, 100.0)
    assert np.all(np.isnan(r.gyro.random_walk.value))
    assert np.all(np.isnan(r.gyro.bias_instability.value))
    # no random walk in the data: the 95 % bound is positive and above zero walk, of the size
    # sigma(tau_max) sqrt(3 / tau_max) of the white noise at the longest averaging time
    tmax = r.gyro.taus[-1]
    scale = 0.01 / math.sqrt(100.0 * tmax) * math.sqrt(3 / tmax)
    assert np.all(r.gyro.random_walk_bound > scale * 0.5) and np.all(r.gyro.random_walk_bound < scale * 3)


def test_accelerometer_figures_in_si(rng):
    n, fs = 200_000, 100.0
    g = rng.standard_normal((n, 3)) * 0.01
    vrw, walk = 2e-3, 5e-4  # m/s^2/sqrt(Hz), m/s^3/sqrt(Hz)
    a = np.array([0.0, 0.0, 9.81]) + rng.standard_normal((n, 3)) * vrw * math.sqrt(fs)
    a += np.cumsum(rng.standard_normal((n, 3)) * walk / math.sqrt(fs), axis=0)
    r = characterise(g, fs, accel=a)
    d = r.accel.density
    assert np.all(np.abs(d.value[:3] - vrw) < 4 * (d.high[:3] - d.low[:3]) / 2 + 0.01 * vrw)
    w = r.accel.random_walk
    seen = np.isfinite(w.value)
    assert seen[3] and np.all(np.abs(w.value[seen] - walk) < 4 * (w.high[seen] - w.low[seen]) / 2 + 0.1 * walk), w


def test_a_log_that_moves_is_cut_to_its_longest_still_stretch(rng):
    fs, n = 100.0, 60_000
    g = rng.standard_normal((n, 3)) * 0.01
    g[20_000:21_000, 2] += 0.5  # a 10 s turn at 29 deg/s
    with pytest.warns(NoiseWarning, match="longest still stretch, 2[01].*-600.0 s"):
        r = characterise(g, fs)
    assert r.start > 200 and r.stop == 600.0 and r.motions_left_out == 1
    assert abs(r.density[2] / (0.01 / 10) - 1) < 0.02  # the turn does not reach the figures
    with pytest.raises(InputError, match="the log moves .1 motion, at 19.*motion restrict"):
        characterise(g, fs, motion="refuse")


def test_six_turns_are_refused_not_read_as_bias_instability():
    from gyrocal.simulation import ServoProtocol, simulate_servo

    rec, _ = simulate_servo(VirtualGyro(ScaleBias(np.ones(3), np.zeros(3)), noise_std=0.01), ServoProtocol(),
                            sample_rate=200.0, rng=np.random.default_rng(3))
    with pytest.raises(InputError, match="the log moves .*still stretch is [0-3].[0-9] s.*at least 10 s"):
        characterise_recording(rec)


def test_constant_and_all_zero_data_are_refused(rng):
    with pytest.raises(InputError, match="axis x reads 0 in every sample"):
        characterise(np.zeros((5000, 3)), 100.0)
    g = rng.standard_normal((5000, 3)) * 0.01
    g[:, 1] = 0.25
    with pytest.raises(InputError, match="axis y reads 0.25 in every sample"):
        characterise(g, 100.0)


def test_counts_without_a_sensitivity_are_refused(rng):
    rec = Recording.from_rate(np.round(rng.standard_normal((5000, 3)) * 20), 100.0, units="counts",
                              source_units="counts")
    with pytest.raises(UnitError, match="raw counts; give sensitivity"):
        characterise_recording(rec)


def test_too_short_record_is_refused(rng):
    with pytest.raises(InputError, match="at least 100"):
        characterise(rng.standard_normal((50, 3)), 100.0)


def test_file_round_trip_and_density_argument(report, tmp_path):
    path = tmp_path / "noise.json"
    save_noise(path, report)
    back = load_noise(path)
    np.testing.assert_array_equal(back.gyro.adev, report.gyro.adev)
    np.testing.assert_array_equal(back.gyro.random_walk.high, report.gyro.random_walk.high)
    np.testing.assert_array_equal(back.gyro.bias_instability.edf, report.gyro.bias_instability.edf)
    assert back.accel is None and back.samples == report.samples
    np.testing.assert_allclose(noise_density_arg(str(path)), report.density)


def test_zero_density_files_are_refused(report, tmp_path):
    path = tmp_path / "zero.json"
    save_noise(path, report)
    doc = json.loads(path.read_text())
    doc["gyroscope"]["y"]["density"]["value"] = 0.0
    path.write_text(json.dumps(doc))
    with pytest.raises(FileFormatError, match="gyroscope.y.density.value' must be a number > 0"):
        load_noise(path)
    with pytest.raises(InputError, match="gives a zero noise density on y"):
        noise_density_arg(str(path))


def _v1_doc():
    """A version 1 noise file as ``gyrocal noise --json`` wrote it before intervals existed."""
    taus = [0.01, 0.1, 1.0]
    return {"format": "gyrocal.noise", "version": 1, "sample_rate": 100.0, "duration": 60.0,
            "arw": [1e-3, 2e-3, 3e-3], "noise_std": [1e-2, 2e-2, 3e-2], "bias_instability": [None, 1e-5, None],
            "bias_instability_tau": [None, 10.0, None], "rrw": [None, None, None], "taus": taus,
            "adev": [[1e-2, 3e-3, 1e-3], [2e-2, 6e-3, 2e-3], [3e-2, 9e-3, 3e-3]]}


def test_version_1_files_still_load(tmp_path):
    path = tmp_path / "v1.json"
    path.write_text(json.dumps(_v1_doc()))
    r = load_noise(path)
    np.testing.assert_allclose(r.density, [1e-3, 2e-3, 3e-3])
    assert np.isnan(r.gyro.density.low).all() and r.gyro.bias_instability.value[1] == 1e-5
    np.testing.assert_allclose(noise_density_arg(str(path)), [1e-3, 2e-3, 3e-3])
    doc = _v1_doc()
    doc["arw"] = [1.0, 0.0, 1.0]
    path.write_text(json.dumps(doc))
    with pytest.raises(FileFormatError, match="> 0"):
        load_noise(path)


def test_noise_density_argument():
    np.testing.assert_allclose(noise_density_arg("0.002"), 0.002)
    np.testing.assert_allclose(noise_density_arg("0.01 deg/s/rtHz"), math.radians(0.01))
    with pytest.raises(InputError, match="noise-density"):
        noise_density_arg("fast")
    with pytest.raises(InputError, match="> 0"):
        noise_density_arg("-1")


def test_allan_plot_draws_every_axis_in_the_chosen_unit(report):
    from gyrocal.plotting import new_figure
    from gyrocal.plotting.noise import allan_deviation_plot

    fig = new_figure()
    ax = fig.subplots()
    art = allan_deviation_plot(ax, report.gyro, unit="deg/s")
    assert [len(art[k]) for k in ("adev", "density", "random_walk", "bias")] == [3, 3, 3, 3]
    np.testing.assert_allclose(art["adev"][0].get_ydata(), np.degrees(report.gyro.adev[0]))
    assert "deg/s" in ax.get_ylabel()


def _warming(t, start=20.0, end=55.0, tau=200.0):
    """First-order warm-up in closed form: T(t) = end - (end - start) exp(-t / tau)."""
    return end - (end - start) * np.exp(-t / tau)


def test_a_warming_board_warns_that_the_long_tau_figures_hold_the_drift(rng):
    """Reference: the warm-up's closed form, whose range over the log is 20 to 55 - 35 exp(-3) = 53.26 degC
    (the recorded range is of block means, within a block's rise of it), and a constant temperature, which
    is no drift at all."""
    fs, n = 50.0, 30_000
    t = np.arange(n) / fs
    g = rng.standard_normal((n, 3)) * 0.01
    with pytest.warns(NoiseWarning, match=r"temperature rises by 3[0-3]\.\d degC .*include the bias's thermal "
                                          r"drift: let the board warm up.*cut the log to its stable part"):
        r = characterise(g, fs, temp=_warming(t) + rng.standard_normal(n) * 0.1)
    assert r.temperature[0] == pytest.approx(20.0, abs=1.0) and r.temperature[1] == pytest.approx(53.26, abs=0.2)
    assert "thermal drift" in r.warnings[-1]
    with warnings.catch_warnings():
        warnings.simplefilter("error", NoiseWarning)
        flat = characterise(g, fs, temp=25.0 + np.round(rng.standard_normal(n) * 0.1, 2))
    assert flat.temperature_span < 0.2 and flat.warnings == ()
    assert characterise(g, fs).temperature is None


def test_a_small_monotone_drift_warns_but_a_small_wander_does_not(rng):
    """Reference: a straight 1-degC ramp (monotone: Spearman rho 1) against a 1-degC sine wander over
    three periods (rho near 0), both under the 2-degC span threshold."""
    fs, n = 50.0, 30_000
    t = np.arange(n) / fs
    g = rng.standard_normal((n, 3)) * 0.01
    with pytest.warns(NoiseWarning, match=r"temperature falls by 1\.0 degC"):
        characterise(g, fs, temp=30.0 - t / t[-1])
    with warnings.catch_warnings():
        warnings.simplefilter("error", NoiseWarning)
        r = characterise(g, fs, temp=30.0 + 0.5 * np.sin(2 * np.pi * 3 * t / t[-1]))
    assert r.temperature_span == pytest.approx(1.0, abs=0.05)


def test_the_temperature_range_round_trips_and_older_version_2_files_load(report, tmp_path, rng):
    """Reference: the range handed in; a version 2 file written before the field existed (no
    ``analysed.temperature``) keeps loading, with no temperature."""
    path = tmp_path / "noise.json"
    r = characterise(rng.standard_normal((5000, 3)) * 0.01, 50.0, temp=np.full(5000, 31.5))
    save_noise(path, r)
    doc = json.loads(path.read_text())
    assert doc["version"] == 2 and doc["analysed"]["temperature"] == {"min": 31.5, "max": 31.5, "span": 0.0,
                                                                       "unit": "degC"}
    assert load_noise(path).temperature == (31.5, 31.5)
    del doc["analysed"]["temperature"]
    path.write_text(json.dumps(doc))
    assert load_noise(path).temperature is None
    doc["analysed"]["temperature"] = {"min": 40.0, "max": 30.0}
    path.write_text(json.dumps(doc))
    with pytest.raises(FileFormatError, match="analysed.temperature' must hold numbers min <= max"):
        load_noise(path)
