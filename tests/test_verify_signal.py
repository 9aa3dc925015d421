"""The numpy stand-ins of verify for scipy.signal and scipy.spatial.transform.Rotation, against those.

Reference: scipy itself (``scipy.signal.correlate``/``correlation_lags``/``find_peaks``/``savgol_filter``,
``scipy.fft.next_fast_len``, ``Rotation.from_rotvec``/``from_matrix``/``as_rotvec``/``align_vectors``) over
random inputs and edge cases: the stand-ins must give the same numbers, to 1e-10 of the result's scale for the
signal steps, 1e-12 for the rotations, and the same indices for the peaks.
"""

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import signal
from scipy.fft import next_fast_len
from scipy.spatial.transform import Rotation

from gyrocal import quaternion
from gyrocal.verify import _signal

RTOL_SIGNAL = 1e-10
RTOL_ROTATION = 1e-12


def _close(ours, theirs, rtol):
    """Largest difference within `rtol` of the largest magnitude of the scipy result."""
    scale = max(float(np.abs(theirs).max(initial=0.0)), np.finfo(float).tiny)
    assert ours.shape == theirs.shape
    assert float(np.abs(ours - theirs).max(initial=0.0)) <= rtol * scale


def test_fast_length_is_scipys():
    assert [_signal._fast_length(n) for n in range(1, 5000)] == [next_fast_len(n, real=True) for n in range(1, 5000)]


@pytest.mark.parametrize("seed", range(5))
def test_correlate_full_and_valid_match_scipy(seed):
    rng = np.random.default_rng(seed)
    for _ in range(40):
        na, nb = (int(n) for n in rng.integers(1, 700, 2))
        a, b = rng.normal(size=na) + 3.0, rng.normal(size=nb)
        _close(_signal.correlate(a, b, "full"), signal.correlate(a, b, mode="full", method="fft"), RTOL_SIGNAL)
        assert np.array_equal(_signal.correlation_lags(na, nb), signal.correlation_lags(na, nb, mode="full"))
        long, short = (a, b) if na >= nb else (b, a)
        _close(_signal.correlate(long, short, "valid"), signal.correlate(long, short, mode="valid", method="fft"),
               RTOL_SIGNAL)


def test_correlate_edge_lengths_and_refusals():
    for a, b in ((np.ones(1), np.ones(1)), (np.arange(5.0), np.ones(1)), (np.ones(1), np.arange(5.0))):
        _close(_signal.correlate(a, b), signal.correlate(a, b, method="fft"), RTOL_SIGNAL)
    _close(_signal.correlate(np.arange(4.0), np.arange(4.0), "valid"),
           signal.correlate(np.arange(4.0), np.arange(4.0), mode="valid", method="fft"), RTOL_SIGNAL)
    with pytest.raises(ValueError):
        _signal.correlate(np.ones(2), np.ones(3), "valid")
    with pytest.raises(ValueError):
        _signal.correlate(np.ones(2), np.ones(3), "same")


@pytest.mark.parametrize("seed", range(5))
def test_find_peaks_matches_scipy_with_ties_and_plateaus(seed):
    rng = np.random.default_rng(seed)
    for _ in range(400):
        x = np.round(rng.normal(size=int(rng.integers(0, 300))), int(rng.integers(0, 3)))  # rounding makes flat tops
        height, distance = float(rng.normal()), int(rng.integers(1, 40))
        expected = signal.find_peaks(x, height=height, distance=distance)[0]
        assert np.array_equal(_signal.find_peaks(x, height, distance), expected)


def test_find_peaks_edge_cases():
    cases = [np.zeros(0), np.ones(2), np.array([0.0, 1, 1, 0]), np.array([0.0, 1, 1, 1]), np.array([2.0, 1, 2]),
             np.array([0.0, 1, 0, 1, 0, 1, 0]), np.array([0.0, 2, 2, 2, 2, 0, 1, 0])]
    for x in cases:
        for distance in (1, 2, 5):
            assert np.array_equal(_signal.find_peaks(x, 0.5, distance), signal.find_peaks(x, 0.5, distance=distance)[0])
    with pytest.raises(ValueError):
        _signal.find_peaks(np.ones(5), 0.0, 0)


