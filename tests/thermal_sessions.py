"""A small turntable session over temperature, shared by the tests that run ``gyrocal thermal`` on one."""

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
