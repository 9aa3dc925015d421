"""Calibrations that check themselves: each defect of real recordings, simulated with its truth.

Every test simulates one defect (bursty receive-time stamps, packet gaps, a wrong declared angle or
sample rate, speed ripple, a poor gyro, ramps under the paper's methods, slow turns at 20 Hz) and
checks the result against the simulator's truth: right within the reported 1-sigma, or flagged.
Monte Carlo tolerances come from the spread of a z-score RMS over M draws of three scale factors,
``sd(RMS) ~ 1 / sqrt(6 M)`` for unit normal z-scores.
"""

import dataclasses
import math
import re

import numpy as np
import pytest

from gyrocal.checks.quality import GoodnessOfFit
from gyrocal.errors import InputError, SegmentationError
from gyrocal.models import ScaleBias
from gyrocal.pipeline import calibrate
from gyrocal.recording import Recording
from gyrocal.segmentation import segment
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo
from gyrocal.simulation.timestamps import ReceiveClock, with_time_defects

K = np.array([1.0069, 0.9960, 0.9955])  # the servo method of Wang et al., Table III (MPU9250)
B = np.array([0.0442, -0.0089, 0.0076])  # [rad/s]
TRUE = np.concatenate([K, B])
GYRO = VirtualGyro(ScaleBias(K, B), noise_std=0.01)
BURSTY = ReceiveClock(packet=2, read_time=0.0035, jitter=0.003, late_per_minute=6, late_delay=0.08)


def _z(run, truth=TRUE):
    return (run.fit.model.params - truth) / run.fit.std


def _rms(z):
    return float(np.sqrt(np.mean(np.square(z))))


def test_bursty_receive_stamps_give_the_right_scale(rng):
    """Stamps in 3/17 ms bursts with late packets: the median step reads 200 Hz, the sensor runs at 100."""
    z = []
    for _ in range(8):
        rec, _ = simulate_servo(GYRO, ServoProtocol(misalignment_deg=3), sample_rate=100, rng=rng)
        bursty, _ = with_time_defects(rec, rng, clock=BURSTY)
        assert np.median(np.diff(bursty.t)) < 0.006
        run = calibrate(bursty, angle=2 * math.pi)
        assert run.time_base.bursty and run.time_base.regular_clock
        z.append(_z(run)[:3])
    # 24 z-scores: RMS 1 +- 4 / sqrt(2 * 24) = 0.58, two-sided (a 1-sigma too wide fails as well as too narrow)
    assert abs(_rms(z) - 1) < 4 / math.sqrt(2 * np.size(z))


def test_turns_across_packet_gaps_are_bounded_or_left_out(rng):
    """Six 169 ms gaps in a 100 Hz log: a turn keeps a gap whose hidden angle is bounded small, and
    leaves the session with the reason when it may hide more than 1 % of the turn."""
    z, dropped, kept = [], 0, 0
    for seed in range(10):
        rec, _ = simulate_servo(GYRO, ServoProtocol(misalignment_deg=3), sample_rate=100, rng=rng)
        gappy, truth = with_time_defects(rec, rng, clock=BURSTY if seed % 2 else None, gaps=6, gap_length=0.169)
        try:
            run = calibrate(gappy, angle=2 * math.pi)
        except SegmentationError as err:  # both turns about an axis crossed a long gap: refused, with the reason
            assert re.search(r"ignored \d+ \((\d+ short static, )?\d+ gap\)", str(err)), str(err)
            continue
        assert len(run.time_base.gaps) == 6 and run.time_base.lost == 6 * 17  # the simulator's truth
        reasons = [r for _, r in run.segmentation.ignored if r.startswith("gap")]
        assert all(re.match(r"gap: \d+ sample\(s\) missing inside the turn \(\d+(\.\d+)? ms step at sample \d+\); "
                            r"the angle they hide may be \d", r) for r in reasons), reasons
        dropped += len(reasons)
        kept += sum(bool(run.time_base.gaps_in(w.start, w.stop)) for w in run.segmentation.rotations)
        z.append(_z(run))
    assert dropped and kept and len(z) >= 5  # both outcomes happen over these draws
    assert abs(_rms(z) - 1) < 4 / math.sqrt(2 * np.size(z))  # two-sided: 4 sd of the RMS of n normals


