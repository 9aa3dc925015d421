"""The whole IMU across temperature: a cube turned through its poses at each plateau of a chamber.

Reference: the independent generator of :mod:`imu_chamber` (the truth's accelerometer and gyro at
every temperature, a log that jumps in time between plateaus).
"""

import numpy as np
import pytest
from imu_chamber import BETWEEN, TEMPS
from imu_chamber import chamber as _chamber

from gyrocal.errors import InputError
from gyrocal.imu.plateaus import find_plateaus, temperature_points
from gyrocal.imu.poses import fibonacci_directions
from gyrocal.imu.thermal import calibrate_imu_thermal

SEEDS = (0, 1, 2)


@pytest.fixture(scope="module")
def fitted():
    out = []
    for seed in SEEDS:
        truth, gyro_truth, t, gyro, accel, temp, breaks = _chamber(seed)
        out.append((truth, gyro_truth, calibrate_imu_thermal(t, gyro, accel, temp, breaks=breaks, min_plateau=10.0)))
    return out


def test_plateaus_are_cut_at_breaks_and_temperature_steps():
    """Reference: the generator's plateaus; two plateaus at one set point are one temperature point."""
    t = np.arange(4000) * 0.1
    temp = np.repeat([20.0, 40.0, 20.3, 60.0], 1000) + np.random.default_rng(3).normal(0, 0.05, 4000)
    plateaus = find_plateaus(t, temp, breaks=[500], min_duration=10.0)
    assert [(p.start, p.stop) for p in plateaus] == [(0, 500), (500, 1000), (1000, 2000), (2000, 3000), (3000, 4000)]
    assert temperature_points(plateaus) == [[0, 1, 3], [2], [4]]


def test_each_point_is_the_truth_at_its_temperature_within_its_sigma(fitted):
    """Accelerometer (9 parameters, triangular frame) and gyro (12) at every point: RMS z in a two-sided band."""
    za, zg = [], []
    for truth, gyro_truth, res in fitted:
        assert res.accel_model == "triangular" and res.gyro_model == "affine"
        assert len(res.points) == len(TEMPS) and all(p.poses >= 12 for p in res.points)
        for p, g_true in zip(res.points, gyro_truth):
            za.append((p.accel - truth.params(p.temperature)) / np.sqrt(np.diag(p.accel_cov)))
            zg.append((p.gyro - g_true) / np.sqrt(np.diag(p.gyro_cov)))
    rms_a, rms_g = np.sqrt(np.mean(np.square(za))), np.sqrt(np.mean(np.square(zg)))
    print(f"per-point RMS z: accelerometer {rms_a:.2f} ({np.size(za)} values), gyro {rms_g:.2f} ({np.size(zg)})")
    assert 0.7 < rms_a < 1.35
    assert 0.7 < rms_g < 1.35


def _force_errors(res, truth, temp, scheme):
    """RMS error [m/s^2] over directions at `temp`: the model, the reference point alone, and the truth's own drift."""
    f = 9.80665 * fibonacci_directions(40)
    a, o = truth.accel(temp)
    u = f @ np.linalg.inv(a).T + o
    model = res.correct_accel(u, np.full(len(u), temp), scheme)
    ref = res.points[res.reference]
    a_ref, o_ref = ref.results[0].accel.matrix, ref.accel[-3:]
    a_true, o_true = truth.accel(ref.temperature)

    def rms(g):
        return float(np.sqrt(np.mean(np.sum((g - f) ** 2, axis=1))))

    return rms(model), rms((u - o_ref) @ a_ref.T), rms((u - o_true) @ a_true.T)


def test_smooth_model_between_points_is_within_its_sigma_and_beats_one_temperature(fitted):
    """Between the points the smooth model's 1-sigma covers the truth, and the correction beats the reference
    point's by the factor the truth's drift over the model's 1-sigma implies."""
    z, model_err, base_err, drift, predicted = [], [], [], [], []
    for truth, _, res in fitted:
        values, std = res.accel.smooth_at(BETWEEN)
        z.append((values - np.array([truth.params(tc) for tc in BETWEEN])) / std)
        for k, temp in enumerate(BETWEEN):
            m, b, d = _force_errors(res, truth, temp, "smooth")
            model_err.append(m)
            base_err.append(b)
            drift.append(d)
            predicted.append(float(np.sqrt(np.mean(std[k, -3:] ** 2) * 3)))  # offsets dominate |f|'s error
    rms_z = float(np.sqrt(np.mean(np.square(z))))
    measured = np.sqrt(np.mean(np.square(base_err))) / np.sqrt(np.mean(np.square(model_err)))
    implied = np.sqrt(np.mean(np.square(drift))) / np.sqrt(np.mean(np.square(predicted)))
    print(f"between points: smooth RMS z {rms_z:.2f}; improvement {measured:.0f}x measured, {implied:.0f}x implied")
    assert 0.6 < rms_z < 1.5
    assert measured > 10
    assert 0.5 < measured / implied < 2.0


