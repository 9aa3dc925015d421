"""The whole IMU across temperature: a cube turned through its poses at each plateau of a chamber.

Reference: an independent generator written here. At each set point the accelerometer's scale
drifts 0.02 %/degC with a cubic part and its offsets by 0.1 g over -25..+60 degC (cubic); the
gyro's scale drifts and its bias jumps from one plateau to the next (turn-on bias). Each plateau
is a multi-position session of its own (:func:`~gyrocal.simulation.multiposition.simulate_multi_position`
with that temperature's sensors), and the log jumps in time between plateaus (the soak is not
recorded). The truth's accelerometer correction is lower triangular, so the frame the fit writes
in (corrected x along the sensor's x, y in its xy plane) is the truth's own.
"""

import numpy as np
import pytest

from gyrocal.errors import InputError
from gyrocal.imu.plateaus import find_plateaus, temperature_points
from gyrocal.imu.poses import fibonacci_directions
from gyrocal.imu.thermal import calibrate_imu_thermal
from gyrocal.models import Affine
from gyrocal.simulation.gyro import VirtualGyro
from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position

TEMPS = (-25.0, -5.0, 20.0, 40.0, 60.0)
BETWEEN = (-15.0, 7.5, 30.0, 50.0)
SEEDS = (0, 1, 2)
_LOWER = np.tril(np.ones((3, 3), bool))


def _x(temp):
    return (temp - 17.5) / 42.5


class Truth:
    """Accelerometer (canonical ``f = A (u - o)``) and gyro of one seeded board, as functions of temperature."""

    def __init__(self, rng):
        self.a0 = np.tril(np.eye(3) * rng.uniform(0.98, 1.02, 3) + rng.normal(0, 0.004, (3, 3)))
        self.o0 = rng.normal(0, 0.2, 3)
        self.drift = rng.choice([-1.0, 1.0], 3) * rng.uniform(0.7, 1.0, 3)
        self.sens = rng.uniform(0.8, 1.2, 3)
        self.k0 = np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3))
        self.b0 = np.radians(rng.normal(0, 0.5, 3))

    def accel(self, temp):
        x = _x(temp)
        s = 1 + self.sens * 2e-4 * (temp - 20) + 1e-3 * x**3  # sensitivity: reading per m/s^2
        a = self.a0.copy()
        a[np.diag_indices(3)] /= s
        offset = self.o0 + 9.80665 * 0.1 * self.drift * (0.35 * x + 0.1 * x**2 + 0.05 * x**3)
        return a, offset

    def params(self, temp):
        a, o = self.accel(temp)
        return np.concatenate([a[_LOWER], o])


def _chamber(seed, poses=14):
    """The log of one board: a session per plateau, 600 s unrecorded between plateaus."""
    rng = np.random.default_rng(seed)
    truth = Truth(rng)
    parts, gyro_truth, t0 = [], [], 0.0
    for temp in TEMPS:
        a, o = truth.accel(temp)
        k = truth.k0 * (1 + 1e-4 * (temp - 20))
        bias = truth.b0 + np.radians(0.002) * (temp - 20) + np.radians(rng.normal(0, 0.05, 3))
        imu = VirtualImu(VirtualGyro(Affine(k, bias), noise_std=np.radians(0.1)), accel_matrix=a, accel_offset=o,
                         accel_noise_std=0.02)
        s = simulate_multi_position(imu, MultiPositionProtocol(poses=poses, static_duration=(1.5, 2.5)), rng=rng)
        parts.append((s.t + t0, s.gyro, s.accel, temp + rng.normal(0, 0.05, len(s.t))))
        gyro_truth.append(np.concatenate([s.truth["gyro_matrix"].ravel(), s.truth["gyro_offset"]]))
        t0 += s.t[-1] + 600.0
    t, gyro, accel, temp = (np.concatenate(c) for c in zip(*parts))
    breaks = np.cumsum([len(p[0]) for p in parts])[:-1]
    return truth, np.array(gyro_truth), t, gyro, accel, temp, breaks


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
    from gyrocal.calibration import Calibration
    from gyrocal.imu.run import calibrate_recording
    from gyrocal.recording import Recording

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
    from gyrocal.calibration import Calibration
    from gyrocal.imu.run import calibrate_recording
    from gyrocal.recording import Recording

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
