"""Export a whole-IMU calibration as imucal's JSON (``FerrarisCalibrationInfo``, format 2.0.0).

imucal (mad-lab-fau/imucal) corrects ``acc_out = R_a^-1 K_a^-1 (acc - b_a)`` and
``gyr_out = R_g^-1 K_g^-1 (gyr - b_g - K_ga acc_out)``, with ``K`` diagonal (the per-axis gain) and
each row of ``R`` a unit vector. gyrocal's canonical ``matrix @ (raw - offset)`` is the same map:
``K R = matrix^-1``, so ``K`` holds the row norms of ``matrix^-1`` and ``R = K^-1 matrix^-1``;
``b`` is ``offset`` and ``K_ga`` the gyro's g-sensitivity (zeros when none was fitted), per unit of
imucal's ``acc_unit``. Units are written as gyrocal's (``counts`` as imucal's ``a.u.``), and imucal
checks them when it applies the calibration. ``imucal.CalibrationInfo.from_json`` loads the text.
"""

from __future__ import annotations

import json

import numpy as np

from .._validation import refuse_options
from .._version import __version__
from ..errors import InputError
from ..results.calibration import Calibration
from . import register_exporter

__all__ = ["imucal_json", "imucal_units"]

#: imucal's file-format version that this exporter writes.
IMUCAL_FORMAT_VERSION = "2.0.0"


def imucal_units(units: str) -> str:
    """A gyrocal unit as imucal writes it (raw counts are imucal's 'a.u.')."""
    return "a.u." if units == "counts" else units


def _gain_rotation(matrix) -> tuple[np.ndarray, np.ndarray]:
    """``(K, R)`` with ``K R = matrix^-1``, ``K`` diagonal positive, rows of ``R`` unit vectors."""
    inv = np.linalg.inv(np.asarray(matrix, dtype=float))
    k = np.linalg.norm(inv, axis=1)
    return np.diag(k), inv / k[:, None]


def imucal_json(cal, **options) -> str:
    """imucal's ``FerrarisCalibrationInfo`` JSON of a calibration with an accelerometer part."""
    refuse_options(options, (), "imucal export")
    part = cal.accelerometer
    if part is None or part.get("correction") is None:
        raise InputError("imucal's format holds the accelerometer and the gyro; this calibration has no "
                         "accelerometer part", param="fmt",
                         hint="calibrate both sensors with 'gyrocal imu', or export with another {param}")
    units = part["units"]
    k_a, r_a = _gain_rotation(part["correction"]["matrix"])
    g_matrix, g_offset = cal.correction
    k_g, r_g = _gain_rotation(g_matrix)
    coupling = part.get("gyro_g_sensitivity")
    per_out = 1.0 if units["output"] == "m/s^2" else float(units["gravity"])
    k_ga = np.zeros((3, 3)) if coupling is None else np.asarray(coupling["matrix"], float) * per_out
    doc = {
        "acc_unit": units["output"], "gyr_unit": cal.output_units,
        "from_acc_unit": imucal_units(units["input"]), "from_gyr_unit": imucal_units(cal.input_units),
        "comment": f"gyrocal {__version__}: {cal.method} calibration, gyro {cal.model.kind}, accelerometer "
                   f"{part.get('model', 'given')}; 1-sigma of every parameter in the gyrocal calibration file",
        "K_a": k_a.tolist(), "R_a": r_a.tolist(), "b_a": list(part["correction"]["offset"]),
        "K_g": k_g.tolist(), "R_g": r_g.tolist(), "K_ga": k_ga.tolist(), "b_g": np.asarray(g_offset).tolist(),
        "cal_type": "Ferraris", "_format_version": IMUCAL_FORMAT_VERSION,
    }
    return json.dumps(doc, indent=4) + "\n"


register_exporter("imucal", (Calibration,), imucal_json, suffix=".json")
