"""The calibration file's sections for a whole-IMU calibration: the gyro's ``fit`` and the ``accelerometer``.

``accelerometer`` (the :class:`~gyrocal.results.sections.AccelerometerPart` keys, plus the ones this
method adds):

* ``units``: ``input`` (m/s^2, g or counts), ``output`` (m/s^2 or g), ``sensitivity`` (LSB per g
  for counts, or null), ``gravity`` [m/s^2] (the local gravity of the fit, and one g);
* ``correction``: ``a_true = matrix @ (raw - offset)``, raw in input units, a_true in output units;
* ``model`` (``affine``, ``triangular``, ``scale-bias``), ``parameters`` (``matrix``, ``offset`` in
  internal units, ``internal``: m/s^2 or counts), ``std`` and ``covariance`` of the free entries
  named in ``parameters.names``, ``sensor_axes`` (sensitivity per axis and angles between axes,
  each ``[value, 1-sigma]``), ``fit`` (chi-square summary, ``choice``: why this model);
* ``poses``: their number, how they cover the sphere, each pose's gravity direction, and
  ``detection``: the stillness thresholds' ``multiplier`` used, whether it was ``given``, and the
  ``sweep`` tried (``multiplier``, ``poses``, ``residual`` in noise units), or null for given windows;
* ``gyro_g_sensitivity``: null, or ``matrix`` [gyro input units per m/s^2] and ``std``, applied as
  ``w_true = gyro matrix @ (raw - offset - G a_true)``.
"""

from __future__ import annotations

import numpy as np

from .session import ImuCalibrationResult

__all__ = ["accelerometer_section", "gyro_fit_section"]


def gyro_fit_section(result: ImuCalibrationResult) -> dict:
    """The ``fit`` section of the gyro: chi-square summary, every pose pair and turn, the model choice."""
    g = result.gyro
    q = g.fit
    checks = list(g.checks)
    return {
        **q.to_dict(),
        "chi2_per_dof": q.chi2 / q.dof if q.dof else None,
        "residuals": [{"window": i, "label": c.label, "z": [float(np.sqrt(c.chi2))]} for i, c in enumerate(checks)],
        "disagree": [i for i, c in enumerate(checks) if c.disagrees],
        "pairs": [c.to_dict() for c in checks],
        "noise_factors": dict(g.noise_factors),
        "left_out": list(g.left_out),
        "model": g.model,
        "choice": list(g.choice),
    }


def _g_sensitivity(result: ImuCalibrationResult, cal) -> dict | None:
    g = result.gyro
    if g.g_sensitivity is None:
        return None
    std = g.std[-9:].reshape(3, 3)
    return {"matrix": (g.g_sensitivity / cal.input_scale).tolist(), "std": (std / cal.input_scale).tolist(),
            "units": f"{cal.input_units} per m/s^2",
            "equation": "w_true = matrix @ (raw - offset - G a_true), a_true in m/s^2"}


def _detection(det) -> dict | None:
    if det is None:
        return None
    return {"multiplier": det.multiplier, "given": len(det.sweep) == 1,
            "sweep": [{"multiplier": m, "poses": n, "residual": r if np.isfinite(r) else None} for m, n, r in det.sweep]}


def accelerometer_section(result: ImuCalibrationResult, rec, cal, accel_out: str, gravity: float) -> dict:
    """The ``accelerometer`` section (see the module notes)."""
    from ..units import accel_scale

    a = result.accel
    c_in = accel_scale(rec.accel_source_units, rec.accel_sensitivity, gravity)
    d_out = 1.0 if accel_out == "m/s^2" else gravity
    cov = result.coverage
    return {
        "units": {"input": rec.accel_source_units, "output": accel_out, "sensitivity": rec.accel_sensitivity,
                  "gravity": gravity},
        "correction": {"equation": "a_true = matrix @ (raw - offset)", "matrix": (a.matrix * c_in / d_out).tolist(),
                       "offset": (a.offset / c_in).tolist()},
        "model": a.model,
        "method": cal.method,
        "parameters": {"matrix": a.matrix.tolist(), "offset": a.offset.tolist(), "internal": rec.accel_units,
                       "names": list(a.param_names), "values": a.params.tolist()},
        "std": dict(zip(a.param_names, a.std.tolist())),
        "covariance": a.covariance.tolist(),
        "sensor_axes": {k: list(v) for k, v in a.sensor_axes().items()},
        "fit": {**a.fit.to_dict(), "choice": list(a.choice)},
        "poses": {"count": len(result.statics), **cov.to_dict(), "directions": a.directions.tolist(),
                  "detection": _detection(result.detection)},
        "gyro_g_sensitivity": _g_sensitivity(result, cal),
    }
