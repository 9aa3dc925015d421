"""gyrocal._chi2.chi2_sf against scipy.special.chdtrc over a grid of degrees of freedom and arguments."""

import math

import numpy as np
import pytest
import scipy.special as scipy_special

from gyrocal._chi2 import chi2_sf


def test_matches_scipy_to_1e12_relative():
    """1e-12 relative down to p = 1e-100, 1e-11 in the far tail (the exponent's own rounding, |log p| eps)."""
    worst = tail = 0.0
    for dof in [0.3, 0.6, 1, 1.5, 2, 3, 5, 7.3, 10, 19.5, 20, 45, 83, 100, 250.7, 500, 1000, 3000]:
        for x in np.concatenate([dof * np.geomspace(1e-3, 30, 60), [1e-8, 0.1, 1.0, 50.0]]):
            want = float(scipy_special.chdtrc(dof, x))
            if want < 1e-290:
                continue
            error = abs(chi2_sf(dof, float(x)) - want) / want
            if want >= 1e-100:
                worst = max(worst, error)
            else:
                tail = max(tail, error)
    assert worst < 1e-12 and tail < 1e-11


def test_edges():
    assert chi2_sf(3, 0.0) == 1.0 and chi2_sf(3, -1.0) == 1.0
    assert chi2_sf(3, math.inf) == 0.0 and math.isnan(chi2_sf(3, math.nan))
    with pytest.raises(ValueError):
        chi2_sf(0, 1.0)
