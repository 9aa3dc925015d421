"""The calibration's fast paths give what the straightforward code gives, to rounding.

Reference: ``tests/naive_selfcheck.py`` (window by window, whole-log arrays, candidate gaps judged one by
one) on ``tests/naive_reference.py`` (plain code written from the documented behaviour: medians and
quantiles by sorting, least squares on designs built column by column, a line by centred sums). Neither calls a
function of gyrocal.observations.longrun, gyrocal.recording.timebase or gyrocal.recording.timegaps, so a slip in any of them shows here;
run on the same seeded data. Tolerances: sums taken in another order differ by a few units in the last
place, relative 1e-15 per sum, so window reductions are held to 1e-12; the time base's decisions (gaps,
lost samples, late deliveries, a regular clock) must be identical, and its times (a difference, median,
spread or line fit of stamps each rounded to eps |t|) agree within 4 eps max|t|. Where the fast path uses
what is exact on a regular clock (even trapezoid weights, block centres a whole step apart) the
straightforward path used rebuilt clock times whose steps carry their own rounding (relative 1e-10 at
1000 s): window means then agree to ~1e-12 and a fit's residuals, a difference of such means over a noise
sigma of 6e-4 of them, to ~1e-8 noise sigmas; those comparisons allow 1e-9 relative and 1e-6 sigma.
"""

import dataclasses
import math

import naive_reference as ref
import naive_selfcheck as naive
import numpy as np
import pytest

from gyrocal.models import ScaleBias
from gyrocal.observations import observe
from gyrocal.observations.longrun import block_means, find_lines, fit_level, fit_levels, newey_west_var, span_variance
from gyrocal.observations.moments import window_moments
from gyrocal.pipeline import _spread_blocks, calibrate
from gyrocal.recording.timebase import analyse_time
from gyrocal.results.sections import FitQuality
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo
from gyrocal.simulation.timestamps import ReceiveClock, with_time_defects

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
    """Every decision of the time base exactly, its times to rounding (stamps as logged and rounded to microseconds)."""
    t = _stamps(session, kind, rng).t
    for stamps in (t, np.round(t, 6)):
        _same_time_base(_facts(analyse_time(stamps)), naive.time_facts(stamps), stamps)
    if kind in ("gaps", "sensor gaps"):
        assert analyse_time(t).gaps, "the gaps were meant to be found"


def test_time_base_of_short_logs_and_gaps_near_the_ends(rng):
    """Logs shorter than a block of the envelope, and gaps within a window's length of either end."""
    for n in (2, 3, 40, 130, 1200):
        t = np.cumsum(rng.uniform(0.5, 1.5, n)) * 1e-3
        _same_time_base(_facts(analyse_time(t)), naive.time_facts(t), t)
    t = np.arange(5000) * 1e-3 + rng.uniform(0, 3e-4, 5000)
    for at in (3, 60, 4950, 4990):
        gappy = np.concatenate([t[:at], t[at:] + 0.02])
        # near the start a gap (its decision compared); in the envelope's last block, a late delivery
        assert (len(analyse_time(gappy).gaps), analyse_time(gappy).delayed) == ((1, 0) if at < 100 else (0, 1))
        _same_time_base(_facts(analyse_time(gappy)), naive.time_facts(gappy), gappy)


def _delivered(n: int, period: float, rng, *, pattern=(1.0,), late_step=None, gap_step=None) -> np.ndarray:
    """A sensor clock delivered in steps repeating `pattern` [periods, mean 1] with 0.1 % of a period of
    jitter, and at sample n / 2 either a late delivery (a step `late_step` long, the samples it held back
    caught up at once: nothing lost) or a gap of one sample spread over three steps (the two samples before
    it delayed), the first and last `gap_step` periods, the middle one ~1."""
    t = np.concatenate([[0.0], np.cumsum(np.resize(pattern, n - 1))]) * period + rng.uniform(0, 1e-3 * period, n)
    j = n // 2
    if late_step is not None:
        end = t[j - 1] + late_step
        held = int(np.searchsorted(t, end + 1e-3 * period)) - j  # the samples due before the late one arrives
        t[j:j + held] = end + 1e-6 * period * np.arange(held)
    if gap_step is not None:
        t[j:] += period
        t[j - 2] += (gap_step - 1) * period
        t[j - 1] += (2 - gap_step) * period
    return t


