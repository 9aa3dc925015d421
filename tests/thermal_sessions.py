"""Simulated thermal sessions and their truth, shared by the tests of `gyrocal thermal` and `gyrocal imu` across temperature."""

import numpy as np


def thermal_session(path):
    """Three temperatures, three table rates, 3-s steps at 50 Hz (the shape of test_thermal_cli's session)."""
    from gyrocal.io import write_csv
    from gyrocal.simulation.thermal_truth import ThermalTruth
    from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable

    gyro = ThermalTruth().gyro(np.radians(0.05), full_scale=np.radians(300.0))
    rec = simulate_turntable(gyro, TurntableProtocol(temps=(0.0, 20.0, 40.0), rates=(0.0, 50.0, 200.0),
                                                     step_duration=3.0), sample_rate=50.0,
                             rng=np.random.default_rng(23))
    d = np.degrees(rec.gyro)
    write_csv(path, {"t": rec.t, "gx": d[:, 0], "gy": d[:, 1], "gz": d[:, 2], "temp": rec.temp,
                     "table_rate": np.degrees(rec.table_rate), "axis": rec.axis})
    return path


def truth_params(doc, sensor, temps):
    """Parameters (N, 12) of `sensor` from a simulation sidecar's cubics at `temps` [degC] (heating branch)."""
    x = (np.asarray(temps) - doc["ref_temp_degC"]) / doc["scale_degC"]
    return np.vander(x, 4, increasing=True) @ np.asarray(doc[sensor]["coefs"]).T


def smooth_at(doc, temps):
    """Values and 1-sigma (N, m) of a file's smooth model (``accelerometer.thermal.<sensor>``) at `temps`."""
    sm = doc["smooth"]
    coefs = np.asarray(sm["coefs"])
    m, width = coefs.shape
    powers = np.vander((np.asarray(temps) - sm["centre"]) / sm["scale"], width, increasing=True)
    cov = np.asarray(sm["covariance"]).reshape(m, width, m, width)
    return powers @ coefs.T, np.sqrt(np.einsum("np,jpjq,nq->nj", powers, cov, powers))
