"""Deterministic pins of 1-sigma constants and rules (issue 20)."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.stats import chi2, multivariate_normal, norm
from scipy.stats import t as student_t

from gyrocal import units
from gyrocal.checks import excess
from gyrocal.estimators import FirstMoment
from gyrocal.flight.polyfit import choose_orders
from gyrocal.models import ScaleBias
from gyrocal.noise.figures import read_figures
from gyrocal.observations import ObservationSet
from gyrocal.pipeline import calibrate
from gyrocal.recording import Recording
from gyrocal.segmentation import Segmentation
from gyrocal.segmentation.screening import screen_gaps
from gyrocal.segmentation.windows import Window
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import ServoProtocol, simulate_servo
from gyrocal.verify.whitenoise import second_difference_noise


def test_mad_to_sigma_is_gaussian_consistency():
    """Reference: 1 / Phi^-1(3/4) for a Gaussian (scipy), not the code's constant (used by every MAD estimate)."""
    assert units.MAD_TO_SIGMA == pytest.approx(1.0 / norm.ppf(0.75), rel=1e-12)


def test_one_standard_error_rule_picks_lower_order():
    """Reference: the 1-SE rule, threshold best * (1 + 1/sqrt(2K)), worked by hand for K = 8."""
    k = 8
    best = 1.0
    slack = 1.0 / math.sqrt(2 * k)  # 0.25
    cv = np.array([[2.0], [best * (1 + 0.9 * slack)], [best]])  # order 2 slightly better than order 1
    assert int(choose_orders(cv, k)[0]) == 1
    cv[1, 0] = best * (1 + 1.1 * slack)
    assert int(choose_orders(cv, k)[0]) == 2


# --- the extra variances of gyrocal.checks.excess: Student's t factor, the solved tau^2, the evidence threshold ---


@pytest.mark.parametrize("dof", [6.5, 9.0, 30.0])
def test_t_factor_is_students_variance(dof):
    """Reference: the variance of Student's t with nu degrees of freedom (scipy), nu / (nu - 2) above 6."""
    assert excess._t_factor(dof) == pytest.approx(student_t(dof).var(), rel=1e-12)


@pytest.mark.parametrize("dof", [2.5, 4.0, 6.0])
def test_t_factor_is_capped_at_one_and_a_half(dof):
    """Reference: the documented cap, 1.5 at and below nu = 6 (where nu / (nu - 2) would reach 1.5 or more)."""
    assert excess._t_factor(dof) == 1.5


def test_extra_variance_is_the_root_of_chi2_equals_dof():
    """Reference: the Paule-Mandel equation sum r2 / (v + c tau2) = dof solved by scipy's brentq."""
    rng = np.random.default_rng(20)
    v = rng.uniform(0.5, 2.0, 12)
    c = rng.uniform(0.2, 3.0, 12)
    r2 = 4.0 * v * rng.chisquare(1, 12)  # scatter four times the noise: tau2 > 0
    dof = 9.0
    root = brentq(lambda tau2: float(np.sum(r2 / (v + c * tau2))) - dof, 0.0, 1e6, xtol=1e-14)
    assert excess._solve_tau2(r2, v, c, dof) == pytest.approx(root, rel=1e-9)
    assert excess._solve_tau2(0.5 * dof * v / len(v), v, c, dof) == 0.0  # chi2 below dof: no extra variance


@pytest.mark.parametrize("side, flagged", [(0.95, True), (1.05, False)])
def test_a_group_is_widened_only_below_p_one_tenth(side, flagged):
    """Reference: chi2.isf from scipy at p = 0.1 (the evidence threshold), for 10 rows of leverage 0.3: the group
    has 10 x (1 - 0.3) = 7 degrees of freedom (each row's leverage is the share of a parameter it takes)."""
    n, dof = 10, 7.0
    z2 = np.full(n, chi2.isf(0.1 * side, dof) / n)  # the group's chi2 has p = 0.1 x side
    h = np.full(n, 0.3)
    out = excess._beyond_noise(z2, h, n, np.zeros(0, dtype=int))
    assert bool(out[0]) is flagged


# --- the paper's methods: a flagged fit has its covariance scaled by chi2/dof (Birge) ---