def test_a_wrong_declared_angle_is_measured_not_imposed(rng):
    """Turns of 135/180/270 deg declared 150: each axis gets its own consistent turns; turns about one
    axis that one scale factor cannot explain are left out with their measured angle."""
    revs = (135 / 360, 180 / 360, 270 / 360, 135 / 360, 180 / 360, 270 / 360)
    rec, _ = simulate_servo(GYRO, ServoProtocol(revolutions=revs, misalignment_deg=3), sample_rate=100, rng=rng)
    run = calibrate(rec, angle=math.radians(150))
    reasons = [r for w, r in run.segmentation.ignored if w.kind == "rotation"]
    assert len(reasons) == 3 and all(r.startswith("wrong angle: turned ") for r in reasons)
    # measured angles read the gyro's scale too (k = 1.0069: 135 deg reads 134)
    assert any(re.search(r"turned 1[78]\d deg where the other x turns make 13\d deg \(declared 150 deg\)", r)
               for r in reasons), reasons
    # what is kept reads k = 150 / 135 etc., and is flagged as implausible for deg/s data
    assert np.allclose(run.fit.model.k, K * [150 / 135, 150 / 135, 150 / 180], rtol=0.01)
    assert sum("from 1 for data in rad/s" in w for w in run.warnings) == 3


def test_windows_that_disagree_give_a_warning_and_a_scaled_covariance(rng):
    """A windows file declares 150 deg for turns of 135-270 deg: every window is used, the fit's chi2
    says they disagree, names them, and widens the covariance of k by the turns' scatter so the truth
    (the simulator's k) is within it; the biases rest on static windows that agree, and keep their 1-sigma."""
    revs = (135 / 360, 180 / 360, 270 / 360, 135 / 360, 180 / 360, 270 / 360)
    rec, truth = simulate_servo(GYRO, ServoProtocol(revolutions=revs, misalignment_deg=3), sample_rate=100,
                                rng=rng)
    windows = [dataclasses.replace(w, angle=math.radians(150)) if w.kind == "rotation" else w for w in truth.windows]
    run = calibrate(rec, angle=math.radians(150), windows=windows)
    q = run.quality
    assert q.covariance_scaled and q.p_value < 1e-3 and q.birge_ratio > 10
    assert run.warnings[0].startswith("the turns and static windows disagree beyond their noise")
    assert all(run.calibration.windows[i]["kind"] == "rotation" for i in q.disagree)
    assert q.birge_ratio == pytest.approx(math.sqrt(q.chi2 / q.dof))
    raw = calibrate(rec, angle=math.radians(150), windows=windows, checks=False, long_run=False)
    assert np.all(run.fit.std[:3] > 10 * raw.fit.std[:3])  # the noise-only 1-sigma would claim 1e-4 on k
    assert np.all(np.abs(run.fit.model.k - K) < 4 * run.fit.std[:3])
    assert np.all(run.fit.std[3:] < 2 * raw.fit.std[3:])
    assert run.quality.excess["turn_reference_sd"] > 10  # [deg]: the declared angles are that far off


def test_a_clean_session_passes_its_own_check():
    """Over 60 clean sessions the p-values are uniform (Kolmogorov-Smirnov against U(0, 1), the
    distribution a right chi2 test gives), and a fit is flagged only by chance: p < 0.001 of all rows or of
    one of its two groups expects about 0.18 of 60; four or more would have Poisson probability 5e-5."""
    from scipy.stats import kstest

    p, scaled = [], 0
    for seed in range(60):
        rec, _ = simulate_servo(GYRO, ServoProtocol(misalignment_deg=3), rng=np.random.default_rng(seed))
        q = calibrate(rec, angle=2 * math.pi).quality
        p.append(q.p_value)
        scaled += bool(q.warnings)
    assert kstest(p, "uniform").pvalue > 1e-3 and scaled <= 3


