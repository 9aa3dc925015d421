"""Upgrades of old gyrocal files to the current version of their format.

:func:`upgrade` applies one step per version until the document is current; each step
is a pure function of the document. :func:`gyrocal.results.files.load` calls it, so every
reader of files accepts old ones. The steps, and what changed:

``gyrocal.calibration`` 1 -> 2
    ``parameters.seed000 {k, b}`` becomes ``parameters.scale_bias {k, b}``;
    ``parameters.seed001 {kg, kg_names}`` becomes ``parameters.affine {K, B, kg, kg_order}``;
    the optional sections ``fit``, ``observed`` and ``accelerometer`` appear (null).
    ``correction``, ``std``, ``covariance`` and ``noise_std`` are unchanged.

``gyrocal.thermal`` 1 -> 2
    ``kg_names`` becomes ``kg_order``; the interpolation rule names the method instead
    of an internal label; the optional ``fit`` section appears (null).

``gyrocal.noise`` 1 -> 2
    Per-axis gyro lists (``arw``, ``bias_instability``, ``rrw``) become figures per axis and
    for the sensor (``gyroscope.x.density.value``, ...) with intervals (null: unknown); the
    accelerometer section appears (null). See :func:`gyrocal.noise.document.upgrade_v1`.

``gyrocal.thermal-bias`` 1 -> 2
    The optional ``accelerometer`` section (the offsets' change from ``tref``) appears (null);
    the gyro's fields are unchanged.
"""

from __future__ import annotations

import copy
import importlib
from collections.abc import Callable
from typing import Any

from ..errors import FileFormatError

__all__ = ["UPGRADES", "upgrade"]

Upgrade = Callable[[dict, Any], dict]


def _need(doc: dict, key: str, path) -> Any:
    if not isinstance(doc, dict) or key not in doc:
        raise FileFormatError(f"{path}: missing field '{key}' (version 1 file)", key)
    return doc[key]


def _calibration_1_to_2(doc: dict, path) -> dict:
    from ..models import KG_NAMES, kg_to_kb

    params = _need(doc, "parameters", path)
    if not isinstance(params, dict):
        raise FileFormatError(f"{path}: field 'parameters' must be an object", "parameters")
    if "seed000" in params:
        new = {"scale_bias": params["seed000"]}
    elif "seed001" in params:
        old = params["seed001"]
        kg = _need(old, "kg", f"{path}: parameters.seed001")
        if not (isinstance(kg, list) and len(kg) == 12 and all(isinstance(v, (int, float)) for v in kg)):
            raise FileFormatError(f"{path}: field 'parameters.seed001.kg' must be 12 numbers", "parameters.seed001.kg")
        K, B = kg_to_kb(kg)
        new = {"affine": {"K": K.tolist(), "B": B.tolist(), "kg": list(kg),
                          "kg_order": old.get("kg_names", list(KG_NAMES))}}
    else:
        raise FileFormatError(f"{path}: field 'parameters' has neither 'seed000' nor 'seed001' (version 1 file)",
                              "parameters")
    out = {k: v for k, v in doc.items() if k not in ("parameters", "windows", "created_by")}
    out.update(version=2, parameters=new, fit=None, observed=None, accelerometer=None)
    out["windows"] = doc.get("windows", [])
    out["created_by"] = doc.get("created_by")
    return out


def _thermal_1_to_2(doc: dict, path) -> dict:
    from ..thermal.model import RULE

    out = {}
    for key, value in doc.items():
        out["kg_order" if key == "kg_names" else key] = value
    _need(doc, "kg_names", path)
    interp = dict(out.get("interpolation") or {})
    interp["rule"] = RULE
    out.update(version=2, interpolation=interp)
    out.setdefault("fit", None)
    return out


def _noise_1_to_2(doc: dict, path) -> dict:
    # by name, as the registry knows its kinds: the noise file's module imports the registry
    return importlib.import_module("gyrocal.noise.document").upgrade_v1(doc, path)


def _thermal_bias_1_to_2(doc: dict, path) -> dict:
    _need(doc, "axes", path)
    out = dict(doc)
    out.update(version=2, accelerometer=None)
    return out


#: (format, version) -> the step to version + 1.
UPGRADES: dict[tuple[str, int], Upgrade] = {
    ("gyrocal.calibration", 1): _calibration_1_to_2,
    ("gyrocal.thermal", 1): _thermal_1_to_2,
    ("gyrocal.noise", 1): _noise_1_to_2,
    ("gyrocal.thermal-bias", 1): _thermal_bias_1_to_2,
}


def upgrade(doc: dict, path: Any = "document") -> dict:
    """`doc` upgraded step by step to the newest version its format has here (a new dict; `doc` is untouched).

    A document of a version with no upgrade is returned as it is; the reader of its
    format then accepts or refuses its version.
    """
    out = doc
    while isinstance(out, dict) and (step := UPGRADES.get((out.get("format"), out.get("version")))) is not None:
        if type(out.get("version")) is not int:  # JSON true == 1
            break
        out = step(copy.deepcopy(out), path)
    return out