def test_flagged_paper_fit_has_covariance_times_chi2_per_dof():
    """Reference: Birge's scaling, covariance x chi2/dof with chi2 summed here from the reported residuals;
    the unchecked fit (checks off) of the same recording gives the covariance before scaling."""
    from gyrocal.checks.noise_terms import EARTH_RATE

    gyro = VirtualGyro(ScaleBias(np.array([1.0069, 0.9960, 0.9955]), np.array([0.0442, -0.0089, 0.0076])),
                       noise_std=0.01)
    protocol = ServoProtocol(turns=("+x", "-x", "+y", "-y", "+z", "-z") * 2, ramp=0.0, unevenness=0.02)
    rec, _ = simulate_servo(gyro, protocol, rng=np.random.default_rng(3))
    for method in ("lm", "algorithm1"):
        run = calibrate(rec, speed=math.radians(60), method=method)
        plain = calibrate(rec, speed=math.radians(60), method=method, checks=False)
        rows = [np.asarray(r) for r in run.quality.residuals]
        chi2_per_dof = sum(float(r @ r) for r in rows) / (sum(len(r) for r in rows) - 6)
        assert run.quality.covariance_scaled and chi2_per_dof > 3  # the uneven plateaus are flagged
        # b's variance carries the Earth's rate too, after the scaling (issue 22)
        earth = np.zeros((6, 6))
        earth[range(3, 6), range(3, 6)] = (EARTH_RATE / run.fit.model.k) ** 2 / 3
        np.testing.assert_allclose(run.fit.covariance, plain.fit.covariance * chi2_per_dof + earth, rtol=1e-8)


# --- the gap bound of gyrocal.segmentation.screening ---


def test_hidden_gap_of_known_bound_gives_the_uniform_variance():
    """Reference: the bound worked by hand, gap length x (|rate after - rate before| / 2 + 3 noise sqrt(1/na + 1/nb)),
    and the variance of a uniform error within it, (bound / angle)^2 / 3."""
    fs, rate, jump = 100.0, 1.0, 0.01  # [Hz], [rad/s]: the turn's rate steps by `jump` across the gap
    n, at, lost = 700, 350, 5
    t = np.arange(n + lost) / fs
    t = np.delete(t, np.arange(at, at + lost))
    w = np.zeros((n, 3))
    w[:, 0] = np.where(np.arange(n) < at, rate, rate + jump)
    rec = Recording(t=t, gyro=w, sample_rate=fs)
    turn = Window(0, n, "rotation", axis="x", sign=1, angle=2 * math.pi, rate=rate)
    seg = Segmentation(windows=(turn,), reference="angle", sample_rate=fs)
    _, rel_var = screen_gaps(seg, rec, rec.time_base(), "angle")
    length = (lost + 1) / fs
    side = round(length * fs)  # samples within one gap length on either side
    noise = math.sqrt(jump**2 / (n - 1) / 2)  # first differences: one step of `jump` among n - 1
    bound = length * (jump / 2 + 3 * noise * math.sqrt(2 / side))
    turned = rate * (at - 1) / fs + (rate + jump) * (n - at - 1) / fs + (2 * rate + jump) / 2 * length
    assert rel_var[(0, n)] == pytest.approx((bound / turned) ** 2 / 3, rel=1e-9)


# --- noise constants derived from their definitions ---


def test_second_difference_mad_variance_from_bivariate_normal():
    """Reference: the asymptotic variance of a median of |d| for a stationary Gaussian series, derived here:
    n var(s_hat) / s^2 = sum over lags of cov(1{|d_0| < q}, 1{|d_k| < q}) / (q f(q))^2, with the lag-1 and lag-2
    correlations -2/3 and 1/6 of normalised second differences on an even grid (probabilities from scipy's
    bivariate normal); checked through the 1-sigma `second_difference_noise` reports."""
    q = norm.ppf(0.75)
    f = 2 * norm.pdf(q)  # density of |d| at its median, unit variance

    def box(rho):  # P(|X| < q, |Y| < q) for a standard bivariate normal with correlation rho
        law = multivariate_normal(mean=[0, 0], cov=[[1, rho], [rho, 1]])
        return law.cdf([q, q]) - 2 * law.cdf([q, -q]) + law.cdf([-q, -q])

    covs = [0.25] + [2 * (box(rho) - 0.25) for rho in (-2 / 3, 1 / 6)]  # lags 0, +-1, +-2
    derived = sum(covs) / (q * f) ** 2
    assert 0.25 / (q * f) ** 2 == pytest.approx(1.36, abs=0.005)  # independent values: the textbook 1.36
    n = 1001
    t = np.arange(n) / 100.0
    w = np.random.default_rng(5).normal(0.0, 0.02, (n, 3))
    est = second_difference_noise(t, w)
    assert np.all(est.std_err**2 * (n - 2) / est.std**2 == pytest.approx(derived, rel=1e-3))


