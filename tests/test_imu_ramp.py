"""Poses taken on a temperature ramp: ``simulate --temp-ramp``, the joint fit across poses, ``gyrocal imu`` on it.

References: pose means built here from a board's cubics (gravity in drawn directions through the
truth's own ``A(T)^-1`` and ``o(T)``, noise of a known standard error), so the joint fit's estimates are
compared with parameters it never saw; the simulated log is checked against the sidecar's cubics
evaluated here from its JSON; the CLI run against the same sidecar.
"""

import json
import math

import numpy as np
import pytest
from cli_runner import invoke, refused
from scipy.stats import binom
from thermal_sessions import smooth_at, truth_params

from gyrocal.errors import InputError
from gyrocal.imu.ramp import fit_ramp_accel, is_ramp
from gyrocal.models import ScaleBias
from gyrocal.results.files import load
from gyrocal.simulation.chamber import chamber_session, random_thermal_imu
from gyrocal.simulation.ramp import ramp_session

G = 9.80665
_LOWER = [0, 3, 4, 6, 7, 8, 9, 10, 11]  # the 9-parameter model's entries of the truth's 12
SE = 0.02 / np.sqrt(300)  # a 3 s pose at 100 Hz with 0.02 m/s^2 per sample


def _poses(truth, temps, rng):
    """Pose means (n, 3) of gravity in uniformly drawn directions at `temps`, with noise of sd SE per axis."""
    d = rng.standard_normal((len(temps), 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    u = np.array([np.linalg.solve(truth.params(t)[0][:9].reshape(3, 3), G * di) + truth.params(t)[0][9:]
                  for t, di in zip(temps, d)])
    return u + SE * rng.standard_normal(u.shape)


def _at(fit, temps):
    """Values and 1-sigma (N, m) of a :class:`RampFit` at `temps`."""
    width = fit.coefs.shape[1]
    powers = np.vander((np.asarray(temps) - fit.centre) / fit.scale, width, increasing=True)
    cov = fit.covariance.reshape(len(fit.orders), width, len(fit.orders), width)
    return powers @ fit.coefs.T, np.sqrt(np.einsum("np,jpjq,nq->nj", powers, cov, powers))


def test_joint_fit_one_sigma_against_the_truth():
    """Over 120 seeded boards (cubic truth, 200 poses from -25 to 60 degC), one z-score per board (a drawn
    parameter at a drawn temperature, so the z's are independent): RMS z within 1 +- 3/sqrt(2m), mean z
    within 3/sqrt(m)."""
    z = []
    for seed in range(120):
        rng = np.random.default_rng(1000 + seed)
        truth = random_thermal_imu(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), rng)
        temps = np.sort(rng.uniform(-25.0, 60.0, 200))
        fit = fit_ramp_accel(_poses(truth, temps, rng), np.full((200, 3), SE), temps, "triangular")
        at = rng.uniform(-25.0, 60.0)
        value, sigma = _at(fit, [at])
        j = seed % 9
        z.append((value[0, j] - truth.params(at)[0][_LOWER][j]) / sigma[0, j])
    m = len(z)
    assert abs(np.sqrt(np.mean(np.square(z))) - 1) < 3 / np.sqrt(2 * m), np.sqrt(np.mean(np.square(z)))
    assert abs(np.mean(z)) < 3 / np.sqrt(m)


def _linear_board(seed):
    """The joint fit of a seeded board whose parameters are linear in temperature, 150 poses from -25 to 60 degC."""
    rng = np.random.default_rng(seed)
    truth = random_thermal_imu(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), rng)
    linear = truth.accel_coefs.copy()
    linear[:, 2:] = 0.0
    truth = type(truth)(linear, truth.gyro_coefs)
    temps = np.sort(rng.uniform(-25.0, 60.0, 150))
    return fit_ramp_accel(_poses(truth, temps, rng), np.full((150, 3), SE), temps, "triangular")


def test_order_drops_when_the_truth_is_linear():
    """A board whose parameters are linear in temperature: the top powers are found zero (their joint Wald test
    passes with probability 0.95 at each step), so order 1 is chosen on most of 20 boards (expected 18)."""
    orders = [int(_linear_board(2000 + seed).orders.max()) for seed in range(20)]
    assert sum(o == 1 for o in orders) >= 14, orders


@pytest.fixture(scope="module")
def linear_boards():
    """300 seeded boards whose parameters are linear in temperature (150 poses each): their fits."""
    return [_linear_board(3000 + seed) for seed in range(300)]


