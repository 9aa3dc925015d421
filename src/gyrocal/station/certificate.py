"""A calibration certificate per unit: HTML from a template, PDF from the same HTML.

Laid out as the IEEE test standards for gyros arrange a report (requirement, test, result with its
uncertainty, limit, verdict), with the unit, the procedure, the equipment and conditions, the
parameters as left (and as found, when the unit had an earlier calibration), a chart of every result
against its limits, and the software and input hashes that make the result reproducible.
"""

from __future__ import annotations

import base64
import io
import math
from datetime import datetime, timezone

from ..errors import InputError, MissingDependencyError

__all__ = ["certificate_html", "write_certificate"]

_REQUIREMENT = {"k": "scale factor", "b": "bias", "misalignment": "misalignment", "noise_density": "noise density",
                "bias_instability": "bias instability", "thermal_residual": "thermal residual",
                "p_value": "fit consistency (p-value)", "sigma_k": "scale-factor uncertainty",
                "sigma_b": "bias uncertainty"}
_TEST = {"gyrocal.calibration": "rate calibration (turns and static windows)",
         "gyrocal.noise": "Allan variance of a static record", "gyrocal.thermal": "temperature table",
         "gyrocal.thermal-bias": "bias against temperature of a still, warming record"}


def _num(x, digits: int = 6) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{digits}g}"


def _results(doc: dict) -> list[dict]:
    acc = doc.get("acceptance") or {}
    test = _TEST.get(doc.get("format"), doc.get("format", ""))
    return [{"requirement": f"{_REQUIREMENT.get(c.get('parameter', ''), c['name'])} ({c['name']})", "test": test,
             "value": _num(c["value"]), "sigma": _num(c["sigma"], 3), "low": _num(c["low"]), "high": _num(c["high"]),
             "unit": c["unit"], "margin": _num(c["margin"], 3), "verdict": c["verdict"].upper()}
            for c in acc.get("criteria", [])]


def _parameters(doc: dict) -> list[dict]:
    std = doc.get("std") or {}
    internal = (doc.get("units") or {}).get("internal", "")
    rows = []
    for name, value in _flat_parameters(doc):
        unit = internal if name[0] in "bB" else "1"
        rows.append({"name": name, "value": _num(value, 8), "sigma": _num(std.get(name), 3), "unit": unit})
    return rows


def _found_left(doc: dict) -> list[dict]:
    """Rows of the as-found / as-left table: each error with its 1-sigma, before and after adjustment."""
    found, left = doc.get("as_found"), doc.get("as_left")
    if not found or not left:
        return []
    return [{"name": f["name"].replace("_", " "), "found": _num(f["error"], 4), "found_sigma": _num(f["sigma"], 2),
             "left": _num(g["error"], 4), "left_sigma": _num(g["sigma"], 2), "unit": f["unit"]}
            for f, g in zip(found["parameters"], left["parameters"])]


def _flat_parameters(doc: dict) -> list[tuple[str, float]]:
    params = doc.get("parameters") or {}
    if "scale_bias" in params:
        sb = params["scale_bias"]
        return [(f"k{a}", sb["k"][i]) for i, a in enumerate("xyz")] + [(f"b{a}", sb["b"][i]) for i, a in enumerate("xyz")]
    if "affine" in params:
        return list(zip(params["affine"]["kg_order"], params["affine"]["kg"]))
    return []


def _picture(doc: dict) -> str | None:
    """PNG (base64) of every criterion: value +- guard x sigma, scaled so that the limits sit at -1 and +1."""
    criteria = [c for c in (doc.get("acceptance") or {}).get("criteria", [])
                if c["value"] is not None and c["low"] is not None and c["high"] is not None]
    if not criteria:
        return None
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 0.28 * len(criteria) + 1.2))
    ax = fig.subplots()
    for i, c in enumerate(criteria):
        centre, half = (c["high"] + c["low"]) / 2, (c["high"] - c["low"]) / 2
        x = (c["value"] - centre) / half
        err = c["guard"] * (c["sigma"] or 0.0) / half
        ax.errorbar(x, i, xerr=err, fmt="o", color="#0a6b0a" if c["verdict"] == "pass" else "#b00000", capsize=3)
    ax.axvline(-1, color="k", lw=1)
    ax.axvline(1, color="k", lw=1)
    ax.set_yticks(range(len(criteria)), [c["name"] for c in criteria])
    ax.set_xlabel("(value - centre of limits) / half-width of limits; bars: guard x sigma")
    ax.invert_yaxis()
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return base64.b64encode(buf.getvalue()).decode()


def _context(doc: dict, record: str) -> dict:
    unit = doc.get("unit")
    if not unit:
        raise InputError("a certificate names its unit: this result has no 'unit' section (calibrate with --unit)")
    proc = unit.get("procedure") or {}
    identity = [("serial number", unit["serial"]), ("part", unit.get("part") or "-"),
                ("revision", unit.get("revision") or "-"), ("device id", unit.get("device_id") or "-"),
                ("procedure", f"{proc.get('name', '-')} {proc.get('version') or ''}".strip()),
                ("operator", unit.get("operator") or "-"), ("calibrated", unit.get("created", "-"))]
    observed = doc.get("observed") or {}
    conditions = [("station", unit.get("station") or "-"), ("fixture", unit.get("fixture") or "-"),
                  ("method", doc.get("method", "-")), ("sample rate", f"{_num(observed.get('sample_rate'), 5)} Hz"),
                  ("input units", (doc.get("units") or {}).get("input", "-"))]
    acc = doc.get("acceptance")
    verdict = "NO LIMITS" if acc is None else acc["verdict"].upper()
    return {"unit": unit, "identity": identity, "conditions": conditions, "verdict": verdict,
            "guard": _num((acc or {}).get("guard", 2)), "results": _results(doc), "parameters": _parameters(doc),
            "found_left": _found_left(doc),
            "previous": (doc.get("as_found") or {}).get("created"), "picture": _picture(doc), "record": record,
            "issued": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "methods": "the servo method of Wang et al. and the full-temperature-range method, as gyrocal implements them"}


def certificate_html(doc: dict, record: str = "-") -> str:
    """The certificate of one result document (with its ``unit`` section) as a standalone HTML page."""
    try:
        from jinja2 import Environment, PackageLoader, select_autoescape
    except ImportError:
        raise MissingDependencyError("a certificate needs Jinja2: pip install 'gyrocal[certificate]'") from None

    env = Environment(loader=PackageLoader("gyrocal.station", "templates"), autoescape=select_autoescape(["html"]))
    return env.get_template("certificate.html").render(**_context(doc, record))


def write_certificate(doc: dict, path, record: str = "-") -> None:
    """Write the certificate as HTML, or as PDF when `path` ends in ``.pdf`` (atomically)."""
    from .._atomic import atomic_path

    html = certificate_html(doc, record)
    suffix = str(path).lower().rsplit(".", 1)[-1]
    if suffix not in ("html", "htm", "pdf"):
        raise InputError(f"a certificate is written as .html or .pdf, got {path}")
    with atomic_path(path) as tmp:
        if suffix == "pdf":
            try:
                import weasyprint
            except ImportError:
                raise MissingDependencyError("a PDF certificate needs WeasyPrint: pip install 'gyrocal[certificate]'") from None
            weasyprint.HTML(string=html).write_pdf(tmp)
        else:
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(html)
