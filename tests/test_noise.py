"""Noise figures read off the Allan deviation of simulated static data.

References: the Allan deviation of white noise, Gauss-Markov bias and random walk in closed form (IEEE Std
952), with tolerances from the deviation's own sampling error.
"""

import math

import numpy as np
import pytest

from gyrocal.errors import FileFormatError, InputError
from gyrocal.models import ScaleBias
from gyrocal.noise import BI_FACTOR, characterise, load_noise, noise_density_arg, save_noise
from gyrocal.simulation import VirtualGyro

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
    """Relative standard deviation of an Allan deviation from T / tau clusters (non-overlapping: conservative)."""
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
    theory = np.sqrt(_avar_theory(report.taus))
    ok = report.taus < report.taus[-1] / 10  # enough clusters for a tight check
    assert np.all(np.abs(report.adev[:, ok] / theory[ok] - 1) < 4 * _rel_sd(report.taus[ok]) + 0.02)


def test_angle_random_walk_is_the_noise_density(report):
    expect = SIGMA / math.sqrt(FS)
    # read on the -1/2 line at short tau, where white noise dominates to < 1 %
    assert np.all(np.abs(report.arw / expect - 1) < 0.02)
    np.testing.assert_allclose(report.noise_std, SIGMA, rtol=0.02)


def test_bias_instability_is_the_floor_over_0664(report):
    theory = np.sqrt(_avar_theory(report.taus))
    floor = theory.min() / BI_FACTOR
    tol = 4 * _rel_sd(report.bias_instability_tau)
    assert np.all(np.abs(report.bias_instability / floor - 1) < tol), (report.bias_instability, floor, tol)


def test_rate_random_walk_on_the_plus_half_line(report):
    # the figure is the +1/2 line through the read point; compare with the theory at that point
    for a in range(3):
        i = np.argmin(np.abs(report.rrw[a] * np.sqrt(report.taus / 3) - report.adev[a]))
        tau = report.taus[i]
        expect = math.sqrt(_avar_theory(tau)) * math.sqrt(3 / tau)
        assert abs(report.rrw[a] / expect - 1) < 4 * _rel_sd(tau), (a, tau, report.rrw[a], expect)


def test_white_noise_only_reports_no_floor(rng):
    m = rng.standard_normal((20000, 3)) * 0.01
    r = characterise(m, 100.0)
    assert np.all(np.isnan(r.rrw))
    assert np.all(np.isnan(r.bias_instability))


def test_json_round_trip(report, tmp_path):
    path = tmp_path / "noise.json"
    save_noise(path, report)
    back = load_noise(path)
    np.testing.assert_array_equal(back.adev, report.adev)
    np.testing.assert_array_equal(back.rrw, report.rrw)
    np.testing.assert_allclose(noise_density_arg(str(path)), report.arw)


def test_load_rejects_bad_fields(report, tmp_path):
    import json

    doc = report.to_dict()
    doc["arw"] = [1.0, 2.0]
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(FileFormatError, match="arw"):
        load_noise(path)


def test_noise_density_argument():
    np.testing.assert_allclose(noise_density_arg("0.002"), 0.002)
    np.testing.assert_allclose(noise_density_arg("0.01 deg/s/rtHz"), math.radians(0.01))
    with pytest.raises(InputError, match="noise-density"):
        noise_density_arg("fast")
    with pytest.raises(InputError, match="> 0"):
        noise_density_arg("-1")


def test_too_short_record_is_refused():
    with pytest.raises(InputError, match="at least 100"):
        characterise(np.zeros((10, 3)), 100.0)


def test_allan_plot_draws_every_axis(report):
    from gyrocal.plotting import new_figure
    from gyrocal.plotting.noise import allan_deviation_plot

    fig = new_figure()
    art = allan_deviation_plot(fig.subplots(), report)
    assert len(art["adev"]) == 3 and len(art["arw"]) == 3 and len(art["rrw"]) == 3 and len(art["bias"]) == 3
    np.testing.assert_array_equal(art["adev"][0].get_ydata(), report.adev[0])
