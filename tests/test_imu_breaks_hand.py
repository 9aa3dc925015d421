"""Issue 22, items 4 and 7: logs glued from parts out of order, and poses held by hand.

Sessions come from the closed-form multi-position simulator (minimum-jerk moves, sensors read at
the true times); the defects are added here, independently of gyrocal's detector:

* a glued log: the simulated samples cut at points inside poses and moves, the parts written out
  of order with a ``samples`` counter (as imucal's annotated session);
* a hand: tremor of 1-2 deg/s at 8-12 Hz about a random axis in every pose after a table rest,
  its tilt seen by the accelerometer and its angular acceleration at a 10 cm lever arm.
"""

import numpy as np
import pytest

from gyrocal.imu import calibrate_imu
from gyrocal.imu.gyro import PairCheck, _beyond_noise
from gyrocal.imu.run import calibrate_recording
from gyrocal.io import read_recording
from gyrocal.models import Affine
from gyrocal.recording.breaks import spans_break
from gyrocal.simulation.gyro import VirtualGyro
from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position


def _imu(rng, gyro_noise=np.radians(0.05), accel_noise=0.03):
    k = np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3))
    gyro = VirtualGyro(Affine(k, np.radians(rng.normal(0, 0.5, 3))), noise_std=gyro_noise)
    a = np.tril(np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3)))
    return VirtualImu(gyro, accel_matrix=a, accel_offset=rng.normal(0, 0.2, 3), accel_noise_std=accel_noise)


def _write(path, s, order=None, cuts=()):
    """The session as CSV (gyro deg/s, accel m/s^2, a samples counter), its parts in `order`."""
    n = len(s.t)
    edges = [0, *cuts, n]
    parts = [np.arange(a, b) for a, b in zip(edges[:-1], edges[1:])]
    rows = np.concatenate([parts[i] for i in (order or range(len(parts)))])
    table = np.column_stack([rows, np.degrees(s.gyro[rows]), s.accel[rows]])
    np.savetxt(path, table, delimiter=",", header="samples,gx,gy,gz,ax,ay,az", comments="",
               fmt=["%d"] + ["%.9g"] * 6)
    return path


def _run(path, fs=100.0):
    rec = read_recording(path, units="deg/s", sample_rate=fs, accel_units="m/s^2")
    return rec, calibrate_recording(rec)


