"""Steps and temperature points from turntable recordings, and the session's bad-input errors.

References: the turntable protocol's own steps and temperatures, and the simulated thermal truth.
"""

import numpy as np
import pytest

from gyrocal.errors import InputError
from gyrocal.io import read_session, write_csv
from gyrocal.recording import Recording
from gyrocal.simulation.thermal_truth import ThermalTruth
from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable
from gyrocal.thermal import (
    DroppedStepsWarning,
    SaturatedStepsWarning,
    calibrate_thermal,
    find_steps,
    session_steps,
)

NOISE = np.radians(0.05)
FAST = {"step_duration": 3.0, "rates": (0.0, 10.0, 100.0, 400.0)}


def _rec(rng, *, gyro_options=None, noise=NOISE, **protocol):
    proto = TurntableProtocol(**{**FAST, **protocol})
    return simulate_turntable(ThermalTruth().gyro(noise, **(gyro_options or {})), proto, sample_rate=50.0, rng=rng)


def _cut(rec: Recording, keep: np.ndarray) -> Recording:
    return Recording(t=rec.t[keep], gyro=rec.gyro[keep], temp=rec.temp[keep], table_rate=rec.table_rate[keep],
                     axis=rec.axis[keep], sample_rate=rec.sample_rate)


def test_steps_are_found_and_settling_is_dropped(rng):
    rec = _rec(rng, temps=(0.0, 20.0, 40.0))
    steps = find_steps(rec, settle=1.0)
    proto = TurntableProtocol(**FAST)
    assert len(steps) == 3 * proto.steps_per_point
    assert np.all(steps.count == 100)  # 3 s at 50 Hz minus 1 s
    assert np.all(rec.t[steps.start] - rec.t[steps.start - 50] == pytest.approx(1.0))
    np.testing.assert_allclose(steps.rate[:7], np.radians([0, 10, -10, 100, -100, 400, -400]))
    # white-noise variance from first differences matches the simulated noise within 4 sigma
    # (var of d^2 / 2 is 2 sigma^4, and neighbouring differences add half again: 3 sigma^4 per difference)
    assert abs(np.mean(steps.noise_var) - NOISE ** 2) < 4 * NOISE ** 2 * np.sqrt(3.0 / (99 * steps.noise_var.size))


def test_settle_must_not_be_negative(rng):
    with pytest.raises(InputError, match="settle"):
        find_steps(_rec(rng, temps=(0.0,)), settle=-1)


def test_recording_without_turntable_columns_is_refused(rng):
    rec = _rec(rng, temps=(0.0,))
    bare = Recording(t=rec.t, gyro=rec.gyro, temp=rec.temp)
    with pytest.raises(InputError, match="table_rate.*axis"):
        find_steps(bare)


def test_fewer_than_three_positions_is_an_error(rng):
    with pytest.raises(InputError, match=r"2 position\(s\) \(x, y\).*three"):
        session_steps([_rec(rng, temps=(0.0, 20.0, 40.0), axes=("x", "y"))], settle=1.0)


def test_too_few_temperature_points_is_an_error(rng):
    with pytest.raises(InputError, match="2 distinct temperature point.*at least 3"):
        session_steps([_rec(rng, temps=(0.0, 20.0))], settle=1.0)


def test_duplicate_temperature_points_are_an_error(rng):
    a, b = _rec(rng, temps=(0.0, 20.0)), _rec(rng, temps=(20.5, 40.0))
    with pytest.raises(InputError, match="duplicate temperature point: 20.*20.5.*b.csv"):
        session_steps([a, b], settle=1.0, names=["a.csv", "b.csv"])


def test_point_missing_rate_steps_is_an_error(rng):
    rec = _rec(rng, temps=(0.0, 20.0, 40.0))
    per_point = len(rec) // 3
    late = (np.arange(len(rec)) >= per_point) & (np.arange(len(rec)) < 2 * per_point)
    drop = late & (rec.axis == "y") & np.isclose(rec.table_rate, np.radians(-100))
    with pytest.raises(InputError, match=r"20\.0 degC is missing 1 rate step.*axis y -100 deg/s"):
        session_steps([_cut(rec, ~drop)], settle=1.0)


def test_saturated_steps_are_left_out_with_a_warning_naming_them(rng):
    rec = _rec(rng, temps=(0.0, 20.0, 40.0), gyro_options={"full_scale": np.radians(300.0)})
    with pytest.warns(SaturatedStepsWarning, match=r"18 step\(s\).*0\.0 degC, axis x, \+400 deg/s"):
        steps = session_steps([rec], settle=1.0, full_scale=np.radians(300.0))
    assert not np.any(np.isclose(np.abs(steps.rate), np.radians(400.0)))
    with pytest.warns(SaturatedStepsWarning):
        _cal, fit = calibrate_thermal([rec], settle=1.0, full_scale=np.radians(300.0))
    assert len(fit.steps) == 3 * (3 * 7 - 6)  # +-400 deg/s left out at every position


def test_unsettled_steps_are_dropped(rng):
    rec = _rec(rng, temps=(0.0, 20.0, 40.0))
    temp = np.array(rec.temp)
    temp[:150] = np.linspace(-10, 0, 150)  # the chamber still moving during the first step
    moved = Recording(t=rec.t, gyro=rec.gyro, temp=temp, table_rate=rec.table_rate, axis=rec.axis)
    with (pytest.warns(DroppedStepsWarning, match="span more than 2 degC"),
          pytest.raises(InputError, match="missing 1 rate step")):
        session_steps([moved], settle=1.0)


def test_folder_session_matches_single_file(rng, tmp_path):
    recs = [_rec(rng, temps=(t,)) for t in (0.0, 20.0, 40.0)]
    for i, r in enumerate(recs):
        d = np.degrees(r.gyro)
        write_csv(tmp_path / f"point{i}.csv", {"t": r.t, "gx": d[:, 0], "gy": d[:, 1], "gz": d[:, 2],
                                               "temp": r.temp, "table_rate": np.degrees(r.table_rate), "axis": r.axis})
    read, names = read_session(tmp_path, units="deg/s")
    assert names == ["point0.csv", "point1.csv", "point2.csv"]
    cal_files, _ = calibrate_thermal(read, settle=1.0)
    cal_mem, _ = calibrate_thermal(recs, settle=1.0, input_units="deg/s")
    assert cal_files.input_units == "deg/s"
    np.testing.assert_allclose(cal_files.kg, cal_mem.kg, rtol=1e-9, atol=1e-12)


def test_missing_session_path_is_an_error(tmp_path):
    with pytest.raises(InputError, match="no such file or folder"):
        read_session(tmp_path / "nope.csv", units="deg/s")
    with pytest.raises(InputError, match="holds no recordings"):
        read_session(tmp_path, units="deg/s")


def test_quantised_noisy_temperature_readings_still_group_into_points(rng):
    rec = _rec(rng, temps=(0.0, 20.0, 40.0), temp_noise=0.4, temp_quantum=1.0)
    steps = session_steps([rec], settle=1.0)
    np.testing.assert_allclose(steps.point_temps, [0.0, 20.0, 40.0], atol=0.1)


def test_steps_shorter_than_settling_are_an_error(rng):
    with pytest.raises(InputError, match="settling time"):
        find_steps(_rec(rng, temps=(0.0,)), settle=5.0)
