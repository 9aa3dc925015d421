"""The calibration's fast paths give what the straightforward code gave, to rounding.

Reference: ``tests/naive_selfcheck.py``, the implementations the fast paths replaced (window by window,
whole-log arrays), run on the same seeded data. Tolerances: sums taken in another order differ by a few
units in the last place, relative 1e-15 per sum, so window reductions are held to 1e-12; the time base's
decisions (gaps, lost samples, late deliveries, the clock) must be identical. Where the fast path uses what
is exact on a regular clock (even trapezoid weights, block centres a whole step apart) the straightforward
path used rebuilt clock times whose steps carry their own rounding (relative 1e-10 at 1000 s): window means
then agree to ~1e-12 and a fit's residuals, a difference of such means over a noise sigma of 6e-4 of them,
to ~1e-8 noise sigmas; those comparisons allow 1e-9 relative and 1e-6 sigma.
"""

import math

import naive_selfcheck as naive
import numpy as np
import pytest

from gyrocal.longrun import fit_level, fit_levels, newey_west_var
from gyrocal.models import ScaleBias
from gyrocal.moments import window_moments
from gyrocal.observations import observe
from gyrocal.pipeline import _spread_blocks, calibrate
from gyrocal.sections import FitQuality
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo
from gyrocal.simulation.timestamps import ReceiveClock, with_time_defects
from gyrocal.timebase import analyse_time

RECEIVE = ReceiveClock(read_time=0.0003, jitter=0.0002)


@pytest.fixture(scope="module")
def session():
    """Two rounds of the servo method's six turns at 1 kHz: ramps, 5 % speed ripple, 5 deg misalignment."""
    gyro = VirtualGyro(ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076]), noise_std=0.035)
    protocol = ServoProtocol(turns=PAPER_TURNS * 2, misalignment_deg=5.0, ripple=0.05)
    rec, _ = simulate_servo(gyro, protocol, sample_rate=1000.0, rng=np.random.default_rng(11))
    return rec


def _stamps(session, kind, rng):
    if kind == "sensor":
        return session
    if kind == "receive":
        return with_time_defects(session, rng, clock=RECEIVE)[0]
    if kind == "late":
        return with_time_defects(session, rng, clock=ReceiveClock(read_time=0.0003, jitter=0.0002, late_per_minute=6))[0]
    if kind == "gaps":
        return with_time_defects(session, rng, clock=RECEIVE, gaps=4, gap_length=0.17)[0]
    return with_time_defects(session, rng, gaps=3, gap_length=0.05)[0]  # sensor stamps with gaps


@pytest.mark.parametrize("kind", ["sensor", "receive", "late", "gaps", "sensor gaps"])
def test_time_base_is_the_same(session, kind, rng):
    """Every fact and decision of the time base, exactly (stamps as logged and rounded to microseconds)."""
    t = _stamps(session, kind, rng).t
    for stamps in (t, np.round(t, 6)):
        assert analyse_time(stamps) == naive.analyse_time(stamps)
    if kind in ("gaps", "sensor gaps"):
        assert analyse_time(t).gaps, "the gaps were meant to be found"


def test_time_base_of_short_logs_and_gaps_near_the_ends(rng):
    """Logs shorter than a block of the envelope, and gaps within a window's length of either end."""
    for n in (2, 3, 40, 130, 1200):
        t = np.cumsum(rng.uniform(0.5, 1.5, n)) * 1e-3
        assert analyse_time(t) == naive.analyse_time(t)
    t = np.arange(5000) * 1e-3 + rng.uniform(0, 3e-4, 5000)
    for at in (3, 60, 4950, 4990):
        gappy = np.concatenate([t[:at], t[at:] + 0.02])
        assert analyse_time(gappy) == naive.analyse_time(gappy)


@pytest.mark.parametrize("order", ["C", "F"])
def test_window_moments_are_the_window_by_window_reductions(order, rng):
    """Sorted, adjacent, overlapping, two-sample and stretch-long windows, with and without sample times."""
    x = np.asarray(rng.normal(0.3, 1.0, (400_000, 3)), order=order)
    t = np.cumsum(rng.uniform(0.2e-3, 1.8e-3, len(x)))
    starts = np.array([0, 10, 12, 500, 2000, 2600, 9000, 150_000, 399_000])
    stops = np.array([10, 12, 400, 2000, 2600, 9000, 150_000, 399_000, 400_000])  # the last ends the log
    for s, e in ((starts, stops), (starts[[0, 3, 2]], stops[[0, 4, 2]])):  # the second set overlaps, unsorted
        for times in (None, t):
            got = window_moments(x, s, e, times)
            for j, (a, b) in enumerate(zip(s, e)):
                ref = naive.observe(x[a:b], 1000.0, "static", t=None if times is None else times[a:b])
                np.testing.assert_allclose(got.mean[j], ref.mean, rtol=1e-12, atol=1e-15)
                np.testing.assert_allclose(got.mean_sq[j], ref.mean_sq, rtol=1e-12)
                np.testing.assert_allclose(got.noise_var[j], ref.noise_var, rtol=1e-12)
                assert got.duration[j] == pytest.approx(ref.duration if times is not None else b - a, rel=1e-12)


