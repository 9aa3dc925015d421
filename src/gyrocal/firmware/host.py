"""The C library on the host: build it with the host's C compiler and call it through ctypes.

:func:`load_library` compiles ``gyrocal/c/gyrocal_cal.c`` (plus any driver sources) into a
cache folder, once per content, and returns a :class:`CLibrary` whose methods call the C
functions one sample at a time, as a device would, so tests and tools can check the C
library against Python.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._atomic import atomic_path
from .._validation import finite_array, positive
from ..errors import (
    ConvergenceError,
    DegenerateDesignError,
    GyrocalError,
    InputError,
    MissingDependencyError,
    NonPhysicalEstimateError,
    OutOfRangeError,
)

__all__ = ["C_FLAGS", "STATUS", "CCompileError", "CLibrary", "build_library", "c_source_dir", "find_c_compiler",
           "load_library"]

#: Host flags: strict C99 and no fused multiply-add, so host results are plain float32 operations.
C_FLAGS: tuple[str, ...] = ("-std=c99", "-O2", "-fPIC", "-shared", "-ffp-contract=off", "-Wall", "-Wextra")


class CCompileError(GyrocalError):
    """The host C compiler failed on the gyrocal C library."""


def c_source_dir() -> Path:
    """Folder of the shipped C library (``gyrocal_cal.h``, ``gyrocal_cal.c``)."""
    return Path(__file__).resolve().parent.parent / "c"


# -- host build ------------------------------------------------------------------------------------------------


def find_c_compiler() -> str | None:
    """Path of the host C compiler: ``$CC``, else ``cc``, ``gcc`` or ``clang``; None if there is none."""
    for name in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if name:
            path = shutil.which(name)
            if path:
                return path
    return None


def _default_cache_dir() -> Path:
    base = os.environ.get("GYROCAL_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "gyrocal"
    )
    return Path(base) / "c"


def build_library(
    cache_dir: str | os.PathLike | None = None,
    *,
    extra_sources: Sequence[str | os.PathLike] = (),
    include_dirs: Sequence[str | os.PathLike] = (),
) -> Path:
    """Compile the C library (plus `extra_sources`) into a shared object, once per content.

    The file name carries a hash of the compiler, the flags and every source and header,
    so an edit rebuilds and an unchanged tree reuses the cached build.

    Parameters
    ----------
    cache_dir : path-like, optional
        Where builds go; default ``$GYROCAL_CACHE_DIR/c`` or ``~/.cache/gyrocal/c``.
    extra_sources : sequence of path-like
        More C files to link in (for example a driver that includes a generated header).
    include_dirs : sequence of path-like
        More header folders (for example where a generated header was written).
    """
    cc = find_c_compiler()
    if cc is None:
        raise MissingDependencyError("no C compiler found; install one (apt-get install gcc) or set CC")
    src = c_source_dir()
    sources = [*sorted(src.glob("*.c")), *map(Path, extra_sources)]
    incs = [src, *map(Path, include_dirs)]
    digest = hashlib.sha256("\0".join([cc, *C_FLAGS]).encode())
    for path in sources + sorted(p for d in incs for p in Path(d).glob("*.h")):
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    suffix = {"darwin": ".dylib", "win32": ".dll"}.get(sys.platform, ".so")
    out = Path(cache_dir or _default_cache_dir()) / f"libgyrocal_cal-{digest.hexdigest()[:16]}{suffix}"
    if out.exists():
        return out
    with atomic_path(out) as tmp:
        cmd = [cc, *C_FLAGS, *(f"-I{d}" for d in incs), *map(str, sources), "-o", str(tmp), "-lm"]
        proc = subprocess.run(cmd, check=False, capture_output=True, text=True)
        if proc.returncode != 0:
            raise CCompileError(f"{Path(cc).name} failed on the gyrocal C library: {proc.stderr.strip()[:2000]}")
    return out


# -- ctypes view -----------------------------------------------------------------------------------------------

_F3 = ctypes.c_float * 3


class _Affine(ctypes.Structure):
    _fields_ = [("matrix", _F3 * 3), ("offset", _F3)]


class _Imu(ctypes.Structure):
    _fields_ = [("gyro", _Affine), ("accel", _Affine), ("g_sens", _F3 * 3)]


class _ScaleBias(ctypes.Structure):
    _fields_ = [("k", _F3), ("b", _F3)]


class _Thermal(ctypes.Structure):
    _fields_ = [("n", ctypes.c_uint16), ("temps", ctypes.POINTER(ctypes.c_float)),
                ("kg", ctypes.POINTER(ctypes.c_float * 12))]


class _Accum(ctypes.Structure):
    _fields_ = [(name, _F3) for name in ("first", "s1", "c1", "s2", "c2")] + [("count", ctypes.c_uint32)]


class _Obs(ctypes.Structure):
    _fields_ = [("mean", _F3), ("mean_sq", _F3), ("rate", ctypes.c_float)]


_P = ctypes.POINTER
_SIGNATURES = {
    "gyrocal_correct": (ctypes.c_int, [_P(_Affine), _P(ctypes.c_float), _P(ctypes.c_float)]),
    "gyrocal_imu_correct": (ctypes.c_int, [_P(_Imu), _P(ctypes.c_float), _P(ctypes.c_float), _P(ctypes.c_float),
                                           _P(ctypes.c_float)]),
    "gyrocal_scale_bias_to_affine": (ctypes.c_int, [_P(_ScaleBias), _P(_Affine)]),
    "gyrocal_thermal_correct": (ctypes.c_int, [_P(_Thermal), ctypes.c_float, _P(ctypes.c_float), ctypes.c_uint,
                                               _P(ctypes.c_float)]),
    "gyrocal_temp_filter": (ctypes.c_float, [_P(ctypes.c_float), ctypes.c_float, ctypes.c_float]),
    "gyrocal_accum_reset": (None, [_P(_Accum)]),
    "gyrocal_accum_add": (None, [_P(_Accum), _P(ctypes.c_float)]),
    "gyrocal_accum_finish": (ctypes.c_int, [_P(_Accum), ctypes.c_float, _P(_Obs)]),
    "gyrocal_algorithm1": (ctypes.c_int, [_P(_Obs), _P(_ScaleBias), _P(ctypes.c_int)]),
    "gyrocal_first_moment": (ctypes.c_int, [_P(_Obs), _P(_ScaleBias), _P(ctypes.c_int)]),
}

#: gyrocal_status_t codes (gyrocal_cal.h) and the Python error each one becomes.
STATUS = {1: ("GYROCAL_E_INPUT", InputError), 2: ("GYROCAL_E_SINGULAR", DegenerateDesignError),
          3: ("GYROCAL_E_NONPHYSICAL", NonPhysicalEstimateError), 4: ("GYROCAL_E_NOCONV", ConvergenceError),
          5: ("GYROCAL_E_RANGE", OutOfRangeError)}


def _f32(name: str, value, shape_tail: tuple[int, ...]) -> np.ndarray:
    return np.ascontiguousarray(finite_array(name, value, shape_tail=shape_tail), dtype=np.float32)


def _ptr(arr: np.ndarray):
    return arr.ctypes.data_as(ctypes.POINTER(ctypes.c_float))


@dataclass(frozen=True)
class CLibrary:
    """The compiled C library seen from Python, one call per sample as on a device.

    Every method returns float32 arrays and turns a C status into the matching
    :class:`~gyrocal.errors.GyrocalError` (``GYROCAL_E_SINGULAR`` is a
    :class:`~gyrocal.errors.DegenerateDesignError`, and so on).
    """

    dll: ctypes.CDLL
    path: Path

    def _check(self, status: int, what: str, iterations: int = 0) -> None:
        if status == 0:
            return
        name, cls = STATUS.get(status, (f"status {status}", GyrocalError))
        message = f"the C library's {what} returned {name}"
        if cls is ConvergenceError:
            raise cls(f"{message}: did not converge after {iterations} iterations", iterations)
        raise cls(message)

    def correct(self, matrix, offset, raw) -> np.ndarray:
        """``gyrocal_correct`` on every row of `raw` (N, 3)."""
        cal = _Affine()
        ctypes.memmove(cal.matrix, _f32("matrix", matrix, (3, 3)).ctypes.data, 36)
        ctypes.memmove(cal.offset, _f32("offset", offset, (3,)).ctypes.data, 12)
        m = _f32("raw", raw, (3,)).reshape(-1, 3)
        out = np.empty_like(m)
        for i in range(len(m)):
            self._check(self.dll.gyrocal_correct(ctypes.byref(cal), _ptr(m[i]), _ptr(out[i])), "correction")
        return out

    def imu_correct(self, gyro, accel, g_sens, gyro_raw, accel_raw) -> tuple[np.ndarray, np.ndarray]:
        """``gyrocal_imu_correct`` on every row; `gyro` and `accel` are ``(matrix, offset)`` pairs,
        `g_sens` (3, 3); returns the corrected rates and accelerations (N, 3) each."""
        imu = _Imu()
        for part, (matrix, offset) in ((imu.gyro, gyro), (imu.accel, accel)):
            ctypes.memmove(part.matrix, _f32("matrix", matrix, (3, 3)).ctypes.data, 36)
            ctypes.memmove(part.offset, _f32("offset", offset, (3,)).ctypes.data, 12)
        ctypes.memmove(imu.g_sens, _f32("g_sens", g_sens, (3, 3)).ctypes.data, 36)
        g, a = _f32("gyro_raw", gyro_raw, (3,)).reshape(-1, 3), _f32("accel_raw", accel_raw, (3,)).reshape(-1, 3)
        w_out, a_out = np.empty_like(g), np.empty_like(a)
        for i in range(len(g)):
            status = self.dll.gyrocal_imu_correct(ctypes.byref(imu), _ptr(g[i]), _ptr(a[i]), _ptr(w_out[i]),
                                                  _ptr(a_out[i]))
            self._check(status, "whole-IMU correction")
        return w_out, a_out

    def thermal_correct(self, temps, kg, temp, raw, clamp: bool = False) -> np.ndarray:
        """``gyrocal_thermal_correct`` on every row of `raw` (N, 3) at temperatures `temp` (N,) [degC]."""
        t = _f32("temps", temps, ())
        k = _f32("kg", kg, (12,))
        table = _Thermal(len(t), _ptr(t), k.ctypes.data_as(ctypes.POINTER(ctypes.c_float * 12)))
        m = _f32("raw", raw, (3,)).reshape(-1, 3)
        tt = np.broadcast_to(_f32("temp", temp, ()), (len(m),))
        out = np.empty_like(m)
        for i in range(len(m)):
            status = self.dll.gyrocal_thermal_correct(ctypes.byref(table), float(tt[i]), _ptr(m[i]), int(clamp),
                                                      _ptr(out[i]))
            self._check(status, f"thermal correction at {float(tt[i]):g} degC")
        return out

    def temp_filter(self, temp, sample_rate: float, tau: float) -> np.ndarray:
        """``gyrocal_temp_filter`` over readings `temp` (N,) [degC], starting from the first."""
        t = _f32("temp", temp, ())
        alpha = -np.expm1(-1.0 / (positive("sample_rate", sample_rate) * positive("tau", tau)))
        state = ctypes.c_float(t[0] if len(t) else 0.0)
        return np.array([self.dll.gyrocal_temp_filter(ctypes.byref(state), float(x), alpha) for x in t], np.float32)

    def accumulate(self, samples, rate: float = 1.0) -> tuple[np.ndarray, np.ndarray, int]:
        """Stream `samples` (N, 3) through the accumulator; ``(mean, mean_sq, count)``."""
        m = _f32("samples", samples, (3,)).reshape(-1, 3)
        acc, obs = _Accum(), _Obs()
        self.dll.gyrocal_accum_reset(ctypes.byref(acc))
        for i in range(len(m)):
            self.dll.gyrocal_accum_add(ctypes.byref(acc), _ptr(m[i]))
        self._check(self.dll.gyrocal_accum_finish(ctypes.byref(acc), float(rate), ctypes.byref(obs)), "accumulator")
        return np.array(obs.mean, np.float32), np.array(obs.mean_sq, np.float32), int(acc.count)

    def _six(self, func: str, mean, mean_sq, rate) -> tuple[np.ndarray, np.ndarray, int]:
        mu, sq, r = _f32("mean", mean, (6, 3)), _f32("mean_sq", mean_sq, (6, 3)), _f32("rate", rate, (6,))
        if mu.shape != (6, 3) or sq.shape != (6, 3) or r.shape != (6,):
            raise InputError(f"the C solvers take exactly six observations, got mean {mu.shape} and rate {r.shape}")
        obs = (_Obs * 6)(*(_Obs(_F3(*mu[i]), _F3(*sq[i]), float(r[i])) for i in range(6)))
        out, it = _ScaleBias(), ctypes.c_int(0)
        self._check(getattr(self.dll, func)(obs, ctypes.byref(out), ctypes.byref(it)), func, it.value)
        return np.array(out.k, np.float32), np.array(out.b, np.float32), it.value

    def algorithm1(self, mean_sq, mean, rate) -> tuple[np.ndarray, np.ndarray, int]:
        """The servo method of Wang et al., Algorithm 1 on six windows; ``(k, b, iterations)``."""
        return self._six("gyrocal_algorithm1", mean, mean_sq, rate)

    def first_moment(self, mean, rate) -> tuple[np.ndarray, np.ndarray, int]:
        """First-moment estimator on six rotation windows; ``(k, b, iterations)``."""
        mu = np.asarray(mean, dtype=float)
        return self._six("gyrocal_first_moment", mu, mu * mu, rate)


def load_library(
    cache_dir: str | os.PathLike | None = None,
    *,
    extra_sources: Sequence[str | os.PathLike] = (),
    include_dirs: Sequence[str | os.PathLike] = (),
) -> CLibrary:
    """Build (see :func:`build_library`) and load the C library with ctypes."""
    path = build_library(cache_dir, extra_sources=extra_sources, include_dirs=include_dirs)
    dll = ctypes.CDLL(str(path))
    for name, (restype, argtypes) in _SIGNATURES.items():
        fn = getattr(dll, name)
        fn.restype, fn.argtypes = restype, argtypes
    return CLibrary(dll=dll, path=path)
