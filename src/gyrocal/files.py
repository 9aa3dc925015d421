"""One registry of gyrocal's file kinds: load any file by its ``format`` field, save any kind.

A file kind is a class with ``FORMAT`` (``"gyrocal.calibration"``), ``VERSION`` (the
version it writes), ``to_document()`` and a classmethod ``from_document(doc, path)``,
registered with :func:`register`. :func:`load` reads the JSON once, finds the kind by
``format``, upgrades old versions through :mod:`gyrocal.legacy`, validates and returns
the object; :func:`save` writes ``obj.to_document()`` atomically.

Kinds register when their module is imported; :data:`KIND_MODULES` names the module of
each known format, so that loading a file never depends on what was imported before.
"""

from __future__ import annotations

import importlib
import os
from typing import Any, Protocol, TypeVar, runtime_checkable

from ._jsonfile import read_json, write_json
from .errors import FileFormatError, InputError

__all__ = [
    "KIND_MODULES", "FileKind", "from_document", "kinds", "load", "load_calibration", "load_correction", "load_thermal",
    "register",
    "save", "save_calibration", "save_thermal",
]

#: Format name -> module that registers its kind (add a line for a new kind).
KIND_MODULES: dict[str, str] = {
    "gyrocal.calibration": "gyrocal.calibration",
    "gyrocal.thermal": "gyrocal.thermal.model",
    "gyrocal.simulation-truth": "gyrocal.simulation.truth",
    "gyrocal.noise": "gyrocal.noise_file",
    "gyrocal.thermal-bias": "gyrocal.thermal_bias_file",
    "gyrocal.verify": "gyrocal.verify.report",
}

_KINDS: dict[str, type] = {}
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
    known = _KINDS.get(fmt)
    if known is not None and known.__qualname__ != cls.__qualname__:
        raise InputError(f"format {fmt!r} is already registered to {known.__name__}")
    _KINDS[fmt] = cls
    return cls


def kinds() -> dict[str, type]:
    """Every known format and its kind (importing the modules of :data:`KIND_MODULES`)."""
    for module in KIND_MODULES.values():
        importlib.import_module(module)
    return dict(_KINDS)


def _kind(fmt: Any, path) -> type:
    if isinstance(fmt, str) and fmt not in _KINDS and fmt in KIND_MODULES:
        importlib.import_module(KIND_MODULES[fmt])
    if isinstance(fmt, str) and fmt in _KINDS:
        return _KINDS[fmt]
    known = ", ".join(sorted(kinds()))
    raise FileFormatError(f"{path}: field 'format' is {fmt!r}; gyrocal reads {known}", "format")


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
    return cls.from_document(upgrade(doc, path), path)


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
    """Write ``obj.to_document()`` to `path` as JSON, atomically."""
    fmt = getattr(type(obj), "FORMAT", None)
    if isinstance(fmt, str) and fmt not in _KINDS and fmt in KIND_MODULES:
        importlib.import_module(KIND_MODULES[fmt])  # a kind whose file code registers it from another module
    if fmt not in _KINDS or not isinstance(obj, _KINDS[fmt]):
        raise InputError(f"{type(obj).__name__} is not a registered gyrocal file kind; it cannot be saved")
    write_json(path, obj.to_document())


def load_calibration(path: str | os.PathLike):
    """Read a ``gyrocal.calibration`` file (any version) as a :class:`~gyrocal.calibration.Calibration`."""
    from .calibration import Calibration

    return load(path, Calibration)


def save_calibration(cal, path: str | os.PathLike) -> None:
    """Write a :class:`~gyrocal.calibration.Calibration` (same as :func:`save`)."""
    save(cal, path)


def load_thermal(path: str | os.PathLike):
    """Read a ``gyrocal.thermal`` file (any version) as a :class:`~gyrocal.thermal.ThermalCalibration`."""
    from .thermal.model import ThermalCalibration

    return load(path, ThermalCalibration)


def load_correction(path: str | os.PathLike):
    """Read a file that corrects data: a ``gyrocal.calibration`` or a ``gyrocal.thermal`` file.

    Any other gyrocal file (a noise file, a verify report, ...) is refused with its format named.
    """
    from .calibration import Calibration
    from .thermal.model import ThermalCalibration

    return load(path, (Calibration, ThermalCalibration))


def save_thermal(cal, path: str | os.PathLike) -> None:
    """Write a :class:`~gyrocal.thermal.ThermalCalibration` (same as :func:`save`)."""
    save(cal, path)