@pytest.mark.parametrize("seed", range(5))
def test_savgol_slope_matches_scipy_interp(seed):
    rng = np.random.default_rng(seed)
    for _ in range(60):
        length = int(rng.integers(3, 600))
        window = min(2 * int(rng.integers(1, 40)) + 1, length - (1 - length % 2))
        x = np.cumsum(rng.normal(size=(length, 3)), axis=0) + rng.normal(size=3)
        delta = float(rng.uniform(1e-4, 2.0))
        expected = signal.savgol_filter(x, window, 2, deriv=1, delta=delta, axis=0, mode="interp")
        _close(_signal.savgol_slope(x, window, delta), expected, RTOL_SIGNAL)


def test_savgol_slope_edge_cases_and_refusals():
    t = np.linspace(0.0, 1.0, 11)
    quad = np.stack([1 + 2 * t - 3 * t**2, np.zeros_like(t), t], axis=1)  # a quadratic's slope is exact
    _close(_signal.savgol_slope(quad, 11, 0.1), np.stack([2 - 6 * t, 0 * t, 1 + 0 * t], axis=1), 1e-12)
    _close(_signal.savgol_slope(quad, 3, 0.1), signal.savgol_filter(quad, 3, 2, deriv=1, delta=0.1, axis=0),
           RTOL_SIGNAL)
    long = np.sin(np.linspace(0, 50, 20001))[:, None] * np.ones(3)
    _close(_signal.savgol_slope(long, 51, 1e-3),
           signal.savgol_filter(long, 51, 2, deriv=1, delta=1e-3, axis=0, mode="interp"), RTOL_SIGNAL)
    for window in (4, 1, 13):
        with pytest.raises(ValueError):
            _signal.savgol_slope(quad, window, 0.1)


def _random_rotvecs(rng, n):
    """Rotation vectors of every size, from tiny (series branches) to near pi."""
    axis = rng.normal(size=(n, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    angle = np.concatenate([10.0 ** rng.uniform(-9, -2, n // 4), rng.uniform(0, np.pi - 1e-6, n - n // 4)])
    return axis * angle[:, None]


def test_rotvec_matrix_and_back_match_scipy():
    rng = np.random.default_rng(7)
    phi = _random_rotvecs(rng, 2000)
    _close(quaternion.rotvec_matrix(phi), Rotation.from_rotvec(phi).as_matrix(), RTOL_ROTATION)
    mats = Rotation.from_rotvec(phi).as_matrix()
    ours, theirs = quaternion.matrix_rotvec(mats), Rotation.from_matrix(mats).as_rotvec()
    # per rotation: 1e-12 of its angle, or 1e-12 rad for angles under one radian
    tol = RTOL_ROTATION * np.maximum(np.linalg.norm(theirs, axis=1), 1.0)
    assert np.all(np.linalg.norm(ours - theirs, axis=1) <= tol)
    assert np.array_equal(quaternion.matrix_rotvec(np.eye(3)), np.zeros(3))


def test_align_vectors_matches_scipy():
    rng = np.random.default_rng(8)
    for k in range(200):
        n = 2 + k % 50
        b = rng.normal(size=(n, 3))
        truth = Rotation.from_rotvec(_random_rotvecs(rng, 4)[k % 4]).as_matrix()
        a = b @ truth.T + rng.normal(scale=10.0 ** -(k % 5), size=(n, 3))
        if k % 7 == 0:
            a = -a  # the best orthogonal map is a reflection: the rotation flips one direction
        _close(quaternion.align_vectors(a, b), Rotation.align_vectors(a, b)[0].as_matrix(), RTOL_ROTATION)


def test_verify_imports_neither_scipy_signal_nor_rotation():
    """Neither at import (a fresh interpreter's modules) nor inside any function of gyrocal.verify (its source)."""
    code = ("import sys, gyrocal.verify, gyrocal.verify.run; "
            "print(sorted(m for m in sys.modules if m.startswith(('scipy.signal', 'scipy.spatial'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
    for path in Path(_signal.__file__).parent.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            assert not any(n.startswith(("scipy.signal", "scipy.spatial")) or n == "scipy" for n in names), path
