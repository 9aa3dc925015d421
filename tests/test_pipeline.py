"""The calibration pipeline: simulated sessions come back within their predicted uncertainty.

References: the simulated truth (within 4 predicted sigma) and the spread over 40 seeds against the
predicted sigma.
"""

import dataclasses
import math

import numpy as np
import pytest

from gyrocal.errors import InputError, SegmentationError
from gyrocal.models import ScaleBias
from gyrocal.pipeline import CalibrationRun, calibrate
from gyrocal.recording import Recording
from gyrocal.results.files import load_calibration, save_calibration
from gyrocal.segmentation.windows import Window
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo

K = np.array([1.0069, 0.9960, 0.9955])  # the servo method of Wang et al., Table III (MPU9250)
B = np.array([0.0442, -0.0089, 0.0076])  # [rad/s]
TRUE = np.concatenate([K, B])
GYRO = VirtualGyro(ScaleBias(K, B), noise_std=0.035)
FS = 200.0
SPEED = math.radians(60.0)

PROTOCOLS = {
    "paper": ServoProtocol(misalignment_deg=10.0),
    "messy": ServoProtocol(turns=PAPER_TURNS + ("+z", "-x"), wait=(3.0, 0.5, 15.0, 1.0, 3.0, 0.4, 2.0),
                           misalignment_deg=7.0, ramp=0.6, vibration=0.08),
}
REFS = {"speed": {"speed": SPEED}, "angle": {"angle": 2 * math.pi}}


def _within_4_sigma(run: CalibrationRun, truth=TRUE) -> None:
    z = (run.fit.model.params - truth) / run.fit.std
    assert np.all(np.abs(z) < 4), z


@pytest.mark.parametrize("name", PROTOCOLS)
@pytest.mark.parametrize("ref", REFS)
def test_estimates_fall_within_4_predicted_sigma(name, ref, rng):
    rec, _ = simulate_servo(GYRO, PROTOCOLS[name], sample_rate=FS, rng=rng)
    run = calibrate(rec, **REFS[ref])
    _within_4_sigma(run)
    n_turns = len(PROTOCOLS[name].turns)
    assert len(run.segmentation.rotations) == n_turns
    assert len(run.observations) == len(run.calibration.windows) == len(run.segmentation.windows)


def test_missing_time_column_calibrates_the_same(rng):
    rec, _ = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    a = calibrate(rec, angle=2 * math.pi)
    b = calibrate(Recording.from_rate(rec.gyro, FS), angle=2 * math.pi)
    np.testing.assert_array_equal(a.fit.model.params, b.fit.model.params)


def test_hand_session_with_the_angle_reference(rng):
    rec, _ = simulate_servo(GYRO, ServoProtocol.hand(wait=(6.0, 4.0)), sample_rate=FS, rng=rng)
    run = calibrate(rec, angle=2 * math.pi)
    _within_4_sigma(run)
    assert [w["axis"] for w in run.calibration.windows if w["kind"] == "rotation"] == ["x", "y", "z"]


@pytest.mark.parametrize("ref", REFS)
def test_predicted_sigma_matches_the_spread_over_seeds(ref):
    """Monte Carlo over 40 sessions: z-scores have unit spread (4-sigma band of a 40-draw std)."""
    z = []
    for seed in range(40):
        rec, _ = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=np.random.default_rng(seed))
        run = calibrate(rec, **REFS[ref])
        z.append((run.fit.model.params - TRUE) / run.fit.std)
    spread = np.std(z, axis=0)
    assert np.all(np.abs(spread - 1) < 4 / np.sqrt(2 * 40)), spread


def test_counts_without_sensitivity_calibrate_to_output_units(rng):
    rec, _ = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    lsb = 16.4  # LSB per deg/s
    counts = Recording(t=rec.t, gyro=np.round(rec.gyro * lsb * 180 / math.pi), units="counts", source_units="counts")
    run = calibrate(counts, angle=2 * math.pi)
    cal = run.calibration
    assert (cal.input_units, cal.output_units, cal.internal_units) == ("counts", "deg/s", "counts")
    # In user units the scale is deg/s per count: K / lsb, and the offset is -b in counts.
    (_, value, sigma, unit), *_ = run.parameters()
    assert unit == "deg/s per count"
    assert abs(value - K[0] / lsb) < 4 * sigma
    matrix, offset = cal.correction
    np.testing.assert_allclose(np.diag(matrix), [p[1] for p in run.parameters()[:3]])
    assert np.all(np.abs(-offset - B * lsb * 180 / math.pi) < 4 * cal.std[3:])