def test_a_declared_reference_accuracy_enters_the_scale_factors_variance(rng):
    """Reference: first-order propagation. Each axis's k rests on its two turns (+ and -), and a turn's rate is
    its angle over its time, so an angle sd of s on every turn of angle A adds ``k^2 (s / A)^2 / 2`` to var(k),
    on top of the noise's variance; the biases lose what the turns told of them and rest on the static windows.
    (Without the checks,
    which would also carry a scatter the turns happen to show, on top of the declared sd.)"""
    rec, _ = simulate_servo(GYRO, ServoProtocol(misalignment_deg=3), rng=rng)
    plain = calibrate(rec, angle=2 * math.pi, checks=False)
    declared = calibrate(rec, angle=2 * math.pi, reference_sd=math.radians(1.0), checks=False)
    expected = np.sqrt(plain.fit.std[:3] ** 2 + declared.fit.model.k**2 * (1.0 / 360.0) ** 2 / 2)
    np.testing.assert_allclose(declared.fit.std[:3], expected, rtol=0.03)
    assert np.all(declared.fit.std[3:] >= plain.fit.std[3:])
    checked = calibrate(rec, angle=2 * math.pi, reference_sd=math.radians(1.0))
    assert any("declared accuracy of every turn's angle, 1 deg" in n for n in checked.notes)
    with pytest.raises(InputError, match="applies to method 'first-moment' only"):
        calibrate(rec, angle=2 * math.pi, method="lm", reference_sd=0.01)
    with pytest.raises(InputError, match=">= 0"):
        calibrate(rec, angle=2 * math.pi, reference_sd=-1.0)


def test_no_degrees_of_freedom_is_said(rng):
    rec, _ = simulate_servo(GYRO, ServoProtocol(), rng=rng)
    run = calibrate(rec, speed=math.radians(60), method="algorithm1")
    assert run.quality.dof == 0 and run.quality.p_value is None
    assert run.warnings == ("no residual degrees of freedom: 6 equations for 6 parameters, so nothing checks the "
                            "turns against each other; add static windows or repeat turns to let the fit check itself",)


def test_angles_on_a_counted_time_base_are_flagged(rng):
    """The chip's clock 0.5 % fast, the time column its sample counter times 10 ms (the generator of
    tests/realistic.py): every k reads 0.5 % low, a hundred of its 1-sigma, and nothing in the data can
    tell. The calibration says what its angles rest on; the same log stamped by a PC on receipt is
    right, and says nothing."""
    import dataclasses

    import realistic as R

    gyro = dataclasses.replace(R.GYROS[0], clock_error=0.005)
    plan = [item for j in range(3) for s in (1, -1)
            for item in (R.Turn(tuple(np.eye(3)[j]), s * 360.0, 60.0), R.Pause(3.0))]
    for stamps in ("sensor", "receive"):
        log = R.record(plan, gyro, stamps=stamps, seed=1)
        rec = Recording(t=log.stamps, gyro=np.radians(log.gyro))
        run = calibrate(rec, angle=2 * math.pi)
        off = np.abs(run.fit.model.k - log.k_eff) / run.fit.std[:3]
        said = any("a sample counter times the nominal rate" in w for w in run.warnings)
        assert (said and np.all(off > 20)) if stamps == "sensor" else (not said and np.all(off < 4))
    assert calibrate(rec, speed=math.radians(60)).warnings == ()  # a known speed needs no time base


def test_a_wrong_declared_sample_rate_is_named(rng):
    """A 20 Hz log declared 25 Hz (no time column): every turn reads 20 % short; the warning says so."""
    rec, _ = simulate_servo(GYRO, ServoProtocol(speed=math.radians(25)), sample_rate=20, rng=rng)
    run = calibrate(Recording.from_rate(rec.gyro, 25.0), angle=2 * math.pi)
    np.testing.assert_allclose(run.fit.model.k, K * 25 / 20, rtol=0.01)
    assert len(run.warnings) == 1
    assert "every turn reads 20 % short" in run.warnings[0]
    assert "is the sample rate 20 Hz rather than the 25 Hz declared?" in run.warnings[0], run.warnings[0]


