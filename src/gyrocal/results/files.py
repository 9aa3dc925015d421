"""One registry of gyrocal's file kinds: load any file by its ``format`` field, save any kind.

A file kind is a class with ``FORMAT`` (``"gyrocal.calibration"``) and ``VERSION`` (the version it
writes), whose documents are made and read by ``to_document(obj)`` and ``from_document(doc, path)``:
the class's own methods, or the functions of a separate document module when the class is core
numerics (a noise report, a thermal-bias fit). :data:`KINDS` names every built-in kind by module, so
the registry imports a kind only when it meets its format and no kind imports the registry back
(no import cycle); :func:`register` adds a kind at run time. :func:`load` reads the JSON once,
finds the kind by ``format``, upgrades old versions through :mod:`gyrocal.results.legacy`, validates and
returns the object; :func:`save` writes the document atomically.
"""

from __future__ import annotations

import importlib
import os
from typing import Any, Protocol, TypeVar, runtime_checkable

from .._jsonfile import read_json, write_json
from ..errors import FileFormatError, InputError

__all__ = [
    "KINDS", "FileKind", "from_document", "kinds", "load", "load_calibration", "load_correction", "load_thermal",
    "register", "save", "save_calibration", "save_thermal", "to_document",
]

#: Format -> (module, class, module of its document functions or None: the class's own methods).
KINDS: dict[str, tuple[str, str, str | None]] = {
    "gyrocal.calibration": ("gyrocal.results.calibration", "Calibration", None),
    "gyrocal.thermal": ("gyrocal.thermal.model", "ThermalCalibration", None),
    "gyrocal.simulation-truth": ("gyrocal.simulation.truth", "SimulationTruth", None),
    "gyrocal.noise": ("gyrocal.noise.report", "NoiseReport", "gyrocal.noise.document"),
    "gyrocal.thermal-bias": ("gyrocal.flight.thermal_bias", "ThermalBias", "gyrocal.flight.thermal_bias_document"),
    "gyrocal.verify": ("gyrocal.verify.report", "VerifyReport", None),
}
#: Kinds added at run time with :func:`register`: format -> class (its own methods make its documents).
_REGISTERED: dict[str, type] = {}
T = TypeVar("T")


@runtime_checkable
class FileKind(Protocol):
    """What a registered file kind provides."""

    FORMAT: str
    VERSION: int

    def to_document(self) -> dict: ...

    @classmethod
    def from_document(cls, doc: dict, path: Any = ...) -> Any: ...


def register(cls: type[T]) -> type[T]:
    """Class decorator: register `cls` as the kind of files whose ``format`` is ``cls.FORMAT``."""
    fmt, version = getattr(cls, "FORMAT", None), getattr(cls, "VERSION", None)
    if not isinstance(fmt, str) or type(version) is not int or version < 1:
        raise InputError(f"{cls.__name__} needs FORMAT (text) and VERSION (an integer >= 1) to be a file kind")
    for name in ("to_document", "from_document"):
        if not callable(getattr(cls, name, None)):
            raise InputError(f"{cls.__name__} needs a {name} method to be a file kind")
    known = _REGISTERED.get(fmt) or (_class(fmt) if fmt in KINDS else None)
    if known is not None and known.__qualname__ != cls.__qualname__:
        raise InputError(f"format {fmt!r} is already registered to {known.__name__}")
    _REGISTERED[fmt] = cls
    return cls


def _class(fmt: str) -> type:
    module, name, _ = KINDS[fmt]
    return getattr(importlib.import_module(module), name)


def _codec(fmt: str):
    """What makes and reads documents of `fmt`: its document module, or the class itself."""
    if fmt in _REGISTERED:
        return _REGISTERED[fmt]
    codec = KINDS[fmt][2]
    return _class(fmt) if codec is None else importlib.import_module(codec)


def kinds() -> dict[str, type]:
    """Every known format and its kind."""
    return {**{fmt: _class(fmt) for fmt in KINDS}, **_REGISTERED}


