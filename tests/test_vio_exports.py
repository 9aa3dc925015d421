"""Kalibr, VINS and imu_utils noise files from a noise report.

References: the field names, units and meanings documented by each tool (Kalibr wiki "IMU Noise
Model"; VINS-Mono integration_base.h, where the values act per sample at the IMU rate; imu_utils
imu_an.cpp writeYAML: Allan deviation at tau = 1 s and its minimum), checked against the report's
own figures, which test_noise.py checks against the simulated truth.
"""

import math

import numpy as np
import pytest
import yaml

from gyrocal.errors import InputError
from gyrocal.flight import imu_utils_yaml, kalibr_yaml, vins_yaml
from gyrocal.noise import characterise

# IEEE Std 952-1997, Annex C: a flicker floor of the Allan deviation sits at sqrt(2 ln 2 / pi) B = 0.6643 B
FLICKER_FLOOR = math.sqrt(2 * math.log(2) / math.pi)

FS = 100.0


@pytest.fixture(scope="module")
def report():
    """Gyro and accelerometer with white noise and a bias random walk strong enough to be seen in 40 min."""
    rng = np.random.default_rng(11)
    n = int(2400 * FS)
    g = rng.standard_normal((n, 3)) * 0.005 + np.cumsum(rng.standard_normal((n, 3)) * 2e-4 / math.sqrt(FS), axis=0)
    a = 9.81 * np.array([0, 0, 1.0]) + rng.standard_normal((n, 3)) * 0.02
    a += np.cumsum(rng.standard_normal((n, 3)) * 1e-3 / math.sqrt(FS), axis=0)
    return characterise(g, FS, accel=a, source={"file": "rest.csv"})


def test_kalibr_imu_yaml_holds_the_sensor_figures(report):
    doc = yaml.safe_load(kalibr_yaml(report, rostopic="/imu0", inflate=2.0))
    assert set(doc) == {"accelerometer_noise_density", "accelerometer_random_walk", "gyroscope_noise_density",
                        "gyroscope_random_walk", "rostopic", "update_rate"}
    assert doc["rostopic"] == "/imu0" and doc["update_rate"] == FS
    pairs = [("gyroscope_noise_density", report.gyro.density), ("gyroscope_random_walk", report.gyro.random_walk),
             ("accelerometer_noise_density", report.accel.density),
             ("accelerometer_random_walk", report.accel.random_walk)]
    for key, figure in pairs:
        assert doc[key] == pytest.approx(2.0 * figure.value[3], rel=1e-6), key
    # the truth behind them (continuous time): 0.005/sqrt(100), 2e-4; 0.02/sqrt(100), 1e-3, times inflate
    assert doc["gyroscope_noise_density"] == pytest.approx(2 * 5e-4, rel=0.02)
    assert doc["gyroscope_random_walk"] == pytest.approx(2 * 2e-4, rel=0.3)
    assert "inflate: 2" in kalibr_yaml(report, inflate=2.0)


def test_vins_block_is_per_sample(report):
    doc = yaml.safe_load(vins_yaml(report, update_rate=200.0))
    root = math.sqrt(200.0)
    assert doc["gyr_n"] == pytest.approx(report.gyro.density.value[3] * root, rel=1e-6)
    assert doc["acc_n"] == pytest.approx(report.accel.density.value[3] * root, rel=1e-6)
    assert doc["gyr_w"] == pytest.approx(report.gyro.random_walk.value[3] * root, rel=1e-6)
    assert doc["acc_w"] == pytest.approx(report.accel.random_walk.value[3] * root, rel=1e-6)
    # VINS grows the bias variance by dt^2 gyr_w^2 per step: per second that is random_walk^2
    dt = 1 / 200.0
    assert doc["gyr_w"] ** 2 * dt**2 / dt == pytest.approx(report.gyro.random_walk.value[3] ** 2, rel=1e-5)


def test_imu_utils_layout(report):
    text = imu_utils_yaml(report, name="bmi088")
    assert text.startswith("%YAML:1.0\n")
    doc = yaml.safe_load(text.split("\n", 1)[1])
    assert doc["type"] == "IMU" and doc["name"] == "bmi088" and doc["Gyr"]["unit"] == " rad/s"
    for block, short, sensor in (("Gyr", "gyr", report.gyro), ("Acc", "acc", report.accel)):
        for i, axis in enumerate("xyz"):
            entry = doc[block][f"{axis}-axis"]
            assert entry[f"{short}_n"] == pytest.approx(sensor.density.value[i], rel=1e-12)
            floor = sensor.bias_instability.value[i] * FLICKER_FLOOR  # imu_utils' *_w: the Allan minimum itself
            assert entry[f"{short}_w"] == pytest.approx(floor, rel=1e-12)
            assert floor == pytest.approx(sensor.adev[i].min(), rel=1e-12)
        assert doc[block]["avg-axis"][f"{short}_n"] == pytest.approx(sensor.density.value[:3].mean(), rel=1e-12)


def test_missing_accelerometer_and_unseen_random_walk_are_never_invented(rng):
    short = characterise(rng.standard_normal((20_000, 3)) * 0.005, FS)
    with pytest.raises(InputError, match="no accelerometer figures.*accel_noise_density"):
        kalibr_yaml(short)
    with pytest.raises(InputError, match="gyroscope random walk is not seen.*use_bound"):
        kalibr_yaml(short, accel_noise_density=2e-3, accel_random_walk=4e-4)
    doc = yaml.safe_load(kalibr_yaml(short, accel_noise_density=2e-3, accel_random_walk=4e-4, use_bound=True))
    assert doc["gyroscope_random_walk"] == pytest.approx(short.gyro.random_walk_bound[3])
    assert doc["accelerometer_noise_density"] == 2e-3
    text = imu_utils_yaml(characterise(rng.standard_normal((200_000, 3)) * 0.005
                                       + np.cumsum(rng.standard_normal((200_000, 3)) * 3e-5, axis=0), FS))
    assert "no Acc block" in text and "Acc:" not in text
    with pytest.raises(InputError, match="inflate must be a factor >= 1"):
        kalibr_yaml(short, inflate=0.5, accel_noise_density=1.0, accel_random_walk=1.0, use_bound=True)
