"""Automatic segmentation on simulated servo and hand sessions, and on the real imucal session."""

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

import gyrocal
from gyrocal.errors import InputError, SegmentationError
from gyrocal.models import ScaleBias
from gyrocal.pipeline import calibrate
from gyrocal.recording import Recording
from gyrocal.segmentation import Segmentation, segment
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo

MPU9250 = ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076])  # the servo method of Wang et al., Table III
GYRO = VirtualGyro(MPU9250, noise_std=0.035)
FS = 200.0
SPEED = math.radians(60.0)
FERRARIS = Path(gyrocal.__file__).parent / "data" / "imucal_ferraris"

# Extra and repeated turns, long and short static gaps (0.4 s between two +x turns).
MESSY = ServoProtocol(turns=PAPER_TURNS + ("+x", "+x", "-y"), wait=(3.0, 0.6, 12.0, 3.0, 3.0, 2.0, 0.4, 1.5),
                      misalignment_deg=10.0, ramp=0.5, vibration=0.05)


def _session(protocol=MESSY, rng=None):
    return simulate_servo(GYRO, protocol, sample_rate=FS, rng=rng)


def _inside(inner, outer, slack=0) -> bool:
    return outer.start - slack <= inner.start and inner.stop <= outer.stop + slack


def test_speed_reference_finds_each_plateau_and_trims_the_ramps(rng):
    rec, truth = _session(rng=rng)
    seg = segment(rec, reference="speed", speed=SPEED)
    rot = seg.rotations
    assert [w.label for w in rot] == list(MESSY.turns)
    for w, plateau in zip(rot, truth.plateaus):
        assert _inside(w, plateau)  # no ramp sample in the window
        assert len(w) >= 0.85 * len(plateau)  # and little plateau lost
        assert (w.axis, w.sign, w.rate) == (plateau.axis, plateau.sign, SPEED)
        assert w.angle == pytest.approx(SPEED * len(w) / FS)


def test_angle_reference_takes_whole_turns_kept_tight(rng):
    rec, truth = _session(rng=rng)
    seg = segment(rec, reference="angle", angle=2 * math.pi)
    turns = [w for w in truth.windows if w.kind == "rotation"]
    assert [w.label for w in seg.rotations] == [w.label for w in turns]
    for w, turn in zip(seg.rotations, turns):
        assert _inside(turn, w)  # the whole turn is inside: its angle is exact
        assert w.start >= turn.start - 0.2 * FS and w.stop <= turn.stop + 0.2 * FS  # tight
        assert w.angle == 2 * math.pi and w.rate == pytest.approx(2 * math.pi * FS / len(w))


@pytest.mark.parametrize("reference", ["speed", "angle"])
def test_static_windows_sit_inside_the_still_stretches(reference, rng):
    rec, truth = _session(rng=rng)
    seg = segment(rec, reference=reference, speed=SPEED)
    truth_static = [w for w in truth.windows if w.kind == "static"]
    for w in seg.statics:
        assert any(_inside(w, s) for s in truth_static)
    # Every gap of at least 1 s yields a window; the 0.4 s and 0.6 s gaps are too short after trimming.
    long_gaps = [s for s in truth_static if len(s) >= FS]
    assert len(seg.statics) == len(long_gaps)
    assert all("short static" in reason for _, reason in seg.ignored)


def test_missing_time_column_segments_the_same(rng):
    rec, _ = _session(rng=rng)
    no_time = Recording.from_rate(rec.gyro, FS)
    for kwargs in ({"reference": "speed", "speed": SPEED}, {"reference": "angle"}):
        a, b = segment(rec, **kwargs), segment(no_time, **kwargs)
        assert a.windows == b.windows


@pytest.mark.parametrize("reference", ["speed", "angle"])
def test_counts_without_sensitivity_segment_like_rad_per_s(reference, rng):
    rec, _ = _session(rng=rng)
    lsb = 16.4 * 180 / math.pi  # MPU9250 at +-2000 deg/s: 16.4 LSB per deg/s
    counts = Recording(t=rec.t, gyro=np.round(rec.gyro * lsb), units="counts", source_units="counts")
    a = segment(rec, reference=reference, speed=SPEED)
    b = segment(counts, reference=reference, speed=SPEED)
    assert [(w.label, w.kind) for w in b.windows] == [(w.label, w.kind) for w in a.windows]
    for wa, wb in zip(a.windows, b.windows):
        assert abs(wa.start - wb.start) <= 2 and abs(wa.stop - wb.stop) <= 2


