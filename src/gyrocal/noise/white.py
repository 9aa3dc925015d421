"""The white-noise density: the -1/2 line fitted where the Allan deviation follows it, read at 1 s.

IEEE Std 952 (annex C) reads the angle random walk N on the -1/2 line at ``tau = 1 s``, the value
Kalibr, imu_utils and allan_variance_ros users expect. The line is fitted, slope fixed at -1/2,
to ``log adev + log(tau) / 2`` weighted by each point's edf (white noise), over the contiguous
range around 1 s where

* the local log-log slope stays within ``SLOPE_TOLERANCE`` (plus twice its own sigma) of -1/2, and
* what bends the curve there is below half a point's own spread: a weighted fit of
  ``adev^2 tau = N^2 + D / tau + F tau`` over that run measures the short-tau departure ``D``
  (filter, quantisation, resonances all fall as 1/tau^2 in the Allan variance once tau is past
  them) and the long-tau one ``F`` (flicker, random walk); points where ``|D/tau|`` or ``|F tau|``
  shifts adev by more than ``KAPPA`` of its sigma are left out;
* then points off the fitted line by 3 sigmas are cut away (what that model misses, a bump's
  skirt), and the range starts ``MARGIN`` times above the largest tau where the curve is off it.

The points share the same samples, so their errors correlate. The interval uses the fit's
variance ``w' C w`` with ``C_ij = s_i s_j rho(tau_i / tau_j)``, ``s_i = 1 / sqrt(2 edf_i)``:
``rho = exp(-ln(r)^2 / RHO_WIDTH)`` is the correlation of overlapping log Allan deviations of
white noise, measured on 450 numpy white-noise curves at 12 points per decade (0.88 at a ratio
1.33, 0.53 at 2, 0.28 at 3, under 0.1 past 5). That variance gives an effective dof and the
chi-squared interval. A curve off the line at short tau gives a departure to warn about.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .allan import confidence, edf

__all__ = ["WhiteLine", "fit_white_line"]

#: Local slope within this of -1/2: the run the fit may use.
SLOPE_TOLERANCE = 0.15
#: A point is used while the measured bend shifts it by at most this many of its sigmas.
KAPPA = 0.5
#: Width of the correlation model in (ln tau ratio)^2, measured on white noise.
RHO_WIDTH = 0.8
#: Off the line by more than this (and 4 of its sigmas) below the fit: the curve leaves the line.
DEPART = 0.03
#: The fit starts at least this factor above the largest tau where the curve is off the line.
MARGIN = 3.0
#: Fallback when no point is within tolerance: the closest slope within this.
_LOOSE = 0.25


@dataclass(frozen=True)
class WhiteLine:
    """The fitted -1/2 line: ``value`` at 1 s with its interval and effective dof, the tau range
    fitted, and where the curve leaves the line at short tau: ``depart_tau`` below which (NaN when
    it does not), ``offsets`` the worst relative offsets below and above the line as (offset, tau)."""

    value: float
    low: float
    high: float
    edf: float
    tau_min: float
    tau_max: float
    depart_tau: float = math.nan
    offsets: tuple = ()


def _run(ok: np.ndarray, a: int, top: int) -> tuple[int, int]:
    lo = hi = a
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    while hi < top and ok[hi + 1]:
        hi += 1
    return lo, hi


def _slope_sd(lt: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Sigma of np.gradient's local slope from the points' sigmas and correlation."""
    i = np.arange(len(lt))
    lo, hi = np.maximum(i - 1, 0), np.minimum(i + 1, len(lt) - 1)
    rho = np.exp(-(lt[hi] - lt[lo]) ** 2 / RHO_WIDTH)
    var = s[hi] ** 2 + s[lo] ** 2 - 2 * rho * s[hi] * s[lo]
    return np.sqrt(np.maximum(var, 0.0)) / np.maximum(lt[hi] - lt[lo], 1e-12)


def _anchor(lt: np.ndarray, off: np.ndarray, top: int) -> tuple[int, float] | None:
    """Index nearest 1 s on the short side of the minimum whose slope offset is within tolerance."""
    idx = np.arange(top + 1)
    for tol in (1.0, _LOOSE / SLOPE_TOLERANCE):
        cand = idx[off[idx] <= tol]
        if len(cand):
            return int(cand[np.argmin(np.abs(lt[cand]))]), tol
    return None


def _rho(lt: np.ndarray) -> np.ndarray:
    return np.exp(-np.subtract.outer(lt, lt) ** 2 / RHO_WIDTH)


def _bends(taus, adev, dof, s) -> tuple[float, float, float]:
    """``N^2, D, F`` of ``adev^2 tau = N^2 + D / tau + F tau``; D zero unless over 3 of its sigmas, F 2
    (a false D costs the short taus' dof, a false F only the long taus', which weigh little)."""
    y = adev**2 * taus
    x = np.column_stack([np.ones(len(taus)), 1.0 / taus, taus])
    w = dof / y**2  # var(adev^2) = 2 adev^4 / edf
    xtw = x.T * w
    inv = np.linalg.inv(xtw @ x)
    coef = inv @ xtw @ y
    cov_y = np.outer(2 * s * y, 2 * s * y) * _rho(np.log(taus))  # the points correlate
    sd = np.sqrt(np.diag(inv @ xtw @ cov_y @ xtw.T @ inv))
    n2, d, f = (c if abs(c) > z * e else 0.0 for c, e, z in zip(coef, sd, (0.0, 3.0, 2.0)))
    return n2, d, f


