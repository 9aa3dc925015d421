"""3-node Lagrange interpolation (the full-temperature-range method, eq. 21-22) and its stencil and range rules.

References: quadratics reproduced exactly, node values hit exactly, and the stencil rule of
docs/thermal.md written out node by node.
"""

import warnings

import numpy as np
import pytest

from gyrocal.errors import InputError, OutOfRangeError
from gyrocal.thermal import ThermalRangeWarning
from gyrocal.thermal.lagrange import interpolate, lagrange_weights, stencil

NODES = np.array([-40.0, -30, -20, -10, 0, 10, 20, 30, 40, 50])


def _paper_eq22(tk, t2, t1, t0):
    """Eq. 22 as printed: nodes T(i-2), T(i-1), T(i) and their weights L2, L1, L0."""
    L0 = (tk - t2) * (tk - t1) / ((t0 - t2) * (t0 - t1))
    L1 = (tk - t2) * (tk - t0) / ((t1 - t2) * (t1 - t0))
    L2 = (tk - t0) * (tk - t1) / ((t2 - t0) * (t2 - t1))
    return np.array([L2, L1, L0])


def test_interior_interval_uses_nodes_i_minus_2_to_i_as_in_the_paper():
    # 25 degC lies in (T(i-1), T(i)) = (20, 30): the paper uses 10, 20, 30
    idx, w = lagrange_weights(NODES, [25.0])
    assert NODES[idx[0]].tolist() == [10, 20, 30]
    np.testing.assert_allclose(w[0], _paper_eq22(25.0, 10, 20, 30), rtol=1e-14)


def test_first_interval_uses_the_first_three_nodes():
    idx, _ = lagrange_weights(NODES, [-40.0, -35.0, -30.0, -25.0])
    assert idx[:, 0].tolist() == [0, 0, 0, 0]


def test_stencil_follows_the_documented_rule_at_every_node_and_interval():
    """The rule in words (docs/thermal.md): inside (T[i-1], T[i]) with i >= 2 and at T[i] itself, nodes i-2..i;
    in [T[0], T[1]], nodes 0..2. Written out node by node, not with searchsorted."""
    n = len(NODES)
    temps, want = [], []
    for i in range(n):
        temps.append(NODES[i])
        want.append(max(i - 2, 0))
        if i >= 1:
            temps.append((NODES[i - 1] + NODES[i]) / 2)
            want.append(max(i - 2, 0))
    assert stencil(NODES, np.array(temps)).tolist() == want


def test_weights_sum_to_one_and_reproduce_quadratics_exactly(rng):
    t = rng.uniform(-40, 50, 200)
    _, w = lagrange_weights(NODES, t)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
    c = rng.normal(size=(3, 4))
    values = c[0] + c[1] * NODES[:, None] + c[2] * NODES[:, None] ** 2
    np.testing.assert_allclose(interpolate(NODES, values, t), c[0] + c[1] * t[:, None] + c[2] * t[:, None] ** 2,
                               rtol=1e-9, atol=1e-9)


def test_nodes_are_hit_exactly(rng):
    values = rng.normal(size=(len(NODES), 12))
    np.testing.assert_allclose(interpolate(NODES, values, NODES), values, atol=1e-13)


def test_outside_the_range_is_refused_by_default_naming_the_temperature():
    with pytest.raises(OutOfRangeError, match=r"\[-40, 50\] degC, e.g. -45.00 degC"):
        lagrange_weights(NODES, [0.0, -45.0])


def test_readings_within_the_margin_of_an_end_node_count_as_at_it(rng):
    values = rng.normal(size=(len(NODES), 2))
    lo, hi = NODES[0], NODES[-1]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = interpolate(NODES, values, [lo - 0.4, hi + 0.4])
    np.testing.assert_allclose(out, values[[0, -1]], atol=1e-13)
    with pytest.raises(OutOfRangeError, match=r"e.g. 50.60 degC"):
        interpolate(NODES, values, [hi + 0.6])


def test_clamp_warns_and_uses_the_end_value(rng):
    values = rng.normal(size=(len(NODES), 2))
    with pytest.warns(ThermalRangeWarning, match="clamped"):
        out = interpolate(NODES, values, [60.0, -50.0], out_of_range="clamp")
    np.testing.assert_allclose(out, values[[-1, 0]], atol=1e-13)


def test_extrapolate_warns_and_continues_the_end_parabola():
    values = (NODES ** 2)[:, None]
    with pytest.warns(ThermalRangeWarning, match="extrapolated"):
        out = interpolate(NODES, values, [55.0], out_of_range="extrapolate")
    assert out[0, 0] == pytest.approx(55.0 ** 2)


@pytest.mark.parametrize("nodes", [[0.0, 10.0], [0.0, 10.0, 10.0], [0.0, 20.0, 10.0]])
def test_bad_nodes_are_refused(nodes):
    with pytest.raises(InputError, match="temperature"):
        lagrange_weights(nodes, [5.0])


def test_unknown_policy_is_refused():
    with pytest.raises(InputError, match="out_of_range"):
        lagrange_weights(NODES, [0.0], out_of_range="wrap")


def test_extrapolation_is_continuous_across_the_margin():
    values = (NODES ** 2)[:, None]
    with pytest.warns(ThermalRangeWarning, match="extrapolated"):
        out = interpolate(NODES, values, [50.49, 50.51], out_of_range="extrapolate")
    np.testing.assert_allclose(out[:, 0], [50.49 ** 2, 50.51 ** 2], rtol=1e-12)