def test_hand_session_with_pauses_joins_the_pieces_of_each_turn(rng):
    rec, truth = _session(ServoProtocol.hand(wait=(4.0, 9.0)), rng)
    seg = segment(rec, reference="angle")
    turns = [w for w in truth.windows if w.kind == "rotation"]
    assert [w.label for w in seg.rotations] == ["+x", "+y", "+z"]
    for w, turn in zip(seg.rotations, turns):
        assert _inside(turn, w) and w.start >= turn.start - 0.2 * FS and w.stop <= turn.stop + 0.2 * FS
    assert len(seg.statics) == 4


def test_hand_session_has_no_plateau_for_a_speed_reference(rng):
    rec, _ = _session(ServoProtocol.hand(), rng)
    seg = segment(rec, reference="speed", speed=math.radians(150), require=False)
    assert seg.rotations == ()
    turns = [r for w, r in seg.ignored if w.kind == "rotation"]
    assert len(turns) >= 3
    assert all(r.startswith(("speed not constant", "no plateau", "wrong speed")) for r in turns)


def test_wrong_declared_speed_is_ignored_with_the_measured_speed(rng):
    """60 deg/s turns declared as 20 deg/s would need k = 1/3, outside the 0.45-2.2 a gyro may have."""
    rec, _ = _session(ServoProtocol(), rng)
    with pytest.raises(SegmentationError) as err:
        segment(rec, reference="speed", speed=math.radians(20))
    msg = str(err.value)
    assert "rotations none" in msg and "ignored 6 (6 wrong speed)" in msg and "no rotation about x, y, z" in msg
    seg = segment(rec, reference="speed", speed=math.radians(20), require=False)
    assert re.search(r"turned at (59|60)\.\d deg/s, declared 20 deg/s: that is a scale factor of 0\.33\d, "
                     r"outside 0\.45-2\.2", seg.ignored[0][1])


def test_wrong_declared_angle_is_ignored(rng):
    rec, _ = _session(ServoProtocol(), rng)
    seg = segment(rec, reference="angle", angle=math.pi / 2, require=False)
    assert seg.rotations == ()
    assert len(seg.ignored) == 6
    assert all(re.search(r"wrong angle: turned 3[56]\d deg, declared 90 deg: that is a scale factor of 0\.2\d",
                         r) for _, r in seg.ignored)


def test_missing_axis_is_reported_with_what_was_found(rng):
    rec, _ = _session(ServoProtocol(turns=("+x", "-x", "+y", "-y")), rng)
    with pytest.raises(SegmentationError, match=r"found rotations \+x, -x, \+y, -y; 5 static window\(s\): "
                                                 r"no rotation about z; .*most likely: turn about the missing axes"):
        segment(rec, reference="speed", speed=SPEED)


def test_one_sense_without_static_is_reported(rng):
    p = ServoProtocol(turns=("+x", "+y", "+z"), wait=0.4, lead_in=0.2, lead_out=0.2)
    rec, _ = _session(p, rng)
    found = r"found rotations \+x, \+y, \+z; 0 static window\(s\)(; ignored \d \(\d short static\))?: "
    with pytest.raises(SegmentationError, match=found + "only one sense about x, y, z and no static window"):
        segment(rec, reference="angle")


def test_summary_lists_windows_and_reasons(rng):
    rec, _ = _session(rng=rng)
    text = segment(rec, reference="speed", speed=SPEED).summary()
    first = text.splitlines()[0]
    assert first.startswith("rotations +x x3, -x, +y, -y x2, +z, -z; 8 static window(s); ignored 2 (2 short static)")
    assert text.count("rotation ") == 9 and "60.000" in text


def test_bad_arguments_are_refused(rng):
    rec, _ = _session(ServoProtocol(), rng)
    with pytest.raises(InputError, match="reference must be 'speed' or 'angle'"):
        segment(rec, reference="gps")
    with pytest.raises(InputError, match="needs the known speed"):
        segment(rec, reference="speed")
    with pytest.raises(InputError, match="angle"):
        segment(rec, reference="angle", angle=0.0)


def test_segmentation_sorts_its_windows():
    from gyrocal.segmentation.windows import Window

    seg = Segmentation((Window(50, 60, "static"), Window(0, 10, "rotation", "x", 1)))
    assert [w.start for w in seg.windows] == [0, 50]
    assert seg.rotations[0].axis == "x" and len(seg.statics) == 1


@pytest.fixture(scope="module")
def ferraris():
    from gyrocal.io import read_recording, read_windows

    rec = read_recording(FERRARIS / "example_ferraris_session.csv", units="deg/s",
                         columns={"gx": "gyr_x", "gy": "gyr_y", "gz": "gyr_z"}, sample_rate=102.4)
    return rec, read_windows(FERRARIS / "example_ferraris_session_list.json", sample_rate=102.4)