def test_the_wald_rule_keeps_a_zero_cubic_at_its_size(linear_boards):
    """The true cubic coefficients are zero, so the joint Wald test of the 9 of them (chi-square, 9 dof) keeps
    the cubic with probability DROP_P = 0.05: the count over 300 boards is Binomial(300, 0.05) (scipy), each
    tail beyond it at least 1e-3. A test with too many dof or a laxer threshold keeps it far less or more often."""
    kept = sum(int(f.orders.max()) == 3 for f in linear_boards)
    assert binom.cdf(kept, 300, 0.05) > 1e-3 and binom.sf(kept - 1, 300, 0.05) > 1e-3, kept


def test_the_fit_chi2_is_that_of_the_pose_noise(linear_boards):
    """Residuals weighted by each pose's noise (the simulated SE) against a truth the fit can follow: the chi2
    summed over the boards is chi-square with the summed dof, so its ratio to them is within
    1 +- 3 sqrt(2 / dof) (a pose's variance 10 % off moves it by 0.1, 14 times that band)."""
    chi2 = sum(f.quality.chi2 for f in linear_boards)
    dof = sum(f.quality.dof for f in linear_boards)
    assert abs(chi2 / dof - 1) < 3 * np.sqrt(2 / dof), chi2 / dof


def test_few_poses_lower_the_order():
    """20 poses leave spare equations for order 0 only (9 x 2 + 3 > 20); 11 poses for nothing: refused."""
    rng = np.random.default_rng(7)
    truth = random_thermal_imu(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), rng)
    temps = np.linspace(-25.0, 60.0, 20)
    fit = fit_ramp_accel(_poses(truth, temps, rng), np.full((20, 3), SE), temps, "triangular")
    assert fit.orders.max() == 0 and fit.coefs.shape == (9, 1)
    with pytest.raises(InputError, match="needs 12 poses or more"):
        fit_ramp_accel(_poses(truth, temps[:11], rng), np.full((11, 3), SE), temps[:11], "triangular")


def test_simulated_ramp_follows_the_truth():
    """Each true still span of a ramp log: |A(T)(u - o(T))| = g from the truth's cubics at the span's true mean
    temperature, within the pose's noise (RMS z within 1 +- 3/sqrt(2m)); the temperature column is the ramp."""
    rng = np.random.default_rng(5)
    truth = random_thermal_imu(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), rng)
    rec, facts = ramp_session(truth, 60.0, -25.0, 20.0, gyro_kw={"noise_std": 0.005}, sample_rate=50.0,
                              accel_noise_std=0.02, rng=rng)
    assert facts["branch"] == "cooling" and facts["duration_s"] == pytest.approx(85 / 20 * 60)
    assert np.allclose(rec.temp, 60.0 - 85.0 * rec.t / facts["duration_s"], atol=1e-9)
    z = []
    for a, b in facts["still"][1:]:
        temp = float(rec.temp[a:b].mean())
        p, _ = truth.params(temp, cooling=True)
        f = p[:9].reshape(3, 3) @ (rec.accel[a:b].mean(axis=0) - p[9:])
        z.append((np.linalg.norm(f) - G) / (0.02 / np.sqrt(b - a)))
    m = len(z)
    assert m > 30
    assert abs(np.sqrt(np.mean(np.square(z))) - 1) < 3 / np.sqrt(2 * m)


def test_ramp_and_plateaus_are_told_apart():
    """A ramp log is a ramp; a plateau chamber log (unrecorded soaks, constant temperature at each point) is not."""
    rng = np.random.default_rng(6)
    truth = random_thermal_imu(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), rng)
    ramp, _ = ramp_session(truth, -25.0, 60.0, 10.0, gyro_kw={"noise_std": 0.005}, sample_rate=20.0, rng=rng)
    assert is_ramp(ramp.t, ramp.temp)
    flat, _ = chamber_session(truth, [-25.0, 0.0, 25.0, 50.0], gyro_kw={"noise_std": 0.005}, poses=12,
                              sample_rate=20.0, temp_noise=0.1, rng=rng)
    breaks = list(np.flatnonzero(np.diff(flat.t) > 1.0) + 1)
    assert not is_ramp(flat.t, flat.temp, breaks)


@pytest.fixture(scope="module")
def ramp_cli(tmp_path_factory):
    """``simulate --temp-ramp`` (10 degC/min) and ``gyrocal imu`` on it: directory, output, truth, section."""
    d = tmp_path_factory.mktemp("ramp")
    log = d / "ramp.csv"
    code, _, err = invoke("simulate", "--protocol", "multi-position", "--temp-ramp", "-25:60:10", "--sample-rate",
                          "50", "--noise", "0.005", "--temp-noise", "0.05", "--seed", "3", "-o", log)
    assert code == 0, err
    code, out, err = invoke("imu", log, "--units", "deg/s", "--accel-units", "m/s^2", "-o", d / "cal.json")
    assert code == 0, err
    truth = json.loads(log.with_suffix(".truth.json").read_text())["imu_thermal"]
    return d, out + err, truth, load(d / "cal.json").accelerometer["thermal"]