def _kind(fmt: Any, path) -> type:
    if isinstance(fmt, str) and fmt in _REGISTERED:
        return _REGISTERED[fmt]
    if isinstance(fmt, str) and fmt in KINDS:
        return _class(fmt)
    known = ", ".join(sorted(kinds()))
    raise FileFormatError(f"{path}: field 'format' is {fmt!r}; gyrocal reads {known}", "format")


def to_document(obj: Any) -> dict:
    """The JSON-ready document of a file kind's object."""
    fmt = getattr(type(obj), "FORMAT", None)
    if not isinstance(fmt, str) or fmt not in KINDS and fmt not in _REGISTERED or not isinstance(obj, _kind(fmt, "")):
        raise InputError(f"{type(obj).__name__} is not a registered gyrocal file kind; it cannot be saved")
    codec = _codec(fmt)
    return obj.to_document() if isinstance(codec, type) else codec.to_document(obj)


def from_document(doc: Any, path: Any = "document", kind: type | tuple[type, ...] | None = None) -> Any:
    """The object a document describes, upgraded and validated (see :func:`load`)."""
    from .legacy import upgrade

    if not isinstance(doc, dict):
        raise FileFormatError(f"{path}: expected a JSON object at the top level, got {type(doc).__name__}")
    cls = _kind(doc.get("format"), path)
    version = doc.get("version")
    if type(version) is not int or not 1 <= version <= cls.VERSION:
        raise FileFormatError(f"{path}: field 'version' is {version!r}; this gyrocal reads {cls.FORMAT} "
                              f"versions 1 to {cls.VERSION}", "version")
    if kind is not None and not issubclass(cls, kind):
        wanted = kind if isinstance(kind, tuple) else (kind,)
        names = " or ".join(repr(getattr(k, "FORMAT", k.__name__)) for k in wanted)
        raise FileFormatError(f"{path}: field 'format' is {cls.FORMAT!r}; expected {names}", "format")
    codec = _codec(cls.FORMAT)
    return codec.from_document(upgrade(doc, path), path)


def load(path: str | os.PathLike, kind: type | tuple[type, ...] | None = None) -> Any:
    """Read, upgrade and validate a gyrocal file of any registered kind.

    Parameters
    ----------
    path : path-like
        A JSON file with a ``format`` field.
    kind : type or tuple of types, optional
        Refuse (with a :class:`~gyrocal.errors.FileFormatError`) a file of another kind.

    Raises
    ------
    FileFormatError
        Not JSON, an unknown ``format`` (the message lists the known ones), an unsupported
        ``version``, or a malformed field (named in ``field``).
    """
    return from_document(read_json(path), path, kind)


def save(obj: Any, path: str | os.PathLike) -> None:
    """Write the document of `obj` (:func:`to_document`) to `path` as JSON, atomically."""
    write_json(path, to_document(obj))


def load_calibration(path: str | os.PathLike):
    """Read a ``gyrocal.calibration`` file (any version) as a :class:`~gyrocal.results.calibration.Calibration`."""
    from .calibration import Calibration

    return load(path, Calibration)


def save_calibration(cal, path: str | os.PathLike) -> None:
    """Write a :class:`~gyrocal.results.calibration.Calibration` (same as :func:`save`)."""
    save(cal, path)


def load_thermal(path: str | os.PathLike):
    """Read a ``gyrocal.thermal`` file (any version) as a :class:`~gyrocal.thermal.ThermalCalibration`."""
    from ..thermal.model import ThermalCalibration

    return load(path, ThermalCalibration)


def load_correction(path: str | os.PathLike):
    """Read a file that corrects data: a ``gyrocal.calibration`` or a ``gyrocal.thermal`` file.

    Any other gyrocal file (a noise file, a verify report, ...) is refused with its format named.
    """
    from ..thermal.model import ThermalCalibration
    from .calibration import Calibration

    return load(path, (Calibration, ThermalCalibration))


def save_thermal(cal, path: str | os.PathLike) -> None:
    """Write a :class:`~gyrocal.thermal.ThermalCalibration` (same as :func:`save`)."""
    save(cal, path)