def test_windows_override_detection(rng):
    rec, truth = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    # As a windows file gives them: spans and kinds only.
    given = [Window(w.start, w.stop, w.kind, label=w.label) for w in truth.windows]
    run = calibrate(rec, angle=2 * math.pi, windows=given)
    _within_4_sigma(run)
    assert run.segmentation.reference == "file"
    assert [w.label for w in run.segmentation.rotations] == list(PAPER_TURNS)
    assert [f"{'+' if w.sign > 0 else '-'}{w.axis}" for w in run.segmentation.rotations] == list(PAPER_TURNS)
    assert all(w.rate == pytest.approx(2 * math.pi * FS / len(w)) for w in run.segmentation.rotations)
    # A window's own angle wins over the default.
    half = [dataclasses.replace(w, angle=math.pi) if w.kind == "rotation" else w for w in given]
    own = calibrate(rec, angle=2 * math.pi, windows=half)
    assert own.observations[1].angle == math.pi and own.fit.model.k[0] < 0.6


def test_a_log_that_dropped_samples_uses_its_time_column(rng):
    rec, _ = simulate_servo(GYRO, ServoProtocol.hand(wait=(6.0, 4.0)), sample_rate=FS, rng=rng)
    keep = np.sort(rng.choice(len(rec), size=int(0.97 * len(rec)), replace=False))  # 3 % lost at random
    dropped = Recording(t=rec.t[keep], gyro=rec.gyro[keep], sample_rate=FS)
    run = calibrate(dropped, angle=2 * math.pi)
    # a turn's time comes from t, not from its sample count (that would read k 3 % high: ~40 sigma)
    _within_4_sigma(run)


def test_speed_reference_refuses_given_windows_with_ramps(rng):
    rec, truth = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    statics = [Window(w.start, w.stop, "static") for w in truth.windows if w.kind == "static"]
    whole = [Window(w.start, w.stop, w.kind, label=w.label) for w in truth.windows if w.kind == "rotation"]
    with pytest.raises(InputError, match=r"rotation window 0 \(\+x\) is not at constant speed: .* trim them, or use"):
        calibrate(rec, speed=SPEED, windows=whole + statics)
    plateaus = [Window(w.start, w.stop, "rotation", label=w.label) for w in truth.plateaus]
    _within_4_sigma(calibrate(rec, speed=SPEED, windows=plateaus + statics))


def test_windows_file_needs_an_angle_for_rotations_without_one(rng):
    rec, _ = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    with pytest.raises(InputError, match="ends after the recording"):
        calibrate(rec, angle=2 * math.pi, windows=[Window(0, len(rec) + 5, "static")])
    with pytest.raises(InputError, match="windows is empty"):
        calibrate(rec, angle=2 * math.pi, windows=[])


@pytest.mark.parametrize("method", ["algorithm1", "lm"])
def test_paper_methods_use_the_six_rotations_only(method, rng):
    rec, _ = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    run = calibrate(rec, speed=SPEED, method=method)
    assert [w["kind"] for w in run.calibration.windows] == ["rotation"] * 6
    assert run.calibration.method == method and run.calibration.std is not None
    # Their mean-of-squares form is biased low by about sum k^2 sigma^2 / (2 omega^2) (docs/core.md, Accuracy): 3k * 0.035^2 / 2.2
    assert np.all(np.abs(run.fit.model.k - K) < 5e-3)
    assert "reads k low by about 0.0017" in run.report()


def test_paper_methods_need_both_senses(rng):
    p = ServoProtocol(turns=("+x", "+y", "+z"))
    rec, _ = simulate_servo(GYRO, p, sample_rate=FS, rng=rng)
    with pytest.raises(SegmentationError, match=r"only one sense about x, y, z; 3 rotation\(s\) where the method needs 6"):
        calibrate(rec, angle=2 * math.pi, method="algorithm1")
    run = calibrate(rec, angle=2 * math.pi)  # first-moment: static windows fix the biases
    _within_4_sigma(run)


def test_bad_arguments_are_refused(rng):
    rec, _ = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    with pytest.raises(InputError, match="exactly one of speed"):
        calibrate(rec, speed=SPEED, angle=2 * math.pi)
    with pytest.raises(InputError, match="exactly one of speed"):
        calibrate(rec)
    with pytest.raises(InputError, match="noise_std applies to method 'first-moment' only"):
        calibrate(rec, speed=SPEED, method="lm", noise_std=0.035)
    with pytest.raises(InputError, match="method='magic'"):
        calibrate(rec, speed=SPEED, method="magic")


def test_known_noise_sets_the_white_level(rng):
    """A given noise is a floor on every window's noise (issue 22): above the data's own it sets the covariance
    (twice the noise, twice the 1-sigma; b's less the Earth's rate it also carries); far below it the data's
    long-run variance still counts, and the 1-sigma stays what the data give."""
    from gyrocal.checks.noise_terms import EARTH_RATE

    rec, _ = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    a = calibrate(rec, speed=SPEED, noise_std=0.1)
    b = calibrate(rec, speed=SPEED, noise_std=0.2)
    np.testing.assert_allclose(b.fit.std[:3], 2 * a.fit.std[:3], rtol=1e-9)
    noise_b = [np.sqrt(r.fit.std[3:] ** 2 - (EARTH_RATE / r.fit.model.k) ** 2 / 3) for r in (a, b)]
    np.testing.assert_allclose(noise_b[1], 2 * noise_b[0], rtol=1e-6)
    np.testing.assert_allclose(a.calibration.noise_std, 0.1)
    data = calibrate(rec, speed=SPEED)
    tiny = calibrate(rec, speed=SPEED, noise_std=1e-4)
    np.testing.assert_allclose(tiny.fit.std, data.fit.std, rtol=1e-6)
    assert any("floor" in n for n in tiny.notes)


