"""The chi-square survival function in plain Python: scipy.special's import costs more than a calibration's start.

``chi2_sf(dof, x) = Q(dof / 2, x / 2)``, the regularised upper incomplete gamma function: a power
series for P below ``x / 2 = a + 1``, a continued fraction for Q above (Numerical Recipes 6.2), with
the factor ``z^a e^-z / Gamma(a)`` formed without cancelling large logarithms (as Cephes does). It
agrees with ``scipy.special.chdtrc`` to 1e-12 relative (tests/test_chi2.py).
"""

from __future__ import annotations

import math

__all__ = ["chi2_sf"]

_TINY = 1e-300
_EPS = 1e-16
_STIRLING = (1 / 12, -1 / 360, 1 / 1260, -1 / 1680, 1 / 1188, -691 / 360360, 1 / 156)


def chi2_sf(dof: float, x: float) -> float:
    """P(X > x) for X chi-square distributed with `dof` > 0 degrees of freedom (any real dof)."""
    if not dof > 0:
        raise ValueError(f"dof must be > 0, got {dof}")
    if math.isnan(x):
        return math.nan
    if x <= 0:
        return 1.0
    if math.isinf(x):
        return 0.0
    a, z = 0.5 * dof, 0.5 * x
    return 1.0 - _lower_series(a, z) if z < a + 1 else _upper_fraction(a, z)


def _log1pmx(t: float) -> float:
    """``log(1 + t) - t`` without cancellation near 0."""
    if abs(t) > 0.5:
        return math.log1p(t) - t
    total, power, k = 0.0, t * t, 2
    while True:
        term = power / k
        total -= term if k % 2 == 0 else -term
        if abs(term) < _EPS * abs(total):
            return total
        power *= t
        k += 1


def _factor(a: float, z: float) -> float:
    """``z^a e^-z / Gamma(a)``; for large `a` through ``log1p`` and Stirling's series."""
    if a < 10:
        return math.exp(a * math.log(z) - z - math.lgamma(a))
    inv, inv2 = 1.0 / a, 1.0 / (a * a)
    stirling = inv * sum(c * inv2**k for k, c in enumerate(_STIRLING))
    return math.exp(a * _log1pmx((z - a) / a) - stirling) * math.sqrt(a / (2 * math.pi))


def _lower_series(a: float, z: float) -> float:
    """P(a, z) by its power series (for z < a + 1)."""
    term = total = 1.0 / a
    n = a
    for _ in range(100_000):
        n += 1
        term *= z / n
        total += term
        if term < _EPS * total:
            break
    return total * _factor(a, z)


def _upper_fraction(a: float, z: float) -> float:
    """Q(a, z) by its continued fraction, modified Lentz (for z >= a + 1)."""
    b = z + 1 - a
    c, d = 1 / _TINY, 1 / b
    h = d
    for i in range(1, 100_000):
        an = -i * (i - a)
        b += 2
        d = an * d + b
        d = _TINY if abs(d) < _TINY else d
        c = b + an / c
        c = _TINY if abs(c) < _TINY else c
        d = 1 / d
        delta = d * c
        h *= delta
        if abs(delta - 1) < _EPS:
            break
    return h * _factor(a, z)
