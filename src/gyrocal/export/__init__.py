"""Export registry: write a calibration file in another format (JSON, YAML, a C header, ...).

An exporter is a function ``fn(obj, **options) -> str`` for some file kinds, registered
under a format name with :func:`register_exporter` by the module that defines it.
:data:`EXPORTER_MODULES` names the module of each format, so this module stays light
(``EXPORT_FORMATS`` needs no import of numpy) and an exporter is imported when it is used.

Layer 8 (firmware, exports, simulation, figures and the store) of docs/architecture.md: imports the package
root and layers 1 to 8 only, and not jobs, store.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .._atomic import write_text_atomic
from ..errors import InputError

__all__ = ["EXPORTER_MODULES", "EXPORT_FORMATS", "Exporter", "export_file", "exporter", "register_exporter", "render"]

#: Format name -> module that registers its exporter (add a line for a new format).
EXPORTER_MODULES: dict[str, str] = {
    "json": "gyrocal.export.builtin",
    "yaml": "gyrocal.export.builtin",
    "c-header": "gyrocal.export.builtin",
    "imucal": "gyrocal.export.imucal",
    "kalibr": "gyrocal.export.flight",
    "vins": "gyrocal.export.flight",
    "imu_utils": "gyrocal.export.flight",
    "px4": "gyrocal.export.flight",
    "ardupilot": "gyrocal.export.flight",
}
#: The export formats, in the order the command line lists them.
EXPORT_FORMATS: tuple[str, ...] = tuple(EXPORTER_MODULES)


@dataclass(frozen=True)
class Exporter:
    """A registered exporter.

    Attributes
    ----------
    name : str
        Format name (``"c-header"``).
    kinds : tuple of type, or None
        File kinds it exports; None for every registered kind.
    fn : callable
        ``fn(obj, **options) -> str``.
    suffix : str
        Usual file suffix of its output (``".h"``).
    """

    name: str
    kinds: tuple[type, ...] | None
    fn: Callable[..., str]
    suffix: str


_REGISTRY: dict[str, Exporter] = {}


def register_exporter(name: str, kinds: tuple[type, ...] | None, fn: Callable[..., str], *, suffix: str) -> None:
    """Register `fn` as the exporter of format `name` for objects of `kinds` (None: every file kind)."""
    if name not in EXPORTER_MODULES:
        raise InputError(f"export format {name!r} is not listed in gyrocal.export.EXPORTER_MODULES; add it there")
    _REGISTRY[name] = Exporter(name, None if kinds is None else tuple(kinds), fn, suffix)


def exporter(fmt: str) -> Exporter:
    """The exporter of format `fmt`, importing its module when needed."""
    if fmt not in EXPORTER_MODULES:
        raise InputError(f"{{param}}={fmt!r} is not one of {', '.join(EXPORT_FORMATS)}", param="fmt", value=fmt)
    if fmt not in _REGISTRY:
        importlib.import_module(EXPORTER_MODULES[fmt])
    return _REGISTRY[fmt]


def render(obj_or_path: Any, fmt: str, **options) -> str:
    """The text of a calibration (an object, or a file read with :func:`gyrocal.results.files.load`) in format `fmt`.

    Parameters
    ----------
    obj_or_path : file kind or path-like
        A calibration object, or the path of any gyrocal file.
    fmt : str
        One of :data:`EXPORT_FORMATS`.
    **options
        Passed to the exporter (``prefix`` for ``c-header``).
    """
    ex = exporter(fmt)
    obj = obj_or_path
    if isinstance(obj_or_path, (str, os.PathLike)):
        from ..results.files import load

        obj = load(obj_or_path)
    if ex.kinds is not None and not isinstance(obj, ex.kinds):
        formats = [getattr(k, "FORMAT", k.__name__) for k in ex.kinds]
        made_by = {"gyrocal.noise": "gyrocal noise LOG --json noise.json", "gyrocal.thermal-bias":
                   "gyrocal thermal-bias LOG -o bias.json", "gyrocal.thermal": "gyrocal thermal SESSION -o thermal.json"}
        how = "; ".join(f"{f} is made by '{made_by[f]}'" for f in formats if f in made_by)
        raise InputError(f"{fmt} export takes {', '.join(formats)}, not {getattr(obj, 'FORMAT', type(obj).__name__)}"
                         + (f" ({how})" if how else ""), param="fmt", value=fmt)
    return ex.fn(obj, **options)


def export_file(path: str | os.PathLike, fmt: str, out: str | os.PathLike, **options) -> None:
    """Write :func:`render` of file `path` to `out`, atomically."""
    write_text_atomic(out, render(path, fmt, **options))