def test_bias_instability_is_the_flat_floor_over_0664():
    """Reference: IEEE Std 952-1997, Annex C: a flicker floor of the Allan deviation sits at
    sqrt(2 ln 2 / pi) B = 0.6643 B; written here from the standard, not read from the code."""
    fs, n = 100.0, 360_000
    taus = np.logspace(-2, 3, 41)
    floor = 1e-4
    adev = floor * np.sqrt(1 + (0.05 / taus) + (taus / 200.0))  # white noise, a floor, a random walk
    i_min = int(np.argmin(adev))
    bias = read_figures(taus, np.tile(adev, (3, 1)), fs, n, level=0.683)[2]
    expected = adev[i_min] / math.sqrt(2 * math.log(2) / math.pi)
    np.testing.assert_allclose(bias.value[:3], expected, rtol=1e-12)


# --- the first-moment covariance with measured window-mean variances: generalised least squares ---


def test_measured_mean_variances_give_the_gls_covariance():
    """Reference: (J^T V^-1 J)^-1 of generalised least squares, with J by central differences of the row model
    written here (turn rows |diag(k)(m + b)| - rate, static rows k_j (m_j + b_j)) and V from the given variances
    of the window means; noise-free means, so the fit sits at the truth and its weights are exact."""
    k, b = np.array([1.01, 0.99, 1.002]), np.array([0.02, -0.01, 0.005])
    rate = 1.0
    axes = np.repeat(np.eye(3), 2, axis=0) * np.tile([1.0, -1.0], 3)[:, None]  # +-x, +-y, +-z
    means = np.vstack([axes * rate / k - b, -b, -b])  # six turns, then two static windows
    static = np.array([False] * 6 + [True] * 2)
    count = np.full(8, 2000.0)
    mean_var = np.random.default_rng(8).uniform(0.5e-8, 2e-8, (8, 3))  # [rad^2/s^2], one per window and axis
    noise_var = np.full((8, 3), 1e-4)
    obs = ObservationSet(means[None], (means**2 + noise_var)[None], noise_var[None],
                         np.where(static, 0.0, rate)[None], count, count / 200.0, static, mean_var=mean_var[None])
    fit = FirstMoment().fit(obs)
    np.testing.assert_allclose(fit.model.params, np.concatenate([k, b]), atol=1e-12)

    def rows(p):
        kk, bb = p[:3], p[3:]
        turns = [np.linalg.norm(kk * (m + bb)) - rate for m in means[:6]]
        return np.concatenate([turns, *[kk * (m + bb) for m in means[6:]]])

    p = np.concatenate([k, b])
    h = 1e-6
    J = np.stack([(rows(p + h * e) - rows(p - h * e)) / (2 * h) for e in np.eye(6)], axis=1)
    u = [k * (m + b) / np.linalg.norm(k * (m + b)) for m in means[:6]]
    var = np.concatenate([[np.sum((k * u[i]) ** 2 * mean_var[i]) for i in range(6)],
                          *[k**2 * mean_var[i] for i in (6, 7)]])
    gls = np.linalg.inv(J.T @ (J / var[:, None]))
    np.testing.assert_allclose(fit.covariance, gls, rtol=1e-6, atol=1e-9 * np.diag(gls).min())


@pytest.mark.parametrize("p, flagged", [(0.5e-3, True), (2e-3, False)])
def test_a_fit_is_flagged_below_p_one_in_a_thousand(p, flagged):
    """Reference: chi2.isf from scipy: twenty one-row windows whose chi2 for 14 dof (6 parameters) has p-value `p`;
    the paper's methods (no groups) are flagged, and their covariance scaled, below p = 1e-3."""
    from gyrocal.checks.quality import assess_fit

    total = chi2.isf(p, 20 - 6)
    residuals = [np.array([math.sqrt(total / 20)])] * 20
    quality = assess_fit(residuals, [f"w{i}" for i in range(20)], 6, what="the turns")
    assert quality.p_value == pytest.approx(p, rel=1e-9)
    assert quality.covariance_scaled is flagged and bool(quality.warnings) is flagged