def test_lagrange_interpolates_the_points_and_carries_their_sigma(fitted):
    """At a point the Lagrange value is that point's fit and its 1-sigma that point's; between, it stays near."""
    truth, _, res = fitted[0]
    nodes = [p.temperature for p in res.points]
    values, std = res.accel.lagrange_at(nodes)
    np.testing.assert_allclose(values, res.accel.values, atol=1e-12)
    np.testing.assert_allclose(std, np.sqrt(np.einsum("kjj->kj", res.accel.covariances)), rtol=1e-9)
    m_l, b_l, _ = _force_errors(res, truth, 30.0, "lagrange")
    m_s, _, _ = _force_errors(res, truth, 30.0, "smooth")
    print(f"at 30 degC: Lagrange {m_l:.2e}, smooth {m_s:.2e}, one temperature {b_l:.2e} m/s^2")
    assert m_l < b_l / 5


def test_too_few_temperature_points_is_one_line_error():
    truth, _, t, gyro, accel, temp, breaks = _chamber(5, poses=12)
    keep = slice(0, breaks[1])  # two plateaus
    with pytest.raises(InputError, match="3 or more temperature points") as err:
        calibrate_imu_thermal(t[keep], gyro[keep], accel[keep], temp[keep], breaks=breaks[:1], min_plateau=10.0)
    assert "\n" not in str(err.value)


def test_a_chamber_recording_writes_the_thermal_section_and_old_files_still_load(tmp_path):
    """calibrate_recording finds the breaks and plateaus itself; the file holds the points and both models."""
    from gyrocal.imu.run import calibrate_recording
    from gyrocal.recording import Recording
    from gyrocal.results.calibration import Calibration

    truth, _, t, gyro, accel, temp, _ = _chamber(7, poses=12)
    rec = Recording(t=t, gyro=gyro, accel=accel, accel_units="m/s^2", accel_source_units="m/s^2",
                    source_units="rad/s", temp=temp)
    run = calibrate_recording(rec)
    assert run.thermal is not None and len(run.thermal.points) == len(TEMPS)
    doc = run.calibration.to_document()
    section = doc["accelerometer"]["thermal"]
    assert section["points"][section["reference_point"]]["temperature"] == pytest.approx(20.0, abs=0.1)
    assert len(section["accelerometer"]["smooth"]["coefs"]) == 9 and "frame" in section
    loaded = Calibration.from_document(doc)
    assert loaded.accelerometer["thermal"]["accelerometer"]["names"][0] == "A_xx"
    a_ref, o_ref = truth.accel(run.thermal.points[run.thermal.reference].temperature)
    np.testing.assert_allclose(doc["accelerometer"]["correction"]["offset"], o_ref, atol=0.02)
    del doc["accelerometer"]["thermal"]
    assert "thermal" not in Calibration.from_document(doc).accelerometer


def test_apply_corrects_both_sensors_at_each_samples_temperature():
    """Reference: the generator's truth at 30 degC, between the points; apply with the file beats the point at 20."""
    from gyrocal.imu.run import calibrate_recording
    from gyrocal.recording import Recording
    from gyrocal.results.calibration import Calibration

    truth, _, t, gyro, accel, temp, _ = _chamber(8, poses=12)
    rec = Recording(t=t, gyro=gyro, accel=accel, accel_units="m/s^2", accel_source_units="m/s^2",
                    source_units="rad/s", temp=temp)
    cal = Calibration.from_document(calibrate_recording(rec).calibration.to_document())
    f = 9.80665 * fibonacci_directions(30)
    a, o = truth.accel(30.0)
    u = f @ np.linalg.inv(a).T + o
    test = Recording(t=np.arange(len(u)) * 0.01, gyro=np.zeros((len(u), 3)), accel=u, accel_units="m/s^2",
                     accel_source_units="m/s^2", source_units="rad/s", temp=np.full(len(u), 30.0))
    thermal = cal.apply(test).accel
    single = cal.apply(Recording(t=test.t, gyro=test.gyro, accel=u, accel_units="m/s^2",
                                 accel_source_units="m/s^2", source_units="rad/s")).accel
    err_t, err_1 = (float(np.sqrt(np.mean(np.sum((x - f) ** 2, axis=1)))) for x in (thermal, single))
    assert err_t < 0.01 < err_1 and err_t < err_1 / 10
    assert np.all(np.isfinite(cal.apply(test).gyro))