def test_real_hand_session_matches_its_section_list(ferraris):
    """imucal's hand session: four 90 deg pieces per turn, re-poses between, at 102.4 Hz in deg/s."""
    rec, listed = ferraris
    seg = segment(rec, reference="angle", angle=2 * math.pi)
    by_label = {w.label: w for w in listed}
    assert [w.label for w in seg.rotations] == ["-x", "-y", "-z"]
    for w, name in zip(seg.rotations, ("x_rot", "y_rot", "z_rot")):
        ref = by_label[name]
        assert abs(w.start - ref.start) <= 0.3 * rec.sample_rate and abs(w.stop - ref.stop) <= 0.3 * rec.sample_rate
    # Every listed static pose is mostly covered by one detected static window.
    for ref in (w for w in listed if w.kind == "static"):
        best = max(min(w.stop, ref.stop) - max(w.start, ref.start) for w in seg.statics)
        assert best >= 0.8 * len(ref), ref.label
    # The half turns and quarter turns between poses are reported with their measured angle, not used
    # (the 178 deg re-pose is not about one axis, which is said first).
    angles = sorted(round(float(m)) for m in re.findall(r"wrong angle: turned (\d+) deg", " ".join(r for _, r in seg.ignored)))
    assert angles == [90, 90, 92, 180, 187]


def test_segment_accepts_an_unused_time_jitter(rng):
    rec, _ = _session(ServoProtocol(), rng)
    jitter = rec.t + rng.uniform(0, 0.3 / FS, len(rec))
    bursty = dataclasses.replace(rec, t=jitter, sample_rate=FS)
    assert segment(bursty, reference="angle").windows == segment(rec, reference="angle").windows


@pytest.mark.parametrize("reference", ["speed", "angle"])
def test_turns_without_any_gap_are_split_at_the_turnaround(reference, rng):
    """+x straight into -x into +y...: no static gap at all, yet every turn is found."""
    p = ServoProtocol(wait=0.0, misalignment_deg=5.0)
    rec, truth = _session(p, rng)
    seg = segment(rec, reference=reference, speed=SPEED)
    assert [w.label for w in seg.rotations] == list(PAPER_TURNS)
    if reference == "angle":
        for w, turn in zip(seg.rotations, (t for t in truth.windows if t.kind == "rotation")):
            assert abs(w.start - turn.start) <= 0.2 * FS and abs(w.stop - turn.stop) <= 0.2 * FS


def test_real_session_calibrates_alike_from_detected_or_listed_windows(ferraris):
    rec, listed = ferraris
    auto = calibrate(rec, angle=2 * math.pi)
    given = calibrate(rec, angle=2 * math.pi, windows=listed)
    ka, kg = auto.fit.model.k, given.fit.model.k
    # Same turns, cut a few samples apart: scales within 0.1 %, biases within 0.01 deg/s.
    np.testing.assert_allclose(ka, kg, rtol=1e-3)
    np.testing.assert_allclose(np.degrees(auto.fit.model.b), np.degrees(given.fit.model.b), atol=0.01)
    assert auto.calibration.input_units == "deg/s" and "kx" in auto.report()


@pytest.mark.parametrize("vibration", [0.05, 0.0])
def test_long_log_with_a_tiny_share_of_rest_calibrates(vibration):
    """139 revolutions per turn, 3 s waits: rest is 0.4 % of the log, as in a 5 M-sample servo log at 1 kHz.

    The standstill level once came out as a rotation plateau (about 60 deg/s off) and no turn about
    two axes was found; a vibration-free servo's plateaus are as quiet as rest, so both are tried.
    """
    rec, truth = simulate_servo(GYRO, ServoProtocol(revolutions=139, vibration=vibration, misalignment_deg=5.0),
                                sample_rate=100.0, rng=np.random.default_rng(3))
    rest = np.concatenate([rec.gyro[w.start:w.stop] for w in truth.windows if w.kind == "static"])
    assert len(rest) < 0.005 * len(rec)
    run = calibrate(rec, speed=SPEED)
    assert [w.label for w in run.segmentation.rotations] == list(PAPER_TURNS)
    # the median of the quiet blocks' means against the mean of all rest: 6 sigma, half the rest in whole blocks
    tol = 6 * 1.6 * GYRO.noise_std / math.sqrt(len(rest) / 2)
    np.testing.assert_allclose(run.segmentation.baseline, rest.mean(axis=0), atol=tol)
    np.testing.assert_allclose(gyrocal.segmentation.standstill_level(rec), rest.mean(axis=0), atol=tol)
    np.testing.assert_allclose(run.fit.model.k, MPU9250.k, rtol=1e-3)
    np.testing.assert_allclose(run.fit.model.b, MPU9250.b, atol=1e-3)