@pytest.mark.parametrize("a, moved", [(0.48, False), (0.6, True)])
def test_a_step_between_neighbouring_blocks_is_judged_against_sqrt2_sigma(a, moved):
    """Reference: the difference of two block means of the same noise has sqrt(2) times one mean's sigma.
    Samples alternate +-1 (each 1 s block: mean 0, spread 1, so a mean's sigma is 1 / sqrt(100) = 0.1 exactly);
    two neighbouring blocks move by +a and -a: |dev| = a stays under 8 sigma, and their step 2a is judged against
    8 sqrt(2) x 0.1 = 1.13 (0.96: still, 1.2: a motion)."""
    from gyrocal.segmentation.stillness import find_motion

    x = np.tile(np.where(np.arange(100) % 2, -1.0, 1.0), 200)[:, None] * np.ones(3)
    x[5000:5100] += a
    x[5100:5200] -= a
    assert bool(find_motion(x, 100.0).moving.any()) is moved


def test_rate_random_walk_is_read_on_the_plus_half_line():
    """Reference: IEEE Std 952-1997, Annex C: a rate random walk K gives an Allan variance K^2 tau / 3, so the
    +1/2 line reads K = sigma(tau) sqrt(3 / tau); on a curve of white noise plus a random walk (no floor),
    at long tau the white part is 3e-4 of it."""
    fs, n = 100.0, 10_000_000
    taus = np.logspace(-2, 4, 61)
    white, walk = 1e-3, 1e-4
    adev = np.sqrt(white**2 / taus + walk**2 * taus / 3)
    rrw = read_figures(taus, np.tile(adev, (3, 1)), fs, n, level=0.683)[3]
    np.testing.assert_allclose(rrw.value[:3], walk, rtol=2e-3)


def test_a_temperature_point_has_the_ols_standard_errors_with_n_minus_4_dof():
    """Reference: ordinary least squares per output axis, rate = K w + B (4 parameters), standard errors
    sqrt(diag((X'X)^-1) RSS / (n - 4)) computed here with numpy's lstsq (the full-temperature-range method, eq. 19)."""
    from gyrocal.thermal.fit import fit_point

    rng = np.random.default_rng(19)
    n = 9
    ref = rng.uniform(-1.0, 1.0, (n, 3))
    means = ref @ np.array([[1.01, 0.002, 0.0], [0.0, 0.99, 0.003], [0.001, 0.0, 1.0]]).T + 0.01
    means = means + rng.normal(0.0, 1e-3, means.shape)
    point = fit_point(ref, means, np.full((n, 3), 1e-6), np.full(n, 100.0))
    X = np.column_stack([ref, np.ones(n)])
    _, rss, _, _ = np.linalg.lstsq(X, means, rcond=None)
    se = np.sqrt(np.outer(np.diag(np.linalg.inv(X.T @ X)), rss / (n - 4)))  # (4 parameters, 3 axes)
    np.testing.assert_allclose(np.sort(point.std.ravel()), np.sort(se.ravel()), rtol=1e-9)


def test_quiet_noise_pools_unbiased_block_variances():
    """Reference: the unbiased sample variance worked by hand: blocks of 8 samples alternating +1, -1 have
    sum of squares 8 over 8 - 1 degrees of freedom, so the pooled noise is sqrt(8 / 7)."""
    from gyrocal.observations.observed import quiet_noise

    x = np.tile([1.0, -1.0], 4 * 20)[:, None] * np.ones(3)  # 20 blocks of 8 at 16 Hz (half-second blocks)
    np.testing.assert_allclose(quiet_noise(x, 16.0), math.sqrt(8 / 7), rtol=1e-12)


@pytest.mark.parametrize("above, order", [(0.65, 1), (0.8, 2)])
def test_the_smooth_model_takes_the_lowest_order_within_one_standard_error(monkeypatch, above, order):
    """Reference: the one-standard-error rule with the LOTO RMS's relative uncertainty 1/sqrt(2n), n = 8
    temperatures: order 1 at best x (1 + 0.65/sqrt(8)) is taken over a better order 2, at (1 + 0.8/sqrt(8)) not."""
    from gyrocal.thermal import smooth

    n = 8
    best = 1.0
    rms = np.array([[5.0], [best * (1 + above / math.sqrt(n))], [best], [best * 1.01]])
    monkeypatch.setattr(smooth, "loto_errors", lambda t, y, top: rms[: top + 1])
    model = smooth.fit_smooth(np.linspace(-40.0, 85.0, n), np.linspace(0.0, 1.0, n)[:, None], max_order=3)
    assert int(model.orders[0]) == order


