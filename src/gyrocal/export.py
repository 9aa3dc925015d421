"""Export a calibration or thermal calibration file as JSON, YAML or a C header.

Both kinds of file are versioned JSON that name themselves in their ``format``
field; :func:`load_any` dispatches on it, so every command that takes "a
calibration file" accepts either kind.
"""

from __future__ import annotations

import json
import os
from typing import Literal, get_args

from ._atomic import write_text_atomic
from ._jsonfile import read_json
from .calibration import FORMAT as CALIBRATION_FORMAT
from .calibration import Calibration, from_document
from .errors import FileFormatError, InputError, MissingDependencyError

__all__ = ["EXPORT_FORMATS", "THERMAL_FORMAT", "ExportFormat", "export_file", "load_any", "render"]

ExportFormat = Literal["json", "yaml", "c-header"]
EXPORT_FORMATS: tuple[str, ...] = get_args(ExportFormat)
THERMAL_FORMAT = "gyrocal.thermal"


def _load_doc(doc: dict, path):
    kind = doc.get("format")
    if kind == CALIBRATION_FORMAT:
        return from_document(doc, path)
    if kind == THERMAL_FORMAT:
        from .thermal import load_thermal

        return load_thermal(path)
    raise FileFormatError(
        f"{path}: field 'format' is {kind!r}; expected {CALIBRATION_FORMAT!r} or {THERMAL_FORMAT!r}", "format"
    )


def load_any(path: str | os.PathLike):
    """Read and validate a calibration file of either kind.

    Returns
    -------
    Calibration or gyrocal.thermal.ThermalCalibration
        Chosen by the file's ``format`` field (``gyrocal.calibration`` or ``gyrocal.thermal``).
    """
    return _load_doc(read_json(path), path)


def _c_header(obj) -> str:
    try:
        from . import firmware
    except ImportError:
        raise MissingDependencyError("this gyrocal build has no C-header exporter (gyrocal.firmware)") from None
    return firmware.c_header(obj) if isinstance(obj, Calibration) else firmware.thermal_c_header(obj)


def _yaml(doc: dict) -> str:
    try:
        import yaml
    except ImportError:
        raise MissingDependencyError("YAML export needs pyyaml: pip install 'gyrocal[yaml]'") from None
    return yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120)


def render(path: str | os.PathLike, fmt: ExportFormat) -> str:
    """The text of calibration file `path` in export format `fmt`.

    The file is validated first. ``json`` and ``yaml`` carry the same document;
    ``c-header`` is firmware code from :mod:`gyrocal.firmware`.

    Parameters
    ----------
    path : path-like
        A ``gyrocal.calibration`` or ``gyrocal.thermal`` file.
    fmt : {"json", "yaml", "c-header"}
    """
    if fmt not in EXPORT_FORMATS:
        raise InputError(f"format={fmt!r} is not one of {', '.join(EXPORT_FORMATS)}")
    doc = read_json(path)
    obj = _load_doc(doc, path)
    if fmt == "json":
        return json.dumps(doc, indent=2, allow_nan=False) + "\n"
    if fmt == "yaml":
        return _yaml(doc)
    return _c_header(obj)


def export_file(path: str | os.PathLike, fmt: ExportFormat, out: str | os.PathLike) -> None:
    """Write :func:`render` of `path` to `out`, atomically."""
    write_text_atomic(out, render(path, fmt))