#: Packets 0.55 and 1.75 periods apart (the packets' step, their median, 0.55: 3 periods is then the limit alone),
#: eight to a cycle so that every 64-step block of the nominal period holds whole cycles.
_BURSTS = (0.55, 1.75, 0.55, 0.55, 1.75, 0.55, 0.55, 1.75)


@pytest.mark.parametrize("case", ["late 1 kHz", "late 100 Hz", "late 100 Hz bursts", "gap step"])
def test_time_base_either_side_of_its_documented_limits(case, rng):
    """Steps 0.5 % either side of the late-delivery limit, max(3 periods, packet step + max(2 periods, 10 ms))
    (at 1 kHz the 10 ms decide, at 100 Hz the periods), and a one-sample gap's steps either side of 1.5 periods
    (shorter ones are not examined): the reference's restated constants decide as the library's, and as the
    documentation says."""
    period = 1e-2 if "100 Hz" in case else 1e-3
    pattern = _BURSTS if "bursts" in case else (1.0,)
    packet = float(np.median([p for p in pattern if p > 0.5])) * period
    limit = max(3 * period, packet + max(2 * period, 0.01))
    for side in (1.005, 0.995):
        if case == "gap step":
            t, want = _delivered(3000, period, rng, gap_step=1.5 * side), ((1, 0) if side > 1 else (0, 0))
        else:
            t = _delivered(3000, period, rng, pattern=pattern, late_step=limit * side)
            want = (0, 1) if side > 1 else (0, 0)
        fast = analyse_time(t)
        assert (len(fast.gaps), fast.delayed) == want
        _same_time_base(_facts(fast), naive.time_facts(t), t)


def test_time_base_gap_judged_on_the_tenth_quantile(rng):
    """A gap of three samples ten samples from the start, after the rest of those ten delayed by 0.8 period: the
    level before it is the tenth quantile of the ten (the second lowest). With two on time, all three lost
    samples are counted there; with one, that one is passed over, two are counted there, and the step after the
    one on time (1.8 periods, judged after the longer one) takes the third."""
    period = 1e-3
    for on_time, gaps in ((2, [(10, 3)]), (1, [(1, 1), (10, 2)])):
        t = np.arange(5000) * period + rng.uniform(0, 1e-3 * period, 5000)
        t[on_time:10] += 0.8 * period
        t[10:] += 3 * period
        fast = analyse_time(t)
        assert [(g.index, g.lost) for g in fast.gaps] == gaps
        _same_time_base(_facts(fast), naive.time_facts(t), t)


def test_time_base_regular_clock_either_side_of_half_a_period(rng):
    """Delays rising as a tent across the log (no gap, no long step), of heights 0.5 % either side of the one
    at which the reference's envelope stops fitting a line within half a period: a regular clock, then not."""
    period, n = 1e-3, 6000
    jitter = rng.uniform(0, 1e-3 * period, n)

    def stamps(height: float) -> np.ndarray:
        return np.arange(n) * period + jitter + height * period * (1 - np.abs(2 * np.arange(n) / (n - 1) - 1))

    lo, hi = 0.3, 0.7
    for _ in range(30):  # bisection for the height where the reference's decision turns
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if naive.time_facts(stamps(mid))["regular_clock"] else (lo, mid)
    for side, regular in ((1.005, False), (0.995, True)):
        t = stamps(hi * side)
        fast = analyse_time(t)
        assert (fast.regular_clock, fast.gaps, fast.delayed) == (regular, (), 0)
        _same_time_base(_facts(fast), naive.time_facts(t), t)


