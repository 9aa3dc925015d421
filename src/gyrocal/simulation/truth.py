"""The truth of a simulated recording: one document format, written beside the recording.

``gyrocal simulate -o rec.csv`` writes ``rec.truth.json`` and the bundled example has
``example_servo.truth.json``; both are a :class:`SimulationTruth`
(``format: gyrocal.simulation-truth``, version 1)::

    {
      "format": "gyrocal.simulation-truth", "version": 1,
      "protocol": "servo" | "hand" | "turntable" | "profile",
      "description": "...",
      "model": "scale-bias" | "affine",
      "units": {"b": "rad/s", "B": "rad/s"},
      "k": [...], "b": [...]           # scale-bias, the servo method of Wang et al. eq. 1
      | "K": [[...]], "B": [...],      # affine, the full-temperature-range method eq. 12
      "settings": {...},               # every setting of the simulation
      ...                              # protocol facts: mounting, windows, plateaus, thermal
    }
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from .._jsonfile import check_header, get, get_array
from .._version import __version__
from ..errors import FileFormatError, InputError, NonPhysicalEstimateError
from ..models import Affine, CalibrationModel, ScaleBias

__all__ = ["SimulationTruth", "servo_facts", "truth_path"]

_RESERVED = ("format", "version", "protocol", "description", "model", "units", "k", "b", "K", "B", "settings",
             "created_by")


def truth_path(recording: str | os.PathLike) -> Path:
    """Where the truth of a simulated recording goes: ``rec.csv`` -> ``rec.truth.json``."""
    p = Path(recording)
    return p.with_name(p.stem + ".truth.json")


def servo_facts(truth) -> dict[str, Any]:
    """The facts of a servo or hand session (:class:`~gyrocal.simulation.servo.ServoTruth`) for the document."""
    return {"mounting": truth.mounting.tolist(), "windows": [w.to_dict() for w in truth.windows],
            "plateaus": [w.to_dict() for w in truth.plateaus]}


@dataclass(frozen=True)
class SimulationTruth:
    """What a simulated recording really holds.

    Parameters
    ----------
    protocol : str
        The motion source (``servo``, ``hand``, ``turntable``, ``profile``).
    model : ScaleBias or Affine
        The gyro's true errors [rad/s for biases].
    settings : dict
        Every setting of the simulation (JSON values).
    facts : dict
        What happened: for example ``mounting``, the true ``windows`` and ``plateaus``, the
        ``thermal`` truth (JSON values; top-level keys of the document).
    description : str
        One line for a reader of the file.
    """

    FORMAT: ClassVar[str] = "gyrocal.simulation-truth"
    VERSION: ClassVar[int] = 1

    protocol: str
    model: CalibrationModel
    settings: dict = field(default_factory=dict)
    facts: dict = field(default_factory=dict)
    description: str = ""

    def __post_init__(self):
        clash = sorted(set(self.facts) & set(_RESERVED))
        if clash:
            raise InputError(f"facts may not use the document's own keys {clash}")

    def to_document(self) -> dict[str, Any]:
        """The JSON-ready document."""
        doc: dict[str, Any] = {"format": self.FORMAT, "version": self.VERSION, "protocol": self.protocol}
        if self.description:
            doc["description"] = self.description
        doc.update(model=self.model.kind, units={"b": "rad/s", "B": "rad/s"})
        if self.model.kind == "affine":
            doc.update(K=self.model.K.tolist(), B=self.model.B.tolist())
        else:
            doc.update(k=self.model.k.tolist(), b=self.model.b.tolist())
        doc["settings"] = dict(self.settings)
        doc.update(self.facts)
        doc["created_by"] = f"gyrocal {__version__}"
        return doc

    @classmethod
    def from_document(cls, doc: dict, path: Any = "document") -> SimulationTruth:
        """Rebuild from a document, naming a bad field."""
        check_header(doc, path, cls.FORMAT, (cls.VERSION,))
        kind = get(doc, "model", path)
        try:
            if kind == "scale-bias":
                model: CalibrationModel = ScaleBias(get_array(doc, "k", (3,), path), get_array(doc, "b", (3,), path))
            elif kind == "affine":
                model = Affine(get_array(doc, "K", (3, 3), path), get_array(doc, "B", (3,), path))
            else:
                raise FileFormatError(f"{path}: field 'model' is {kind!r}; expected 'scale-bias' or 'affine'", "model")
        except (InputError, NonPhysicalEstimateError) as exc:
            raise FileFormatError(f"{path}: the true model is not a gyro: {exc}", "model") from None
        settings = get(doc, "settings", path)
        if not isinstance(settings, dict):
            raise FileFormatError(f"{path}: field 'settings' must be an object", "settings")
        facts = {k: v for k, v in doc.items() if k not in _RESERVED}
        return cls(protocol=str(get(doc, "protocol", path)), model=model, settings=settings, facts=facts,
                   description=str(doc.get("description") or ""))