def test_hysteresis_chi2_and_half_width_by_hand():
    """Reference: one point seen heating (20 degC), then 40, then cooling back to 20; two parameters whose
    branch difference d = (0.5, -0.1) has covariance C = [[0.004, 0.0005], [0.0005, 0.004]] (the two plateaus'
    covariances summed). By hand: chi2 = d^T C^-1 d = (0.004 * 0.25 - 2 * 0.0005 * (-0.05) + 0.004 * 0.01) /
    (0.004^2 - 0.0005^2), 2 dof, p = exp(-chi2 / 2); flagged, so the added variance is the half-width's,
    (d_j^2 - C_jj) / 4."""
    from gyrocal.imu.plateaus import Plateau
    from gyrocal.imu.thermal_limits import hysteresis

    plateaus = [Plateau(0, 10, 20.0, 0.0), Plateau(10, 20, 40.0, 0.0), Plateau(20, 30, 20.0, 0.0)]
    params = [np.array([1.0, 2.0]), np.array([1.2, 2.2]), np.array([1.5, 1.9])]
    covs = [np.array([[0.002, 0.001], [0.001, 0.003]]), np.eye(2) * 0.01,
            np.array([[0.002, -0.0005], [-0.0005, 0.001]])]
    h = hysteresis([[0, 2], [1]], plateaus, params, covs, ("o_x", "o_y"))
    want = (0.004 * 0.25 - 2 * 0.0005 * (-0.05) + 0.004 * 0.01) / (0.004**2 - 0.0005**2)
    assert h.dof == 2 and h.chi2 == pytest.approx(want, rel=1e-9)
    assert h.p_value == pytest.approx(math.exp(-want / 2), rel=1e-6) and h.flagged
    np.testing.assert_allclose(h.extra_variance, [(0.25 - 0.004) / 4, (0.01 - 0.004) / 4], rtol=1e-9)
    np.testing.assert_allclose(h.difference, [0.5, -0.1], rtol=1e-9)


def test_mid_branch_join_by_hand():
    """Reference: the mean of two independent branch values, (p_h + p_c) / 2, has covariance (C_h + C_c) / 4;
    a point seen heating only moves by half the measured difference, its variance plus std^2 / 4."""
    from gyrocal.imu.thermal_limits import Hysteresis, Limits

    h = Hysteresis((20.0,), ("o_x", "o_y"), np.array([0.4, -0.2]), np.array([0.02, 0.04]), 50.0, 2, 1e-11,
                   np.array([0.04, 0.01]))
    lim = Limits(accelerometer=h, gyro=None, drifts=())
    ch, cc = np.array([[0.002, 0.001], [0.001, 0.003]]), np.array([[0.004, 0.0], [0.0, 0.001]])
    value, cov = lim.join("accelerometer", [np.array([1.0, 2.0]), np.array([1.4, 1.8])], [ch, cc],
                          ["heating", "cooling"])
    np.testing.assert_allclose(value, [1.2, 1.9], rtol=1e-12)
    np.testing.assert_allclose(cov, [[0.0015, 0.00025], [0.00025, 0.001]], rtol=1e-12)
    value, cov = lim.join("accelerometer", [np.array([1.0, 2.0])], [ch], ["heating"])
    np.testing.assert_allclose(value, [1.2, 1.9], rtol=1e-12)
    np.testing.assert_allclose(cov, [[0.002 + 0.0001, 0.001], [0.001, 0.003 + 0.0004]], rtol=1e-12)


def test_a_misfitting_top_order_is_birge_scaled_by_chi2_over_dof():
    """Reference: weighted least squares by hand (numpy lstsq) of a quadratic, the highest order 4 points allow,
    through a cubic that it cannot follow: coefficients' covariance (X^T W X)^-1 times chi2 / dof (1 dof)."""
    from gyrocal.imu.thermal_model import temperature_model

    nodes = np.array([-20.0, 0.0, 20.0, 40.0])
    values = (1.0 + 0.01 * nodes + 2e-6 * nodes**3)[:, None]
    var = np.array([1e-6, 4e-6, 1e-6, 2e-6])
    model = temperature_model(("k",), nodes, values, var[:, None, None], max_order=3)
    x = np.vander((nodes - model.smooth.centre) / model.smooth.scale, 3, increasing=True)
    w = 1.0 / np.sqrt(var)
    beta, *_ = np.linalg.lstsq(x * w[:, None], values[:, 0] * w, rcond=None)
    chi2_ = float(np.sum(((values[:, 0] - x @ beta) * w) ** 2))
    assert chi2.sf(chi2_, 1) < 1e-3  # the misfit is flagged
    want = np.linalg.inv((x * w[:, None] ** 2).T @ x) * chi2_
    assert model.smooth.orders[0] == 2 and model.misfit_scale[0] == pytest.approx(chi2_, rel=1e-6)
    np.testing.assert_allclose(model.smooth_covariance[:3, :3], want, rtol=1e-6)
