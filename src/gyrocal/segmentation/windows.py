"""Windows of a recording: where the gyro turned, and where it stood still."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Literal

import numpy as np

from ..errors import InputError

__all__ = ["Window", "WindowKind", "axis_vector"]

WindowKind = Literal["rotation", "static"]


@dataclass(frozen=True)
class Window:
    """A span of samples ``start:stop`` (stop exclusive) and what happened in it.

    Attributes
    ----------
    start, stop : int
        Sample indices.
    kind : {"rotation", "static"}
    axis : {"x", "y", "z"} or None
        Body axis closest to the rotation axis (rotations only).
    sign : int
        +1 or -1 for the sense of the turn about `axis`; 0 for static windows.
    angle : float
        Angle turned inside the window [rad]: measured, or declared by a windows file; NaN if unknown.
    rate : float
        Mean rate magnitude inside the window [rad/s], NaN if unknown.
    label : str
        Free text (for example imucal's section name ``x_rot``).
    """

    start: int
    stop: int
    kind: WindowKind
    axis: Literal["x", "y", "z"] | None = None
    sign: int = 0
    angle: float = math.nan
    rate: float = math.nan
    label: str = ""

    def __post_init__(self):
        if self.kind not in ("rotation", "static"):
            raise InputError(f"window kind must be 'rotation' or 'static', got {self.kind!r}")
        if not (0 <= int(self.start) < int(self.stop)):
            raise InputError(f"window {self.label or ''} needs 0 <= start < stop, got {self.start}:{self.stop}")
        if self.axis not in (None, "x", "y", "z"):
            raise InputError(f"window axis must be x, y or z, got {self.axis!r}")

    def __len__(self) -> int:
        return self.stop - self.start

    def to_dict(self) -> dict:
        """JSON-ready record (angles in degrees for people; NaN becomes null)."""
        # A shallow dict: asdict() deep-copies and is slow on thousands of windows.
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        d["angle_deg"] = None if math.isnan(self.angle) else math.degrees(self.angle)
        d["rate"] = None if math.isnan(self.rate) else self.rate
        del d["angle"]
        return d

    @classmethod
    def from_dict(cls, d: dict) -> Window:
        """The window of a record written by :meth:`to_dict` (as kept in a calibration file)."""
        angle, rate = d.get("angle_deg"), d.get("rate")
        return cls(int(d["start"]), int(d["stop"]), d["kind"], d.get("axis"), int(d.get("sign") or 0),
                   math.nan if angle is None else math.radians(angle), math.nan if rate is None else float(rate),
                   str(d.get("label") or ""))


def axis_vector(name: str) -> np.ndarray:
    """Unit vector of a signed axis name such as ``"+x"`` or ``"-z"``."""
    key = str(name).strip().lower()
    if len(key) == 1:
        key = "+" + key
    if len(key) != 2 or key[0] not in "+-" or key[1] not in "xyz":
        raise InputError(f"axis {name!r} is not one of +x, -x, +y, -y, +z, -z")
    e = np.zeros(3)
    e["xyz".index(key[1])] = 1.0 if key[0] == "+" else -1.0
    return e