@pytest.mark.parametrize("k", [[1.55, 1.80, 1.30], [0.5, 0.6, 2.0]])
@pytest.mark.parametrize("reference", ["speed", "angle"])
def test_poor_gyros_are_found_and_flagged(k, reference, rng):
    """k from 0.5 to 2 (the servo method's extreme study reaches 2): found by structure, and each axis far from
    1 warned about. Reference: the simulated truth over 10 seeded sessions, RMS of 60 z two-sided."""
    gyro = VirtualGyro(ScaleBias(k, B), noise_std=0.01)
    z = []
    for _ in range(10):
        rec, _ = simulate_servo(gyro, ServoProtocol(misalignment_deg=3), rng=rng)
        run = calibrate(rec, **({"speed": math.radians(60)} if reference == "speed" else {"angle": 2 * math.pi}))
        assert len(run.segmentation.rotations) == 6
        assert sum("from 1 for data in rad/s" in w for w in run.warnings) == 3
        z.append(_z(run, np.concatenate([k, B])))
    assert np.all(np.abs(z) < 4)
    assert abs(_rms(z) - 1) < 4 / math.sqrt(2 * np.size(z)), _rms(z)


def test_ripple_standard_errors_hold(rng):
    """5 % speed ripple at 2.5 Hz with the speed reference. Reference: the simulated truth; the RMS of error /
    reported sigma is within 1 +- 4 sd of the RMS of 30 x 3 normals (sd 0.075: 0.70-1.30, two-sided; before,
    0.8-1.5 let a sigma 1.5x too narrow pass) and the sigma at most 3x the white-noise one."""
    z, z_plain, ratio = [], [], []
    for _ in range(30):
        p = ServoProtocol(speed=math.radians(120), ripple=0.05, ripple_freq=2.5, vibration=0, misalignment_deg=3)
        rec, _ = simulate_servo(GYRO, p, rng=rng)
        run = calibrate(rec, speed=math.radians(120))
        plain = calibrate(rec, speed=math.radians(120), checks=False, long_run=False)  # plain means, white sigma
        z.append(_z(run)[:3])
        z_plain.append(_z(plain)[:3])
        ratio.append(run.fit.std[:3] / plain.fit.std[:3])
    assert abs(_rms(z) - 1) < 4 / math.sqrt(2 * np.size(z)), _rms(z)  # measured 1.10
    assert np.max(ratio) <= 3.0
    # the defect is there: without the self-checks the plain means read the ripple, far beyond their sigma
    assert _rms(z_plain) > 1.5 + 4 / math.sqrt(6 * 30)


def test_the_paper_methods_refuse_whole_turns_with_ramps(rng):
    rec, _ = simulate_servo(GYRO, ServoProtocol(), rng=rng)
    for method, name in (("algorithm1", "Algorithm 1"), ("lm", "LM")):
        with pytest.raises(InputError, match=rf"rotation window .* its rate varies \d+ %.*{name} \(the servo method of "
                                             r"Wang et al\., eq\. 4-8\) assumes a constant speed.*use the default method"):
            calibrate(rec, angle=2 * math.pi, method=method)
    assert calibrate(rec, speed=math.radians(60), method="lm").fit.method == "lm"  # plateaus are constant


@pytest.mark.parametrize("reference", ["speed", "angle"])
def test_slow_turns_at_20_hz_are_one_window_each(reference):
    """README's example row: 20 Hz, 25 deg/s. Every turn is one window, over 8 seeds."""
    for seed in range(8):
        rec, _ = simulate_servo(VirtualGyro(ScaleBias(K, B), noise_std=0.035), ServoProtocol(speed=math.radians(25)),
                                sample_rate=20, rng=np.random.default_rng(seed))
        seg = segment(rec, reference=reference, speed=math.radians(25))
        assert [w.label for w in seg.rotations] == list(PAPER_TURNS)


