"""Deterministic pins of 1-sigma constants and rules (issue 20)."""

import math

import numpy as np
import pytest
from scipy.stats import norm

from gyrocal import units
from gyrocal.flight.polyfit import choose_orders


def test_mad_to_sigma_is_gaussian_consistency():
    """Reference: 1 / Phi^-1(3/4) for a Gaussian (scipy), not the code's constant (used by every MAD estimate)."""
    assert units.MAD_TO_SIGMA == pytest.approx(1.0 / norm.ppf(0.75), rel=1e-12)


def test_one_standard_error_rule_picks_lower_order():
    """Reference: the 1-SE rule, threshold best * (1 + 1/sqrt(2K)), worked by hand for K = 8."""
    k = 8
    best = 1.0
    slack = 1.0 / math.sqrt(2 * k)  # 0.25
    cv = np.array([[2.0], [best * (1 + 0.9 * slack)], [best]])  # order 2 slightly better than order 1
    assert int(choose_orders(cv, k)[0]) == 1
    cv[1, 0] = best * (1 + 1.1 * slack)
    assert int(choose_orders(cv, k)[0]) == 2