def test_report_and_saved_file(tmp_path, rng):
    rec, _ = simulate_servo(GYRO, PROTOCOLS["paper"], sample_rate=FS, rng=rng)
    deg = dataclasses.replace(rec, source_units="deg/s")
    run = calibrate(deg, speed=SPEED)
    text = run.report()
    assert "reference speed 60 deg/s" in text and "6 rotation and 7 static window(s)" in text
    bx = next(p for p in run.parameters() if p[0] == "bx")
    assert bx[3] == "deg/s" and abs(bx[1] - math.degrees(B[0])) < 4 * bx[2]
    assert f"{bx[1]:.6g}" in text
    save_calibration(run.calibration, tmp_path / "cal.json")
    back = load_calibration(tmp_path / "cal.json")
    assert back.windows == run.calibration.windows and back.input_units == "deg/s"
    np.testing.assert_allclose(back.correction[0], run.calibration.correction[0])


def _random_session(rng: np.random.Generator):
    """Paper turns plus up to three extra ones in random order, waits of 0 to 20 s, random
    ramps, vibration, speed, misalignment, sample rate; a fifth are hand sessions, a third in counts."""
    turns = [str(t) for t in [*PAPER_TURNS, *rng.choice(PAPER_TURNS, rng.integers(0, 4))]]
    rng.shuffle(turns)
    waits = [float(w) for w in rng.choice([0.0, 0.3, 1.0, 5.0, 20.0], len(turns) - 1)]
    hand = rng.uniform() < 0.2
    if hand:
        waits = [max(w, 1.5) for w in waits]
        p = ServoProtocol.hand(turns=tuple(turns), wait=tuple(waits), misalignment_deg=rng.uniform(0, 10),
                               speed=math.radians(rng.uniform(60, 300)))
    else:
        p = ServoProtocol(turns=tuple(turns), wait=tuple(waits), misalignment_deg=rng.uniform(0, 10),
                          vibration=rng.uniform(0, 0.08), ramp=rng.uniform(0, 0.8),
                          speed=math.radians(rng.uniform(30, 120)))
    fs = float(rng.choice([50.0, 100.0, 200.0]))
    rec, _ = simulate_servo(GYRO, p, sample_rate=fs, rng=rng)
    truth = TRUE
    if rng.uniform() < 0.3:
        lsb = 16.4 * 180 / math.pi
        rec = Recording(t=rec.t, gyro=np.round(rec.gyro * lsb), units="counts", source_units="counts")
        truth = np.concatenate([K / lsb, B * lsb])
    return rec, p, turns, waits, hand, truth


def test_random_sessions_find_every_turn_and_the_truth(rng):
    """Many protocols: every turn is found (two turns about one axis and sense with no wait
    at all may read as one 720 deg turn with --angle) and the truth lies within 4 sigma. The 1-sigma is judged
    two-sided: the RMS of all z (about 270) within 4 sd of the RMS of that many normals, 1 +- 4 / sqrt(2 m)."""
    zs = []
    for _ in range(25):
        rec, p, turns, waits, hand, truth = _random_session(rng)
        for ref in ("angle",) if hand else ("speed", "angle"):
            run = calibrate(rec, **({"speed": p.speed} if ref == "speed" else {"angle": 2 * math.pi}))
            labels = [w.label for w in run.segmentation.rotations]
            joined = {i for i, w in enumerate(waits) if w == 0 and turns[i] == turns[i + 1]} if ref == "angle" else set()
            joined |= {i + 1 for i in joined}
            assert labels in (turns, [t for i, t in enumerate(turns) if i not in joined]), (p, ref)
            z = (run.fit.model.params - truth) / run.fit.std
            assert np.all(np.abs(z) < 4), (p, ref, z)
            zs.append(z)
    rms = float(np.sqrt(np.mean(np.square(zs))))
    assert abs(rms - 1) < 4 / math.sqrt(2 * np.size(zs)), rms


def test_turns_too_short_for_a_plateau_point_to_the_angle_reference(rng):
    fast = ServoProtocol(speed=math.radians(300.0))
    rec, _ = simulate_servo(GYRO, fast, sample_rate=FS, rng=rng)
    with pytest.raises(SegmentationError, match=r"6 no plateau.*calibrate with the angle reference \(angle 360\)"):
        calibrate(rec, speed=fast.speed)
    _within_4_sigma(calibrate(rec, angle=2 * math.pi))
