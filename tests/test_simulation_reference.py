"""The simulated reference log: its clock, its mounting and its noise.

Independent reference: the motion evaluated directly at the times the clock relation gives
(a motion linear in time between the test samples, so linear interpolation is exact),
turned by the transpose of the mounting rotation.
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from gyrocal import ScaleBias
from gyrocal.errors import InputError
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.reference import ReferenceTruth, simulate_reference

IDEAL = ScaleBias(k=(1.0, 1.0, 1.0), b=(0.0, 0.0, 0.0))


def _motion(t):
    """A motion linear in t on each axis: interpolation between test samples is exact."""
    return np.stack([0.1 * t, 1.0 - 0.05 * t, 0.3 + 0.02 * t], axis=1)


def test_reference_samples_the_motion_on_its_own_clock_and_frame(rng):
    t_test = np.arange(0, 30, 0.005)
    rot = Rotation.from_rotvec([0.2, -0.4, 0.1]).as_matrix()
    ref, truth = simulate_reference(t_test, _motion(t_test), VirtualGyro(model=IDEAL), sample_rate=100.0,
                                    time_offset_s=-2.5, clock_drift_ppm=300.0, mounting_rotation=rot, rng=rng)
    on_test_clock = ref.t * (1 + 300e-6) - 2.5
    assert on_test_clock[0] >= t_test[0] and on_test_clock[-1] <= t_test[-1]
    assert np.allclose(np.diff(ref.t), 0.01) and np.allclose(ref.t * 100, np.round(ref.t * 100))
    assert np.allclose(ref.gyro, _motion(on_test_clock) @ rot, atol=1e-12)  # w_ref = R^T w_test
    assert isinstance(truth, ReferenceTruth) and truth.mounting_rotation_deg == pytest.approx(
        math.degrees(np.linalg.norm([0.2, -0.4, 0.1])))


def test_truth_document_holds_the_clock_mounting_and_noise(rng):
    t_test = np.arange(0, 10, 0.01)
    _, truth = simulate_reference(t_test, _motion(t_test), VirtualGyro(model=IDEAL, noise_std=0.003),
                                  sample_rate=50.0, time_offset_s=1.25, clock_drift_ppm=-40.0, mounting_deg=12.0,
                                  rng=rng)
    doc = truth.to_dict()
    assert doc["time_offset_s"] == 1.25 and doc["clock_drift_ppm"] == -40.0 and doc["sample_rate"] == 50.0
    assert doc["mounting_rotation_deg"] == pytest.approx(12.0)
    assert doc["noise_std"] == [0.003] * 3 and np.allclose(doc["K"], np.eye(3))


def test_reference_noise_has_the_given_sigma(rng):
    t_test = np.arange(0, 200, 0.01)
    ref, _truth = simulate_reference(t_test, _motion(t_test) * 0, VirtualGyro(model=IDEAL, noise_std=0.004),
                                    sample_rate=100.0, rng=rng)
    sd = np.std(ref.gyro, axis=0)
    assert np.all(np.abs(sd - 0.004) < 4 * 0.004 / math.sqrt(2 * len(ref.gyro)))


@pytest.mark.parametrize("kwargs, match", [
    ({"mounting_rotation": np.diag([1.0, 1.0, -1.0])}, "proper rotation"),
    ({"sample_rate": 0.05}, "fewer than 2 samples"),
    ({"clock_drift_ppm": math.inf}, "finite"),
    ({"mounting_deg": 200.0}, "mounting_deg"),
    ({"sample_rate": 0.0}, "sample_rate"),
])
def test_bad_settings_are_refused(kwargs, match, rng):
    t_test = np.arange(0, 10, 0.01)
    with pytest.raises(InputError, match=match):
        simulate_reference(t_test, _motion(t_test), VirtualGyro(model=IDEAL), rng=rng, **kwargs)
