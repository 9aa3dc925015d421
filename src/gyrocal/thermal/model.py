"""The temperature table: per-point Kg, its interpolation, compensation and file.

File layout (``format: gyrocal.thermal``, ``version: 1``)::

    {
      "format": "gyrocal.thermal", "version": 1, "model": "affine-thermal",
      "units": {"input": "deg/s", "output": "deg/s", "internal": "rad/s", "temperature": "degC"},
      "range": [Tmin, Tmax],
      "interpolation": {"rule": "...", "out_of_range": "refuse"},
      "reference_temp": 25.0,      # traditional baseline: the point nearest to it
      "temp_tau_s": 20.0,          # smoothing of per-sample temperature before lookup
      "kg_names": ["Kxx", ..., "Bz"],
      "points": [{"temp": ..., "kg": [...], "kg_user": [...], "std": [...], "std_noise": [...],
                  "residual_rms": [...], "correction": {"matrix": [[...]], "offset": [...]}}, ...],
      "smooth": {"centre": ..., "scale": ..., "orders": [...], "coefs": [[...]], ...},
      "settings": {...}, "created_by": "gyrocal 0.1.0"
    }

``kg`` is internal (K dimensionless, B in rad/s, eq. 14 order); ``kg_user`` has B in
input units and K scaled by output/input unit factors, so ``w_in = K_user w_out + B_user``;
``correction`` is the canonical ``w_out = matrix @ (raw - offset)`` in user units.
The smooth model is stored for internal ``kg``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .. import __version__
from .._jsonfile import check_header, get, get_array, read_json, write_json
from .._validation import finite_array
from ..errors import FileFormatError, InputError, UnitError
from ..models import _KG_COLS, _KG_ROWS, KG_NAMES, _freeze
from ..recording import Recording
from ..units import RateUnit, parse_rate_unit, unit_factor
from .lagrange import OutOfRange, check_nodes, interpolate, range_policy
from .smooth import SmoothModel
from .tempfilter import DEFAULT_TEMP_TAU, smooth_temperature

__all__ = ["FORMAT", "VERSION", "TableModel", "ThermalCalibration", "kg_to_kb", "load_thermal", "save_thermal"]

FORMAT = "gyrocal.thermal"
VERSION = 1
TableModel = Literal["lagrange", "smooth", "traditional"]
_MODELS = ("lagrange", "smooth", "traditional")
RULE = ("3-node Lagrange (seed 001 eq. 21-22): i = first node >= T, stencil nodes s..s+2 with s = clip(i-2, 0, n-3)")


def kg_to_kb(kg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """K (..., 3, 3) and B (..., 3) from Kg vectors (..., 12) (eq. 11 and 14)."""
    kg = np.asarray(kg, float)
    K = np.zeros(kg.shape[:-1] + (3, 3))
    K[..., _KG_ROWS, _KG_COLS] = kg[..., :9]
    return K, kg[..., 9:].copy()


@dataclass(frozen=True)
class ThermalCalibration:
    """A gyro calibrated at several temperatures (seed 001).

    Parameters
    ----------
    temps : array_like, shape (n,)
        Temperature points [degC], strictly increasing, n >= 3.
    kg : array_like, shape (n, 12)
        Eq. 14 vectors in internal units (K dimensionless, B [rad/s]).
    smooth : SmoothModel
        Per-element polynomials of ``kg`` in temperature.
    input_units, output_units : {"rad/s", "deg/s"}
        Units of the raw data and of the corrected rates.
    reference_temp : float
        Temperature of the traditional single-temperature baseline [degC]; the
        nearest point is used.
    std, std_noise : array_like, shape (n, 12), optional
        1-sigma of ``kg`` from residuals and from the step noise (internal units).
    residual_rms : array_like, shape (n, 3), optional
        RMS step residual of each fit [rad/s].
    temp_tau : float
        Time constant of the temperature smoothing applied in :meth:`apply` [s].
    settings : dict
        How the table was made (settling time, tolerances), for the record.
    """

    temps: np.ndarray
    kg: np.ndarray
    smooth: SmoothModel
    input_units: RateUnit = "rad/s"
    output_units: RateUnit = "rad/s"
    reference_temp: float = 25.0
    std: np.ndarray | None = None
    std_noise: np.ndarray | None = None
    residual_rms: np.ndarray | None = None
    temp_tau: float = DEFAULT_TEMP_TAU
    settings: dict = field(default_factory=dict)

    def __post_init__(self):
        temps = check_nodes(self.temps)
        n = len(temps)
        object.__setattr__(self, "temps", _freeze(temps))
        object.__setattr__(self, "kg", _freeze(finite_array("kg", self.kg, shape_tail=(12,), ndim=2)))
        if self.kg.shape[0] != n:
            raise InputError(f"kg has {self.kg.shape[0]} rows but there are {n} temperature points")
        for name, width in (("std", 12), ("std_noise", 12), ("residual_rms", 3)):
            value = getattr(self, name)
            if value is not None:
                arr = finite_array(name, value, ndim=2)
                if arr.shape != (n, width):
                    raise InputError(f"{name} must have shape ({n}, {width}), got {arr.shape}")
                object.__setattr__(self, name, _freeze(arr))
        object.__setattr__(self, "input_units", parse_rate_unit(self.input_units, "input_units"))
        object.__setattr__(self, "output_units", parse_rate_unit(self.output_units, "output_units"))
        if not math.isfinite(self.reference_temp):
            raise InputError(f"reference_temp must be a finite temperature in degC, got {self.reference_temp!r}")
        K, _ = kg_to_kb(self.kg)
        cond = np.linalg.cond(K)
        if np.any(~np.isfinite(cond) | (cond > 1e12)):
            bad = int(np.argmax(~np.isfinite(cond) | (cond > 1e12)))
            raise InputError(f"K at {temps[bad]:g} degC is singular; it cannot be inverted")

    # --- views ------------------------------------------------------------
    @property
    def range(self) -> tuple[float, float]:
        """Calibrated temperature range (Tmin, Tmax) [degC]."""
        return float(self.temps[0]), float(self.temps[-1])

    @property
    def reference_index(self) -> int:
        """Index of the point nearest to :attr:`reference_temp` (the traditional baseline)."""
        return int(np.argmin(np.abs(self.temps - self.reference_temp)))

    def to_user(self, kg: np.ndarray) -> np.ndarray:
        """Kg-ordered values (n, 12) in user units: K terms times output/input factor, B in input
        units. Linear, so it serves Kg and its 1-sigma alike."""
        c, d = unit_factor(self.input_units), unit_factor(self.output_units)
        return np.concatenate([kg[:, :9] * (d / c), kg[:, 9:] / c], axis=1)

    @property
    def kg_user(self) -> np.ndarray:
        """Kg (n, 12) in user units (:meth:`to_user`)."""
        return self.to_user(self.kg)

    @property
    def correction(self) -> tuple[np.ndarray, np.ndarray]:
        """Canonical ``(matrix (n, 3, 3), offset (n, 3))`` per point in user units: ``w_out = matrix @ (raw - offset)``."""
        K, B = kg_to_kb(self.kg_user)
        return np.linalg.inv(K), B

    # --- evaluation -------------------------------------------------------
    def kg_at(self, temp, model: TableModel = "lagrange", out_of_range: OutOfRange = "refuse") -> np.ndarray:
        """Kg (N, 12) [internal units] at temperatures (N,) [degC]."""
        t = finite_array("temp", np.atleast_1d(np.asarray(temp, dtype=float)), ndim=1)
        if model == "traditional":
            return np.broadcast_to(self.kg[self.reference_index], (len(t), 12)).copy()
        if model == "lagrange":
            return interpolate(self.temps, self.kg, t, out_of_range)
        if model == "smooth":
            return self.smooth(range_policy(self.temps, t, out_of_range))  # same range policy as the table
        raise InputError(f"model={model!r} is not one of {', '.join(_MODELS)}")

    def compensate(self, gyro, temp, model: TableModel = "lagrange", out_of_range: OutOfRange = "refuse") -> np.ndarray:
        """True rates (N, 3) [rad/s] from readings (N, 3) [rad/s] at temperatures (N,) [degC] (eq. 12 inverted)."""
        w = finite_array("gyro", gyro, shape_tail=(3,), ndim=2)
        t = np.broadcast_to(np.asarray(temp, dtype=float), (len(w),))
        K, B = kg_to_kb(self.kg_at(t, model, out_of_range))
        return np.linalg.solve(K, (w - B)[..., None])[..., 0]

    def apply(self, rec: Recording, model: TableModel = "lagrange", out_of_range: OutOfRange = "refuse",
              temp_tau: float | None = None) -> np.ndarray:
        """Corrected rates (N, 3) [output units] of a recording with a per-sample ``temp``.

        The temperature is first smoothed in time (:func:`smooth_temperature`, time
        constant `temp_tau`, default :attr:`temp_tau`), so quantised or noisy readings
        do not make the output jump.
        """
        if rec.temp is None:
            raise InputError("thermal compensation needs a temperature for every sample; the recording has no "
                             "'temp' column (map one with --columns temp=NAME)")
        if rec.units != "rad/s":
            raise UnitError("the recording is in raw counts without a sensitivity; give its sensitivity in LSB per unit")
        tau = self.temp_tau if temp_tau is None else temp_tau
        temp = smooth_temperature(rec.temp, rec.sample_rate, tau)
        return self.compensate(rec.gyro, temp, model, out_of_range) / unit_factor(self.output_units)


# --- file -------------------------------------------------------------------
def _opt_list(a):
    return None if a is None else a.tolist()


def to_document(cal: ThermalCalibration) -> dict:
    """The JSON-ready document of a thermal calibration."""
    matrix, offset = cal.correction
    user = cal.kg_user
    points = []
    for i, t in enumerate(cal.temps):
        points.append({
            "temp": float(t), "kg": cal.kg[i].tolist(), "kg_user": user[i].tolist(),
            "std": None if cal.std is None else cal.std[i].tolist(),
            "std_noise": None if cal.std_noise is None else cal.std_noise[i].tolist(),
            "residual_rms": None if cal.residual_rms is None else cal.residual_rms[i].tolist(),
            "correction": {"matrix": matrix[i].tolist(), "offset": offset[i].tolist()},
        })
    return {
        "format": FORMAT, "version": VERSION, "model": "affine-thermal",
        "units": {"input": cal.input_units, "output": cal.output_units, "internal": "rad/s", "temperature": "degC"},
        "range": list(cal.range),
        "interpolation": {"rule": RULE, "out_of_range": "refuse"},
        "reference_temp": cal.reference_temp,
        "temp_tau_s": cal.temp_tau,
        "kg_names": list(KG_NAMES),
        "points": points,
        "smooth": cal.smooth.to_dict(),
        "settings": cal.settings,
        "created_by": f"gyrocal {__version__}",
    }


def save_thermal(cal: ThermalCalibration, path: str | os.PathLike) -> None:
    """Write `cal` as versioned JSON, atomically."""
    write_json(path, to_document(cal))


def from_document(doc: dict, path="file") -> ThermalCalibration:
    """Validate a document and rebuild the calibration, naming any bad field."""
    check_header(doc, path, FORMAT, (VERSION,))
    if list(get(doc, "kg_names", path)) != list(KG_NAMES):
        raise FileFormatError(f"{path}: field 'kg_names' must be {list(KG_NAMES)}", "kg_names")
    pts = get(doc, "points", path)
    if not isinstance(pts, list) or len(pts) < 3:
        raise FileFormatError(f"{path}: field 'points' must list at least 3 temperature points", "points")
    named = {f"points[{i}]": p for i, p in enumerate(pts)}  # so messages say points[2].kg
    cols = {}
    for key, width in (("temp", 1), ("kg", 12), ("std", 12), ("std_noise", 12), ("residual_rms", 3)):
        rows = [get_array(named, f"{name}.{key}", (width,) if key != "temp" else (), path,
                          allow_none=key not in ("kg", "temp")) for name in named]
        cols[key] = None if any(r is None for r in rows) else np.stack(rows)
    temps = cols.pop("temp")
    raw = get(doc, "smooth.coefs", path)
    width = len(raw[0]) if isinstance(raw, list) and raw and isinstance(raw[0], list) else 0
    coefs = get_array(doc, "smooth.coefs", (12, width), path)
    loto = get(doc, "smooth", path).get("loto_rms") or np.zeros((1, 12))
    try:
        smooth = SmoothModel(centre=float(get(doc, "smooth.centre", path)), scale=float(get(doc, "smooth.scale", path)),
                             orders=np.asarray(get(doc, "smooth.orders", path), int), coefs=coefs,
                             loto_rms=np.asarray(loto, float))
        return ThermalCalibration(
            temps=temps, kg=cols["kg"], smooth=smooth,
            input_units=get(doc, "units.input", path), output_units=get(doc, "units.output", path),
            reference_temp=float(get(doc, "reference_temp", path)), std=cols["std"], std_noise=cols["std_noise"],
            residual_rms=cols["residual_rms"], temp_tau=float(doc.get("temp_tau_s", DEFAULT_TEMP_TAU)),
            settings=dict(doc.get("settings") or {}))
    except (InputError, TypeError, ValueError) as exc:
        raise FileFormatError(f"{path}: {exc}") from None


def load_thermal(path: str | os.PathLike) -> ThermalCalibration:
    """Read and validate a ``gyrocal.thermal`` file."""
    return from_document(read_json(path), path)