def test_ripple_lines_span_variance_and_block_means(rng):
    """The library's line search, span variance and block means against the plain loops of
    ``tests/naive_reference.py`` (its own taper, padding and bins; span sums and block means of its own)."""
    n = 2400
    k = np.arange(n)
    y = 0.05 * np.sin(2 * np.pi * 0.0125 * k + 0.3) + 0.02 * np.cos(2 * np.pi * 0.031 * k) + rng.normal(0, 0.03, n)
    got, want = find_lines(y), ref.find_lines(y)
    assert len(want) == 2
    # bins are 1 / (4 n) = 1e-4 apart; the two spectra agree to 1e-15 of their peak, the lines far closer than this
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    # white noise (b only), with a bounded vibration (a and b), differenced (a only)
    residuals = []
    for m in (800, 1000, 1300):
        e = rng.normal(size=(m + 1, 3))
        r = np.column_stack([e[1:, 0], e[1:, 1] + 2 * np.sin(0.7 * np.arange(m)), np.diff(e[:, 2])])
        residuals.append(r - r.mean(axis=0))
    for got, want in zip(span_variance(residuals), ref.span_variance(residuals)):
        # sums over up to 266 rows (relative 1e-14) through a two-term fit of condition below 1e3
        np.testing.assert_allclose(got, want, rtol=1e-10, atol=0)
    x = rng.normal(size=(1003, 3))
    for d in (1, 5, 7):
        for v in (x, x[:, 1], np.asfortranarray(x)):
            np.testing.assert_allclose(block_means(v, d), ref.block_means(v, d), rtol=1e-13, atol=1e-15)


def test_ripple_line_either_side_of_its_threshold(rng):
    """A line standing 0.05 % above, then below, 25 times the background (median / ln 2 of the bins with a whole
    cycle or more in the window) of the reference's periodogram: found, then not, by the library too."""
    n = 400
    noise, wave = rng.normal(size=n), np.sin(2 * np.pi * 0.1 * np.arange(n) + 0.4)

    def ratio(a: float) -> float:
        spec = ref.periodogram(noise + a * wave)[4:]  # bin j has j / 4 cycles in the window
        return float(spec.max() / (ref.median(spec) / math.log(2.0)))

    for side, want in ((1.0005, 1), (0.9995, 0)):
        lo, hi = 0.0, 2.0
        for _ in range(50):  # bisection for the amplitude whose peak is `side` times the threshold
            lo, hi = ((lo + hi) / 2, hi) if ratio((lo + hi) / 2) < 25 * side else (lo, (lo + hi) / 2)
        y = noise + hi * wave
        assert len(find_lines(y, max_lines=1)) == len(ref.find_lines(y, max_lines=1)) == want


def _facts(tb) -> dict:
    """A TimeBase's fields, its gaps as ``(index, step, lost)`` (the reference's own form)."""
    facts = dataclasses.asdict(tb)
    facts["gaps"] = tuple((g["index"], g["step"], g["lost"]) for g in facts["gaps"])
    return facts


_TIMES = ("span", "period", "mean_step", "median_step", "jitter", "clock_start", "clock_period")


def _same_time_base(fast: dict, slow: dict, t) -> None:
    """Counts, decisions and gaps (a gap's step is the same subtraction) exactly; the times to 4 eps max|t|.

    The logs here are contiguous (generated so): the reference has no breaks to find, and there must be none."""
    assert fast.pop("breaks", ()) == () == slow.pop("breaks", ())
    assert {k: v for k, v in fast.items() if k not in _TIMES} == {k: v for k, v in slow.items() if k not in _TIMES}
    tol = 4 * np.finfo(float).eps * float(np.max(np.abs(t)))
    for name in _TIMES:
        assert fast[name] == pytest.approx(slow[name], rel=0, abs=tol), name


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
        _same_calibration(fast, slow, rec.t)


def _same_calibration(fast, slow, t):
    a, b = fast.calibration, slow.calibration
    assert _close_documents(list(a.windows), list(b.windows))  # an angle's rate: the duration to rounding
    np.testing.assert_allclose(a.model.params, b.model.params, rtol=1e-9)
    scale = np.sqrt(np.outer(np.diag(b.covariance), np.diag(b.covariance)))
    np.testing.assert_allclose(a.covariance / scale, b.covariance / scale, atol=1e-9)
    np.testing.assert_allclose(a.noise_std, b.noise_std, rtol=1e-9)
    assert (fast.warnings, fast.notes) == (slow.warnings, slow.notes)
    assert (fast.time_base is None) == (slow.time_base is None)
    if fast.time_base is not None:
        _same_time_base(_facts(fast.time_base), _facts(slow.time_base), t)
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