@pytest.fixture(scope="module")
def glued(tmp_path_factory):
    rng = np.random.default_rng(22)
    proto = MultiPositionProtocol(poses=16, static_duration=(2.0, 3.0), latitude_deg=None)
    s = simulate_multi_position(_imu(rng), proto, rng=rng)
    # cut inside pose 5, inside the move 9 -> 10 and inside pose 13
    (a5, b5), (_, b9), (a10, _), (a13, b13) = s.still[4], s.still[8], s.still[9], s.still[12]
    cuts = [(a5 + b5) // 2, (b9 + a10) // 2, (a13 + b13) // 2]
    d = tmp_path_factory.mktemp("glued")
    return s, _run(_write(d / "whole.csv", s)), _run(_write(d / "glued.csv", s, [0, 2, 1, 3], cuts)), cuts


def test_the_glued_log_reports_its_breaks_and_no_pose_spans_one(glued):
    s, _, (rec, run), cuts = glued
    assert len(rec.breaks) == 3 and rec.breaks[0] == cuts[0]  # the counter's jumps, where the parts meet
    lines = run.time_base.describe()
    assert any("not contiguous: 3 break(s)" in line for line in lines)
    assert list(run.calibration.observed["time_base"]["breaks"]) == list(rec.breaks)
    assert all(not spans_break(p.start, p.stop, rec.breaks) for p in run.result.statics)
    assert sum("not contiguous in the move" in w for w in run.warnings) >= 3


def test_the_glued_log_calibrates_as_the_whole_one_within_one_sigma(glued):
    """Reference: the same samples in order. Gyro and accelerometer parameters agree within the glued log's
    1-sigma (it lost the pose pairs across its breaks): RMS of the differences under 1 sigma, none over 1.5."""
    _, (_, whole), (_, part), _ = glued
    for a, b in ((whole.result.gyro, part.result.gyro), (whole.result.accel, part.result.accel)):
        z = (a.params - b.params) / b.std
        assert np.sqrt(np.mean(z**2)) < 1.0 and np.abs(z).max() < 1.5, z


def test_a_glued_log_without_its_counter_is_flagged_beyond_its_noise(glued, tmp_path):
    """The same glued samples with no counter: the moves across the cuts join unrelated poses; they are
    judged in noise units (never 'none disagrees')."""
    s, _, _, cuts = glued
    path = _write(tmp_path / "nocount.csv", s, [0, 2, 1, 3], cuts)
    text = path.read_text().splitlines()
    path.write_text("\n".join(",".join(r.split(",")[1:]) for r in text) + "\n")
    _, run = _run(path)
    checks = run.result.gyro.checks
    assert sum(c.beyond_noise for c in checks) >= 2
    assert all(c.beyond_noise for c in checks if c.residual_deg > 5)


def test_a_44_degree_misfit_is_never_within_its_noise():
    """Reference: imucal's annotated session read as contiguous, every turn off by about 44 deg."""
    deg = np.radians(1.0)
    checks = [PairCheck("pair", f"pose {i} -> {i + 1}", 0.0, 1.0, 90.0, 44.0 + i, 1.0, 0.6, (i, i + 1),
                        (44.0 * deg / (0.05 * deg)) ** 2) for i in range(6)]
    assert all(c.beyond_noise and not c.disagrees for c in checks)
    (line,) = _beyond_noise(checks)
    assert "median 46 deg" in line and "6 of 6 are beyond it" in line and "do not trust" in line


def _tremor(s, rng, lever=0.1):
    """Gyro and accelerometer readings with a hand's tremor in every pose after the first (the table)."""
    gyro, accel = s.gyro.copy(), s.accel.copy()
    k = np.linalg.inv(s.truth["gyro_matrix"])
    a_inv = np.linalg.inv(s.truth["accel_matrix"])
    for a, b in s.still[1:]:
        t = s.t[a:b] - s.t[a]
        amp, f, phase = np.radians(rng.uniform(1.0, 2.0)), rng.uniform(8.0, 12.0), rng.uniform(0, 2 * np.pi)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        arg = 2 * np.pi * f * t + phase
        w = amp * np.sin(arg)[:, None] * axis
        theta = amp / (2 * np.pi * f) * (np.cos(phase) - np.cos(arg))[:, None] * axis
        alpha = amp * 2 * np.pi * f * np.cos(arg)[:, None] * axis
        force = (accel[a:b] - s.truth["accel_offset"]) @ s.truth["accel_matrix"].T
        change = -np.cross(theta, force) + np.cross(alpha, [0.0, 0.0, lever])
        gyro[a:b] += w @ k.T
        accel[a:b] += change @ a_inv.T
    return gyro, accel


def _hand(seed):
    rng = np.random.default_rng(seed)
    proto = MultiPositionProtocol(poses=12, turn_deg=None, first_static=37.0, static_duration=(2.0, 3.0),
                                  latitude_deg=None)
    s = simulate_multi_position(_imu(rng), proto, rng=rng)
    return s, *_tremor(s, rng)


def _z(r, truth):
    acc = np.concatenate([truth["accel_matrix"][np.tril(np.ones((3, 3), bool))], truth["accel_offset"]])
    gyr = np.concatenate([truth["gyro_matrix"].ravel(), truth["gyro_offset"]])
    return np.concatenate([(r.accel.params - acc) / r.accel.std, (r.gyro.params[:12] - gyr) / r.gyro.std[:12]])


def test_poses_held_by_hand_are_found_and_calibrate_within_their_uncertainty():
    """Reference: the simulated truth. The table's thresholds find the table alone; the sweep keeps a
    multiplier that finds every pose, says which, and both sensors land within their 1-sigma (RMS z over
    5 sessions x 21 parameters, two-sided: 0.81 over 10 sessions, 0.54 before tremor could average out)."""
    zs = []
    for seed in range(5):
        s, gyro, accel = _hand(300 + seed)
        r = calibrate_imu(s.t, gyro, accel)
        assert len(r.statics) >= 10 and r.detection.multiplier > 1
        assert len(r.detection.sweep) > 1 and r.detection.sweep[0][1] < 4  # x1: the table rest, little else
        zs.append(_z(r, s.truth))
    z = np.concatenate(zs)
    assert 0.6 < np.sqrt(np.mean(z**2)) < 1.35, z
    assert np.abs(z).max() < 4.5


def test_the_threshold_override_is_used_and_said(tmp_path):
    s, gyro, accel = _hand(310)
    r = calibrate_imu(s.t, gyro, accel, threshold=300.0)
    assert r.detection.multiplier == 300.0 and len(r.detection.sweep) == 1 and len(r.statics) >= 10
    with pytest.raises(Exception, match="still pose"):
        calibrate_imu(s.t, gyro, accel, threshold=1.0)


def test_calibrate_leaves_out_turns_across_a_break_and_cuts_static_windows():
    from gyrocal.segmentation import Segmentation
    from gyrocal.segmentation.screening import screen_breaks
    from gyrocal.segmentation.windows import Window

    seg = Segmentation(windows=(Window(0, 100, "static"), Window(100, 200, "rotation", "z", 1), Window(200, 300, "static")))
    out = screen_breaks(seg, [150, 250])
    assert [(w.start, w.stop, w.kind) for w in out.windows] == [(0, 100, "static"), (200, 250, "static"),
                                                                 (250, 300, "static")]
    assert len(out.ignored) == 1 and "not contiguous inside the turn" in out.ignored[0][1]


def test_time_stepping_back_between_parts_is_read_as_breaks(tmp_path):
    """Parts of a stamped log glued out of order: laid end to end, one period apart; jitter is still refused."""
    t = np.arange(300) / 100.0
    t = np.concatenate([t[200:], t[:200]])
    path = tmp_path / "back.csv"
    np.savetxt(path, np.column_stack([t, np.zeros((300, 3))]), delimiter=",", header="t,gx,gy,gz", comments="")
    rec = read_recording(path, units="deg/s")
    assert rec.breaks == (100,) and np.allclose(np.diff(rec.t), 0.01)
    assert rec.time_base().breaks == (100,)


def test_the_cli_says_which_threshold_it_used(tmp_path):
    from gyrocal.cli.app import run

    s, gyro, accel = _hand(311)
    s = type(s)(s.t, gyro, accel, s.still, s.orientations, s.truth)
    path, out = _write(tmp_path / "hand.csv", s), tmp_path / "cal.json"
    assert run(["imu", str(path), "--units", "deg/s", "--accel-units", "m/s^2", "--sample-rate", "100",
                "--threshold", "300", "-o", str(out)]) == 0
    import json

    det = json.loads(out.read_text())["accelerometer"]["poses"]["detection"]
    assert det["multiplier"] == 300 and det["given"] and det["sweep"][0]["poses"] >= 10