def test_observe_is_the_straightforward_reduction(rng):
    m = rng.normal(1.0, 0.05, (3000, 3))
    t = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, 3000))
    for kw in ({"kind": "static"}, {"kind": "speed", "speed": 1.2}, {"kind": "angle", "angle": 2.0, "t": t}):
        new, old = observe(m, 1000.0, **kw), naive.observe(m, 1000.0, **kw)
        for field in ("mean", "mean_sq", "noise_var"):
            np.testing.assert_allclose(getattr(new, field), getattr(old, field), rtol=1e-13)
        assert (new.duration, new.rate, new.count) == pytest.approx((old.duration, old.rate, old.count), rel=1e-13)


def test_long_run_variance_and_plateau_fits(rng):
    """Newey-West on rows; plateaus on a regular clock sharing one design; irregular ones on their own."""
    x = np.cumsum(rng.normal(size=(20_000, 3)), axis=0) * 0.01 + rng.normal(size=(20_000, 3))
    np.testing.assert_allclose(newey_west_var(x), naive.newey_west_var(x), rtol=1e-12)
    lines = [0.0125, 0.031]
    xs = [rng.normal(1.0, 0.1, (n, 3)) for n in (800, 1050, 1050, 1200)]
    # a regular clock as rebuilt (whole steps up to rounding), and one with jitter of a tenth of a step
    ts = [np.arange(len(v)) * (1 + 1e-15) for v in xs[:3]] + [np.arange(1200) + rng.uniform(-0.1, 0.1, 1200)]
    for (level, factor, resid), v, tt in zip(fit_levels(xs, ts, lines), xs, ts):
        ref = naive.fit_level(v, tt, lines)
        np.testing.assert_allclose(level, ref[0], rtol=1e-9)
        assert factor == pytest.approx(ref[1], rel=1e-9)
        np.testing.assert_allclose(resid, ref[2], atol=1e-9)
    assert fit_levels(xs, ts, [])[0][1] == fit_level(xs[0], ts[0], [])[1] == 1 / 800


def test_sections_and_spread_blocks_are_unchanged(rng):
    doc = {"chi2": 3.0, "dof": 2, "residuals": [[0.5], [1.0, -2.0, 0.25]], "labels": ["+x", "static"],
           "warnings": [], "disagree": [1]}
    assert dict(FitQuality(doc)) == dict(naive._freeze(doc, "fit"))
    with pytest.raises(ValueError, match=r"fit.residuals\[1\]\[2\] must be finite"):
        FitQuality({**doc, "residuals": [[0.5], [1.0, -2.0, math.nan]]})
    g = rng.normal(size=(300_000, 3))
    for arr in (g, np.asfortranarray(g)):
        np.testing.assert_array_equal(_spread_blocks(arr, 1000.0), naive._spread_blocks(arr, 1000.0))


@pytest.mark.parametrize("kind", ["sensor", "receive", "gaps"])
@pytest.mark.parametrize("reference", ["speed", "angle"])
def test_calibration_is_the_same(session, kind, reference, rng, monkeypatch):
    """Whole calibrations, with the self-checks and without, against the straightforward path."""
    rec = _stamps(session, kind, rng)
    ref = {"speed": math.radians(60)} if reference == "speed" else {"angle": 2 * math.pi}
    for kw in ({}, {"checks": False}, {"checks": False, "long_run": False}):
        fast = calibrate(rec, **ref, **kw)
        with monkeypatch.context() as m:
            naive.install(m)
            slow = calibrate(rec, **ref, **kw)
        _same_calibration(fast, slow)


def _same_calibration(fast, slow):
    a, b = fast.calibration, slow.calibration
    assert _close_documents(list(a.windows), list(b.windows))  # an angle's rate: the duration to rounding
    np.testing.assert_allclose(a.model.params, b.model.params, rtol=1e-9)
    scale = np.sqrt(np.outer(np.diag(b.covariance), np.diag(b.covariance)))
    np.testing.assert_allclose(a.covariance / scale, b.covariance / scale, atol=1e-9)
    np.testing.assert_allclose(a.noise_std, b.noise_std, rtol=1e-9)
    assert (fast.warnings, fast.notes, fast.time_base) == (slow.warnings, slow.notes, slow.time_base)
    assert (a.observed is None) == (b.observed is None) and (a.fit is None) == (b.fit is None)
    if a.fit is not None:
        fa, fb = a.fit.to_document(), b.fit.to_document()
        assert (fa["dof"], fa["labels"], fa["covariance_scaled"], fa["disagree"]) == \
            (fb["dof"], fb["labels"], fb["covariance_scaled"], fb["disagree"])
        assert fa["chi2"] == pytest.approx(fb["chi2"], rel=1e-9)
        for za, zb in zip(fa["residuals"], fb["residuals"]):
            np.testing.assert_allclose(za, zb, atol=1e-6)
        assert _close_documents(a.observed.to_document(), b.observed.to_document())


def _close_documents(x, y) -> bool:
    if isinstance(x, dict):
        assert x.keys() == y.keys()
        return all(_close_documents(x[k], y[k]) for k in x)
    if isinstance(x, list):
        return len(x) == len(y) and all(_close_documents(u, v) for u, v in zip(x, y))
    if isinstance(x, float):
        assert x == pytest.approx(y, rel=1e-9)
        return True
    assert x == y
    return True