def test_constant_data_and_zero_noise_are_refused(rng):
    zero = Recording.from_rate(np.zeros((2000, 3)), 100.0)
    with pytest.raises(SegmentationError, match=r"every reading is the same \(0, 0, 0 on x, y, z\)"):
        calibrate(zero, angle=2 * math.pi)
    rec, _ = simulate_servo(GYRO, ServoProtocol(), rng=rng)
    with pytest.raises(InputError, match="noise_std must be > 0 on every axis"):
        calibrate(rec, angle=2 * math.pi, noise_std=0.0)


def test_counts_print_their_implied_sensitivity_and_skip_the_re_poses(rng):
    """Counts from an MPU-9250 at +-2000 deg/s (16.4 LSB per deg/s) with 90 deg re-poses between the turns:
    the 360 deg turns are the calibration turns (never the most common motion), and the note names the setting."""
    revs = (0.25, 0.25, 0.25, 1, 1, 1, 1, 1, 1, 0.25, 0.25)
    turns = ("+x", "+y", "+z") + PAPER_TURNS + ("+y", "-y")
    rec, _ = simulate_servo(GYRO, ServoProtocol(turns=turns, revolutions=revs, misalignment_deg=3), rng=rng)
    counts = Recording(t=rec.t, gyro=np.round(rec.gyro * 16.4 * 180 / math.pi), units="counts", source_units="counts")
    run = calibrate(counts, angle=2 * math.pi)
    assert [w.label for w in run.segmentation.rotations] == list(PAPER_TURNS)
    # the only warning: the simulator's time column counts samples at 200 Hz, so k is as good as that rate
    assert len(run.warnings) == 1 and "a sample counter times the nominal rate" in run.warnings[0]
    assert len(run.notes) == 1 and "sensitivity of 16." in run.notes[0]
    assert "+-2000 deg/s = 16.4 LSB/(deg/s) (InvenSense, Bosch)" in run.notes[0]


def test_fit_quality_round_trips_through_its_document(rng):
    rec, _ = simulate_servo(GYRO, ServoProtocol(), rng=rng)
    q = calibrate(rec, angle=2 * math.pi).quality
    doc = q.to_document()
    assert set(doc) >= {"chi2", "dof", "p_value", "birge_ratio", "covariance_scaled", "residuals", "warnings"}
    assert GoodnessOfFit.from_document(doc) == q
    assert len(doc["residuals"]) == len(q.labels) and len(doc["residuals"][0]) == 3  # a static window first


def test_each_extra_variance_makes_its_groups_chi2_equal_its_dof():
    """Reference: the defining equation ``sum r2 / (v + c tau2) = dof``, solved here in closed form for equal
    rows: four turns of chi2 4 each at 1.74 dof need tau2 = 16 / 1.74 - 1 (the former bracket stopped at 4)."""
    from gyrocal.checks.excess import _solve_tau2

    r2, v, c = np.full(4, 4.0), np.ones(4), np.ones(4)
    assert _solve_tau2(r2, v, c, 1.74) == pytest.approx(16 / 1.74 - 1, rel=1e-9)
    rng = np.random.default_rng(7)
    for _ in range(50):
        r2, v, c = rng.chisquare(1, 6) * 5, rng.uniform(0.5, 2, 6), rng.uniform(0.1, 3, 6)
        tau2 = _solve_tau2(r2, v, c, 2.9)
        if tau2 > 0:
            assert np.sum(r2 / (v + c * tau2)) == pytest.approx(2.9, rel=1e-9)


def test_every_printed_warning_and_note_is_in_the_file(rng):
    """A poor gyro (k 55/80/30 % from 1) on a counted time base: the plausibility and time-base warnings the
    command prints are the file's ``fit.warnings`` too, so a flagged calibration does not look clean there."""
    gyro = VirtualGyro(ScaleBias([1.55, 1.80, 1.30], B), noise_std=0.01)
    rec, _ = simulate_servo(gyro, ServoProtocol(misalignment_deg=3), rng=rng)
    run = calibrate(rec, angle=2 * math.pi)
    assert any("55 % from 1" in w for w in run.warnings) and any("sample counter" in w for w in run.warnings)
    assert list(run.calibration.fit["warnings"]) == list(run.warnings)
    assert list(run.calibration.fit["notes"]) == list(run.notes)