def test_cli_ramp_says_so_and_writes_the_section(ramp_cli):
    """The output says the log was a ramp and flags poses whose temperature moves over 0.5 degC (10 degC/min,
    3 s +- 25 % poses: 0.4 to 0.6 degC); the section has the ramp and points spanning the poses' range."""
    _, text, truth, section = ramp_cli
    assert "a temperature ramp (" in text and "drift by more than 0.5 degC" in text
    assert section["method"].startswith("temperature ramp")
    temps = section["accelerometer"]["points"]["temperature"]
    assert min(temps) < -24.0 and max(temps) > 59.0
    assert truth["ramp"]["rate_degC_per_min"] == 10.0
    assert section["ramp"]["rate_degC_per_min"] == pytest.approx(10.0, rel=0.05)


def test_cli_ramp_accelerometer_against_the_sidecar(ramp_cli):
    """The smooth model's 9 parameters at 7 temperatures across the ramp: every |z| < 4.5 against the sidecar's
    cubics (63 z-scores; a normal one exceeds 4.5 with probability 7e-6)."""
    _, _, truth, section = ramp_cli
    temps = np.linspace(-24.0, 59.0, 7)
    value, sigma = smooth_at(section["accelerometer"], temps)
    z = (value - truth_params(truth, "accelerometer", temps)[:, _LOWER]) / sigma
    assert np.abs(z).max() < 4.5, z


def test_cli_ramp_apply_and_export(ramp_cli):
    """``apply`` and ``export --format c-header`` take the ramp's file as any chamber file."""
    d, _, _, _ = ramp_cli
    code, _, err = invoke("apply", d / "cal.json", d / "ramp.csv", "-o", d / "corrected.csv")
    assert code == 0, err
    code, _, err = invoke("export", d / "cal.json", "--format", "c-header", "-o", d / "imu.h")
    assert code == 0, err
    assert "GYROCAL_IMU_THERMAL" in (d / "imu.h").read_text().upper()


@pytest.mark.parametrize("flags, words", [
    (["--temp-ramp", "-25:60:x"], "LOW:HIGH or LOW:HIGH:RATE"),
    (["--temp-ramp", "25"], "LOW:HIGH or LOW:HIGH:RATE"),
    (["--temp-ramp", "-25:60:0"], "RATE must be > 0"),
    (["--temp-ramp", "-25:60", "--temp-points", "0,25,50"], "give one"),
    (["--temp-ramp", "-25:60", "--temp-soak", "60"], "has none"),
    (["--temp-ramp", "20:20.5"], "1 degC or more apart"),
    (["--temp-ramp", "-25:60", "--device"], "not used by --device"),
])
def test_cli_ramp_refusals(tmp_path, flags, words):
    """Bad --temp-ramp input: one line, exit 2."""
    assert words in refused("simulate", "--protocol", "multi-position", *flags, "-o", tmp_path / "r.csv")


def test_a_lagging_sensor_on_a_ramp_is_moved_back_to_the_die():
    """Reference: a first-order lag solved by hand for a linear ramp. The die warms at r degC/s; a sensor with time
    constant tau settles to T_die - r tau (y' = (T_die - y) / tau), plus seeded reading noise of 0.02 degC.
    die_temperature must give the die back within the noise the 60 s slope carries (its standard error,
    sigma sqrt(12 / (n w^2)) per degC/s, times tau, after the settling of 10 tau)."""
    from gyrocal.imu.thermal_limits import die_temperature

    rng = np.random.default_rng(5)
    fs, rate, tau, sigma = 10.0, 5.0 / 60.0, 30.0, 0.02
    t = np.arange(0, 3600, 1 / fs)
    die = -25.0 + rate * t
    sensor = die - rate * tau * (1 - np.exp(-t / tau)) + sigma * rng.standard_normal(len(t))
    moved = die_temperature(t, sensor, tau)
    settled = (t > 10 * tau) & (t < t[-1] - 30)
    slope_sd = sigma * math.sqrt(12.0 / (60 * fs * 60.0**2))
    bound = 5 * math.hypot(sigma, tau * slope_sd)
    assert np.max(np.abs(moved[settled] - die[settled])) < bound
    assert np.max(np.abs(sensor[settled] - die[settled])) > 10 * bound  # the lag itself is far larger
