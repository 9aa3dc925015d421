"""Rate profiles for ``gyrocal simulate --protocol profile``: a CSV of ``t, wx, wy, wz``."""

from __future__ import annotations

import os

import numpy as np

from ..errors import InputError
from ..units import to_rad_s
from .csvfile import read_csv_columns

__all__ = ["read_profile"]


def read_profile(path: str | os.PathLike, *, units: str = "rad/s") -> tuple[np.ndarray, np.ndarray]:
    """Read a profile CSV with columns ``t, wx, wy, wz`` (header row) into ``(t [s], w [rad/s])``."""
    cols, _ = read_csv_columns(path)
    if "t" not in cols:
        raise InputError(f"{os.fspath(path)}: a rate profile needs a time column 't' [s]")
    return np.asarray(cols["t"], float), to_rad_s(np.stack([cols["gx"], cols["gy"], cols["gz"]], axis=1), units)