def _trim(taus, adev, dof, s, lo, hi, a) -> tuple[int, int]:
    """Narrow [lo, hi] to where the measured short- and long-tau bends stay under KAPPA sigmas."""
    if hi - lo < 3:
        return lo, hi
    sl = slice(lo, hi + 1)
    n2, d, f = _bends(taus[sl], adev[sl], dof[sl], s[sl])
    if not n2 > 0:
        return a, a
    short, long_ = np.abs(d / taus) / (2 * n2), np.abs(f * taus) / (2 * n2)
    idx = np.arange(len(taus))
    inside = (idx >= lo) & (idx <= hi)
    ok_lo, ok_hi = np.flatnonzero(inside & (short <= KAPPA * s)), np.flatnonzero(inside & (long_ <= KAPPA * s))
    if len(ok_lo) and len(ok_hi) and ok_lo[0] <= ok_hi[-1]:
        return int(ok_lo[0]), int(ok_hi[-1])
    best = lo + int(np.argmin(((short + long_) / s)[sl]))
    return best, best


def _fit(lt, adev, dof, s, lo, hi) -> tuple[float, float]:
    """ln N of the edf-weighted -1/2 line over [lo, hi], and its sigma from the correlated points."""
    sl = slice(lo, hi + 1)
    w = dof[sl] / dof[sl].sum()
    var = float(w @ (_rho(lt[sl]) * np.outer(s[sl], s[sl])) @ w)  # correlated points: not 1 / sum(edf)
    return float(np.sum(w * (np.log(adev[sl]) + 0.5 * lt[sl]))), math.sqrt(var)


def _off_line(lt, adev, s, ln_n, s_fit, limit: float = 3.0) -> np.ndarray:
    """Points off the line by more than `limit` sigmas (theirs and the fit's), and DEPART."""
    off = np.log(adev) + 0.5 * lt - ln_n
    return np.abs(off) > np.maximum(DEPART if limit > 3 else 0.0, limit * np.hypot(s, s_fit))


def _departure(taus, adev, s, lo, ln_n, s_fit) -> tuple[float, tuple]:
    """Below the fit: the largest tau off the line (over DEPART and 4 sigmas), the worst offsets down and up."""
    lt = np.log(taus[:lo])
    bad = np.flatnonzero(_off_line(lt, adev[:lo], s[:lo], ln_n, s_fit, 4.0))
    if not len(bad):
        return math.nan, ()
    off = adev[:lo] * np.sqrt(taus[:lo]) / math.exp(ln_n) - 1.0
    worst = [int(i) for i in (np.argmin(off), np.argmax(off)) if i in bad]
    return float(taus[bad[-1]]), tuple((float(off[i]), float(taus[i])) for i in dict.fromkeys(worst))


def fit_white_line(taus, adev, fs: float, n: int, *, i_min: int, mult: float, level: float) -> WhiteLine | None:
    """The -1/2 line of one Allan deviation curve (None where no point is near slope -1/2).

    `i_min`: index of the curve's minimum (the line is sought at or before it); `mult`: dof
    factor (3 for the pooled sensor row).
    """
    lt = np.log(taus)
    dof = mult * np.array([edf(0, round(t * fs), n) for t in taus])
    s = 1.0 / np.sqrt(2.0 * dof)
    # slope offset in tolerances; a slope's own noise (2 sigma) widens its tolerance
    off = np.abs(np.gradient(np.log(adev), lt) + 0.5) / (SLOPE_TOLERANCE + 2 * _slope_sd(lt, s))
    found = _anchor(lt, off, max(i_min, 1))
    if found is None:
        return None
    a, tol = found
    lo, hi = _run(off <= tol, a, max(i_min, 1))
    lo, hi = _trim(taus, adev, dof, s, lo, hi, a)
    ln_n, s_fit = _fit(lt, adev, dof, s, lo, hi)
    for _ in range(8):  # what the bends' model misses (a bump's skirt): narrow past points off the line
        bad = np.flatnonzero(_off_line(lt, adev, s, ln_n, s_fit)[lo:hi + 1]) + lo
        below, above = bad[bad < a], bad[bad > a]
        if not (len(below) or len(above)):
            break
        lo, hi = (below[-1] + 1 if len(below) else lo), (above[0] - 1 if len(above) else hi)
        ln_n, s_fit = _fit(lt, adev, dof, s, lo, hi)
    depart = _departure(taus, adev, s, lo, ln_n, s_fit)
    if np.isfinite(depart[0]) and taus[lo] < MARGIN * depart[0]:  # a bump's skirt reaches past where it shows
        lo = min(int(np.searchsorted(taus, MARGIN * depart[0])), a)
        ln_n, s_fit = _fit(lt, adev, dof, s, lo, hi)
        depart = _departure(taus, adev, s, lo, ln_n, s_fit)
    dof_fit = 1.0 / (2.0 * s_fit**2)
    value = math.exp(ln_n)
    low, high = confidence(value, dof_fit, level)
    return WhiteLine(value, low, high, dof_fit, float(taus[lo]), float(taus[hi]), *depart)
