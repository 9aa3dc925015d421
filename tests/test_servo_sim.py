"""The servo and hand-turn simulator: exact turn angles, plateaus, vibration, mounting.

References: the commanded protocol (angles, waits, speeds, tilt) and the gyro model's noise statistics.
"""

import math

import numpy as np
import pytest

from gyrocal.errors import InputError
from gyrocal.models import ScaleBias
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo

# The servo method of Wang et al., Table III (MPU9250).
MPU9250 = ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076])
FS = 200.0


def _turned(truth, w) -> float:
    return float(np.linalg.norm(truth.rates[w.start:w.stop].sum(axis=0)) / FS)


@pytest.mark.parametrize("protocol", [
    ServoProtocol(misalignment_deg=10.0),
    ServoProtocol(ramp=0.0, vibration=0.0, revolutions=2.0),
    ServoProtocol(turns=("+x", "+x", "-z"), wait=(0.4, 7.0), vibration=0.2, ramp=1.0),
    ServoProtocol.hand(),
])
def test_every_turn_turns_exactly_the_protocol_angle(protocol, rng):
    _, truth = simulate_servo(VirtualGyro(MPU9250), protocol, sample_rate=FS, rng=rng)
    turns = [w for w in truth.windows if w.kind == "rotation"]
    assert [w.label for w in turns] == list(protocol.turns)
    for w in turns:
        assert _turned(truth, w) == pytest.approx(protocol.turn_angle, rel=1e-12)
        assert w.angle == protocol.turn_angle
        assert w.rate == pytest.approx(w.angle * FS / len(w), rel=1e-12)


def test_static_windows_do_not_move_and_cover_the_gaps(rng):
    p = ServoProtocol(wait=(3.0, 0.5, 10.0, 3.0, 3.0))
    _, truth = simulate_servo(VirtualGyro(MPU9250), p, sample_rate=FS, rng=rng)
    statics = [w for w in truth.windows if w.kind == "static"]
    assert [len(w) for w in statics] == [400, 600, 100, 2000, 600, 600, 400]
    for w in statics:
        assert not np.any(truth.rates[w.start:w.stop])
    assert sum(len(w) for w in truth.windows) == len(truth.rates)


def test_plateau_mean_speed_is_the_commanded_speed(rng):
    """Vibration is a bounded angle error, so the plateau mean errs by at most 2 * amplitude / T."""
    p = ServoProtocol(vibration=0.05, misalignment_deg=3.0)
    _, truth = simulate_servo(VirtualGyro(MPU9250), p, sample_rate=FS, rng=rng)
    assert len(truth.plateaus) == 6
    for w in truth.plateaus:
        rates = np.linalg.norm(truth.rates[w.start:w.stop], axis=1)
        amplitude = p.vibration * p.speed / (2 * np.pi * p.vibration_freq) + 4 * p.vibration * p.speed / (2 * FS)
        assert abs(rates.mean() - p.speed) <= 2 * amplitude / (len(w) / FS)
        # The jitter is there: RMS of the order of vibration * speed.
        assert 0.3 * p.vibration * p.speed < rates.std() < 1.5 * p.vibration * p.speed


def test_mounting_misalignment_tilts_every_turn_axis_by_the_given_angle(rng):
    p = ServoProtocol(misalignment_deg=10.0, vibration=0.0)
    _, truth = simulate_servo(VirtualGyro(MPU9250), p, sample_rate=FS, rng=rng)
    for w in (w for w in truth.windows if w.kind == "rotation"):
        v = truth.rates[w.start:w.stop].sum(axis=0)
        j = "xyz".index(w.axis)
        tilt = math.degrees(math.acos(w.sign * v[j] / np.linalg.norm(v)))
        assert 0 < tilt <= 10.0 + 1e-9
    np.testing.assert_allclose(truth.mounting @ truth.mounting.T, np.eye(3), atol=1e-12)


def test_readings_follow_the_gyro_model(rng):
    gyro = VirtualGyro(MPU9250, noise_std=0.035)
    rec, truth = simulate_servo(gyro, ServoProtocol(), sample_rate=FS, rng=rng)
    assert rec.sample_rate == FS and rec.has_time and rec.units == "rad/s"
    err = rec.gyro - MPU9250.distort(truth.rates)
    n = len(err)
    assert np.all(np.abs(err.mean(axis=0)) < 4 * 0.035 / np.sqrt(n))
    assert np.all(np.abs(err.std(axis=0) / 0.035 - 1) < 4 / np.sqrt(2 * n))
    assert truth.model is MPU9250


def test_hand_turns_are_uneven_with_pauses(rng):
    p = ServoProtocol.hand()
    _, truth = simulate_servo(VirtualGyro(MPU9250), p, sample_rate=FS, rng=rng)
    assert truth.plateaus == ()
    for w in (w for w in truth.windows if w.kind == "rotation"):
        speed = np.linalg.norm(truth.rates[w.start:w.stop], axis=1)
        still = speed == 0
        # Three pauses of pause_length inside every turn.
        edges = np.flatnonzero(np.diff(still.astype(int)) == 1)
        assert len(edges) == p.pauses
        moving = speed[~still]
        assert moving.std() / moving.mean() > 0.2


@pytest.mark.parametrize("kwargs, match", [
    ({"turns": ("+x", "+w")}, "'\\+w' is not one of"),
    ({"turns": ()}, "turns is empty"),
    ({"misalignment_deg": 12.0}, "misalignment_deg"),
    ({"wait": (1.0, 2.0)}, "one per gap"),
    ({"speed": 0.0}, "speed"),
    ({"ramp": -1.0}, "ramp"),
    ({"pauses": 1.5}, "pauses"),
])
def test_protocol_refuses_bad_settings(kwargs, match):
    with pytest.raises(InputError, match=match):
        ServoProtocol(**kwargs)


def test_paper_turns_are_the_six_point_design():
    assert ServoProtocol().turns == PAPER_TURNS == ("+x", "-x", "+y", "-y", "+z", "-z")
    assert ServoProtocol().speed == pytest.approx(math.radians(60))
