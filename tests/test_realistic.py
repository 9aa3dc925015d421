"""Calibrations of realistic recordings that no gyrocal code made: right within their 1-sigma, or flagged.

Reference: the truth of ``tests/realistic.py``, a generator independent of ``gyrocal.simulation``
(robot and hand motion in physical time, a chip's low-pass filter, flicker noise, quantisation, the
Earth's rate, mounting misalignment and non-orthogonality, PC receive-time stamps). ``k_eff`` is the
scale factor the norm equations give for its noise-free turns. Each test scores ``z = error / reported
1-sigma`` over a few seeded sessions; with ``m`` values of ``z`` its RMS has a spread of about
``1 / sqrt(2 m)``, and the bands below are about three of those wide. The figures over many more seeds
are in docs/selfcheck.md (``python tools/audit_realistic.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import realistic as R

from gyrocal.io import read_recording
from gyrocal.pipeline import calibrate
from gyrocal.segmentation.windows import Window


def _rms(z) -> float:
    return float(np.sqrt(np.mean(np.square(z))))


def _six(speed=60.0, **kw) -> list:
    return [item for j in range(3) for s in (1, -1)
            for item in (R.Turn(tuple(np.eye(3)[j]), s * 360.0, speed, **kw), R.Pause(3.0))]


def _read(log: R.Log, tmp_path):
    path = tmp_path / "log.csv"
    log.write(path)
    return read_recording(path, units="deg/s")


_ZB: list = []  # z of b in the current test (scored by the fixture below wherever k is scored)


def _z(run, log: R.Log, *, earth: bool = True, score_b: bool = True) -> np.ndarray:
    if score_b:
        _ZB.append(((run.fit.model.b - np.radians(log.b_true)) / run.fit.std[3:6], earth))
    return (run.fit.model.k - log.k_eff) / run.fit.std[:3]


@pytest.fixture(autouse=True)
def _score_b():
    """b wherever k is scored: its RMS z against the generator's b_true, two-sided within four spreads.

    b's 1-sigma carries the Earth's rate on an axis of unknown orientation (issue 22); in a session simulated
    without it that term is pure margin, so there only the upper side is judged."""
    _ZB.clear()
    yield
    if _ZB:
        z = np.array([zb for zb, _ in _ZB])
        rms, tol = float(np.sqrt(np.mean(z**2))), 4 / math.sqrt(2 * z.size)
        print(f"RMS z(b) {rms:.2f} over {z.size}")
        assert rms < 1 + tol and (not all(e for _, e in _ZB) or rms > 1 - tol), (rms, tol)


def test_turns_carry_the_noise_the_chips_filter_leaves(tmp_path):
    """1 kHz behind a 41 Hz low-pass filter (an MPU-9250's DLPF_CFG 3): successive samples are alike, so the
    white noise of first differences is a twentieth of a turn's angle noise. Turns now take the static windows'
    long-run variance: before, RMS z was 17 (the 1-sigma claimed 2.8e-6 on k where the error was 5e-5)."""
    gyro = R.Gyro(k=(1.01, 0.99, 1.0))
    z = [_z(calibrate(_read(log := R.record(_six(), gyro, rate=1000, stamps="sensor", seed=seed), tmp_path),
                      angle=2 * math.pi), log) for seed in range(4)]
    assert 0.4 <= _rms(z) <= 1.6  # 12 values: spread of the RMS about 0.2


def _robot_windows(log: R.Log, rec, tmp_path) -> list[Window]:
    """The windows file a user writes from the robot's log (seconds), read as ``gyrocal calibrate --windows`` does."""
    import json

    from gyrocal.io import read_windows

    path = tmp_path / "windows.json"
    path.write_text(json.dumps(log.windows()))
    return read_windows(path, sample_rate=rec.sample_rate, t0=float(rec.t[0]), n_samples=len(rec), t=rec.t)


def test_robot_angles_that_scatter_widen_the_scale_factors(tmp_path):
    """Robot turns of 135-270 deg at 40 deg/s whose logged angles are off by 0.1 deg (sd): the turns
    disagree beyond their noise, and only a few of their rows sit among many static ones. Each group now
    gets its own extra variance: k's 1-sigma holds the angle errors. Before: RMS z 2.5, up to 7, with no
    flag on most sessions (the static rows diluted the chi2)."""
    z, flagged = [], []
    for seed in range(5):
        rng = np.random.default_rng(seed)
        log = R.record(R.robot_plan(40.0, rng), R.GYROS[0], seed=seed, angle_sd=0.1)
        rec = _read(log, tmp_path)
        run = calibrate(rec, angle=2 * math.pi, windows=_robot_windows(log, rec, tmp_path))
        z.append(_z(run, log))
        flagged.append(bool(run.warnings))
        assert run.quality.excess["turn_reference_sd"] > 0.02  # [deg]: the scatter was seen
    assert 0.6 <= _rms(z) <= 1.6  # 15 values
    assert np.all(np.abs(np.array(z))[~np.array(flagged)] < 4)


def test_servo_vibration_at_a_known_speed(tmp_path):
    """--speed with 5 % ripple at 2.5 Hz and a servo's random vibration (0.02 deg, 8 Hz band; a bounded angle
    error) on a gyro whose noise is white behind its low-pass filter: plateau variances from the variance of
    residual sums over spans. Before: the Newey-West lag window counted the vibration's short-lag covariance
    only, sigma 7.9x the white-noise one and RMS z 0.25. (With flicker noise and the Earth's rate the 1-sigma
    rightly grows beyond 3x: the bias wanders under the plateaus, and the Earth's rate differs from pose to
    pose by up to 0.006 deg/s, a tenth of a per mille of 60 deg/s; docs/selfcheck.md has those figures.)"""
    gyro = R.Gyro(k=(1.01, 0.99, 1.0), mount_deg=2.0, flicker=0.0)
    z, ratio = [], []
    for seed in range(6):
        log = R.record(_six(ripple=0.05, ripple_hz=2.5, jitter_deg=0.02), gyro, stamps="packets", per_packet=1,
                       seed=seed, earth=False)
        rec = _read(log, tmp_path)
        run = calibrate(rec, speed=math.radians(60))
        plain = calibrate(rec, speed=math.radians(60), checks=False, long_run=False)
        z.append(_z(run, log, earth=False))
        ratio.append(run.fit.std[:3] / plain.fit.std[:3])
    assert 0.6 <= _rms(z) <= 1.6  # 18 values
    # the white-noise 1-sigma misses the chip's filter and the vibration (1.5-1.9x here), and a fit whose plateaus
    # scatter a little is widened: single runs reach 4x, the typical one stays well under 3x
    assert np.mean(ratio) <= 3.0


def test_a_wandering_hand_axis_is_integrated_as_a_rotation(tmp_path):
    """Hand tilts of 45 deg whose axis wobbles 1.5-2.5 deg: the rate's integral is shorter than the rotation
    (coning), and k read high by 4e-4 (before: mean z +1.0, RMS 1.5 over the first 6 of these sessions). Each
    turn's integral is now compared with its rotation from quaternion kinematics. The mean of 27 z has a spread
    of 0.19; their RMS is judged two-sided (measured 0.86 here, 0.99 over the 28 of seeds 0-29 that segment). (A turn that wobbles so
    much that a tenth of its motion cancels out is left out, with the reason.)"""
    gyro = R.Gyro(k=(1.01, 0.99, 1.005), mount_deg=0.0, cross=0.0)
    z = []
    for seed in range(9):
        rng = np.random.default_rng(seed)
        plan = []
        for j in range(3):
            for _ in range(2):
                a = math.radians(rng.uniform(0, 20))
                axis = tuple(math.cos(a) * np.eye(3)[j] + math.sin(a) * np.eye(3)[(j + 1) % 3])
                for s in (1, -1):
                    plan += [R.Turn(axis, s * 45.0, rng.uniform(20, 60), profile="hand", wobble_deg=rng.uniform(1.5, 2.5),
                                    wobble_hz=rng.uniform(0.8, 2.5)), R.Pause(2.0)]
        log = R.record(plan, gyro, seed=seed, stamps="packets", per_packet=1, angle_sd=0.0)
        z.append(_z(calibrate(_read(log, tmp_path), angle=math.radians(45)), log))
    assert abs(float(np.mean(z))) < 0.6
    # too wide fails too: 4 sd of the RMS of m normals below 1; the upper bound stays the tighter 1.4
    assert 1 - 4 / math.sqrt(2 * np.size(z)) < _rms(z) <= 1.4


@pytest.mark.parametrize("rate", [200, 1000])
def test_receive_stamps_in_packets(tmp_path, rate):
    """PC receive-time stamps of USB packets of four samples, with late deliveries: the sensor clock is rebuilt
    and no delivery rhythm is taken for a late packet. Reference: the generator's k over 8 seeded sessions, RMS of
    24 z two-sided (measured 0.92 at 200 Hz, 0.74 at 1000 Hz; docs/selfcheck.md: 0.66-1.15 over such logs)."""
    z = []
    for seed in range(7, 15):
        log = R.record(_six(), R.Gyro(k=(1.01, 0.99, 1.0)), rate=rate, stamps="packets", per_packet=4, seed=seed)
        rec = _read(log, tmp_path)
        tb = rec.time_base()
        assert tb.regular_clock and not tb.gaps and tb.delayed <= 10
        z.append(_z(calibrate(rec, angle=2 * math.pi), log))
    assert np.all(np.abs(z) < 4)
    assert abs(_rms(z) - 1) < 4 / math.sqrt(2 * np.size(z)), _rms(z)  # too wide fails as well as too narrow


def test_clipping_is_found_and_a_smooth_peak_is_not(tmp_path):
    """A 130 deg/s turn on a +-125 deg/s chip clips: readings pile up at full scale and the file is refused.
    At 1 kHz behind the chip's low-pass filter a 60 deg/s turn holds its top reading a few samples running,
    as often as the reading below it: no saturation (before, such a log was refused as stuck at full scale)."""
    import dataclasses

    from gyrocal.errors import SaturationError

    clipped = R.record(_six() + [R.Turn((1, 0, 0), 360.0, 130.0), R.Pause(3.0)],
                       dataclasses.replace(R.GYROS[0], lsb=262.4), seed=2)
    with pytest.raises(SaturationError, match="axis x is stuck at full scale"):
        _read(clipped, tmp_path)
    smooth = R.record(_six(), R.Gyro(k=(1.01, 0.99, 1.0)), rate=1000, stamps="sensor", seed=2)
    assert len(_read(smooth, tmp_path)) == len(smooth.gyro)


def test_a_declared_robot_accuracy_carries_what_no_residual_shows(tmp_path):
    """Robot turns at 120 deg/s, where the robot's 0.05 deg angle errors outweigh the noise: an error that the
    few turns about an axis happen to share moves k and leaves no residual, so the data alone gave RMS z 1.16
    and up to 4.7 over 216 runs (docs/selfcheck.md). Declared (``reference_sd``, ``--angle-sd``), the accuracy
    enters every turn's variance: RMS z within the band of its own spread."""
    z = []
    for seed in range(8):
        rng = np.random.default_rng(100 + seed)
        log = R.record(R.robot_plan(120.0, rng), R.GYROS[0], seed=seed, angle_sd=0.05)
        rec = _read(log, tmp_path)
        run = calibrate(rec, angle=2 * math.pi, windows=_robot_windows(log, rec, tmp_path),
                        reference_sd=math.radians(0.05))
        z.append(_z(run, log))
        assert any("declared accuracy" in n for n in run.notes)
    assert 0.6 <= _rms(z) <= 1.45  # 24 values: spread of the RMS about 0.14
    assert np.max(np.abs(z)) < 3.5


def test_a_gap_inside_a_plateau_keeps_the_ripple_in_phase(tmp_path):
    """--speed with a 5 % ripple at 2.5 Hz and three 0.5 s packet gaps inside the plateaus: the ripple's sines
    are placed on the sample clock, so a gap moves nothing but samples. Before, each plateau's own mean step
    (stretched by its gap) set the phase: half the runs warned falsely with a 1-sigma ten times too wide.
    Reference: the same sessions without gaps (their 1-sigma) and the generator's k (z)."""
    z, ratio, flagged = [], [], 0
    for seed in range(4):
        plan = [item for j in range(3) for s in (1, -1)
                for item in (R.Turn(tuple(np.eye(3)[j]), s * 360.0, 60.0, ripple=0.05, ripple_hz=2.5, jitter_deg=0.02),
                             R.Pause(3.0))]
        gyro = R.Gyro(k=(1.01, 0.99, 1.0), mount_deg=2.0)
        runs = []
        for gaps in ((), (50,) * 3):
            log = R.record(plan, gyro, rate=100.0, stamps="packets", per_packet=1, seed=seed, gaps=gaps)
            runs.append(calibrate(_read(log, tmp_path), speed=math.radians(60.0)))
        # not b: with --speed its 1-sigma is still short, RMS z(b) 1.4 over 12 seeds (2.2 before issue 22; open)
        z.append(_z(runs[1], log, score_b=False))
        ratio.append(runs[1].fit.std[:3] / runs[0].fit.std[:3])
        flagged += any("disagree" in w for w in runs[1].warnings)
    assert flagged == 0
    # 1.5 s of 108 lost: the 1-sigma grows a little (median 1.1 over 12; the old phase gave 4.5, one session
    # in four still shows 4 through its turns' chi2); losing samples cannot narrow it
    assert 1.0 <= np.median(ratio) < 1.5
    assert np.max(np.abs(z)) < 3.5
    assert abs(_rms(z) - 1) < 4 / math.sqrt(2 * np.size(z)), _rms(z)  # two-sided; measured 1.07


def test_the_generators_plateau_ripple_has_zero_mean_over_the_true_plateau():
    """The plateau-only ripple of issue 22 item 8 (``Turn.plateau_ripple``), on a noise-free, unmounted gyro.
    Reference: the turn's own parameters (60 deg/s cruise between 0.3 s ramps, 5 % at 2.5 Hz)."""
    gyro = R.Gyro(mount_deg=0.0, cross=0.0, noise_density=0.0, flicker=0.0, lsb=None, dlpf_hz=None,
                  offset=(0.0, 0.0, 0.0))
    turn = R.Turn((1, 0, 0), 360.0, 60.0, profile="trapezoid", accel=200.0, plateau_ripple=0.05)
    log = R.record([turn], gyro, rate=1000.0, stamps="sensor", seed=3, earth=False)
    t0 = log.turns[0]["start"]
    cruise = log.gyro[int(round((t0 + 0.3) * 1000)) + 2: int(round((t0 + 6.0) * 1000)) - 2, 0]
    assert abs(cruise.mean() - 60.0) < 0.01 and 2.9 < (cruise.max() - cruise.min()) / 2 < 3.1
    assert abs(log.gyro[:, 0].sum() / 1000 - 360.0) < 0.05  # the turn still turns its angle


@pytest.mark.parametrize("model", ["plateau_ripple", "ripple"])
def test_speed_ripple_on_the_plateau_only_or_about_the_speed(tmp_path, model):
    """Issue 22 item 8: k = (1.8, 0.6, 1.25), 8 deg mount, 0.5 deg/s white noise at 200 Hz, 0.3 s ramps, 5 % ripple
    at 2.5 Hz either on the cruise only with zero mean over it (the declared speed is the plateau's mean) or about
    the commanded speed (its level under the ripple). The two readings differ by the ripple's partial cycles over
    the whole plateau; opposite turns against the standstill offset tell which holds. Before, for the plateau-only
    ripple: RMS z 1.59, max 4.36 over 20 seeds. Band: the issue's target above, four spreads of 24 z below."""
    gyro = R.Gyro(k=(1.8, 0.6, 1.25), mount_deg=8.0, noise_density=0.5 / 40, dlpf_hz=None, flicker=0.0)
    z, ratio = [], []
    for seed in range(8):
        plan = _six(profile="trapezoid", accel=200.0, **{model: 0.05})
        rec_log = R.record(plan, gyro, rate=200.0, stamps="sensor", seed=seed, earth=False)
        rec = _read(rec_log, tmp_path)
        run = calibrate(rec, speed=math.radians(60))
        plain = calibrate(rec, speed=math.radians(60), checks=False, long_run=False)
        z.append(_z(run, rec_log, earth=False))
        ratio.append(run.fit.std[:3] / plain.fit.std[:3])
    assert 1 - 4 / math.sqrt(2 * np.size(z)) <= _rms(z) <= 1.5
    assert np.abs(z).max() < 4 and np.mean(ratio) <= 3.0
