"""As found and as left: the error this session shows with the unit's previous calibration, and with the new one.

With the servo method's model ``w = diag(k) (m + b)``, the new calibration is this session's best
estimate of the truth. Corrected with the previous calibration instead, a turn reads
``k_old / k_new - 1`` too large (relative scale error) and the unit at rest reads
``k_old (b_old - b_new)`` (bias error); their 1-sigma is the new calibration's, carried through.
As left (the new calibration) both errors are zero within that 1-sigma.
"""

from __future__ import annotations

import math

__all__ = ["as_found_and_left", "parameter_values"]


def parameter_values(doc: dict) -> dict[str, tuple[float, float]]:
    """``name -> (value, 1-sigma)`` of a calibration document's parameters (internal units); {} for other files."""
    params, std = doc.get("parameters") or {}, doc.get("std") or {}
    if "scale_bias" in params:
        sb = params["scale_bias"]
        names = [f"k{a}" for a in "xyz"] + [f"b{a}" for a in "xyz"]
        values = list(sb["k"]) + list(sb["b"])
    elif "affine" in params:
        names, values = params["affine"]["kg_order"], params["affine"]["kg"]
    else:
        return {}
    return {n: (float(v), math.nan if std.get(n) is None else float(std[n])) for n, v in zip(names, values)}


def _axes(doc: dict) -> tuple[list[float], list[float], list[float], list[float]] | None:
    """(k, b, sigma_k, sigma_b) per axis, for the scale-bias and affine models alike (diagonal of K)."""
    v = parameter_values(doc)
    if not v:
        return None
    kname = ("k{}" if "kx" in v else "K{0}{0}").format
    bname = ("b{}" if "bx" in v else "B{}").format
    return ([v[kname(a)][0] for a in "xyz"], [v[bname(a)][0] for a in "xyz"],
            [v[kname(a)][1] for a in "xyz"], [v[bname(a)][1] for a in "xyz"])


def as_found_and_left(new: dict, old: dict, *, record: int, created: str) -> tuple[dict, dict] | None:
    """The ``as_found`` (previous calibration) and ``as_left`` (new) sections; None when either is no calibration."""
    a, b = _axes(new), _axes(old)
    if a is None or b is None:
        return None
    unit = (new.get("units") or {}).get("internal", "rad/s")
    k, bias, sk, sb = a
    k_old, b_old = b[0], b[1]
    found, left = [], []
    for i, ax in enumerate("xyz"):
        found.append({"name": f"scale_error_{ax}", "error": k_old[i] / k[i] - 1, "sigma": k_old[i] * sk[i] / k[i] ** 2,
                      "unit": "1"})
        found.append({"name": f"bias_error_{ax}", "error": k_old[i] * (b_old[i] - bias[i]), "sigma": k_old[i] * sb[i],
                      "unit": unit})
        left.append({"name": f"scale_error_{ax}", "error": 0.0, "sigma": sk[i] / k[i], "unit": "1"})
        left.append({"name": f"bias_error_{ax}", "error": 0.0, "sigma": k[i] * sb[i], "unit": unit})
    return ({"record": record, "created": created, "parameters": found}, {"parameters": left})
