"""Calibration models: conversions, the canonical correction, and the Kg element order.

References: the papers' equations written out by hand (eq. 1; eq. 11, 14 and 15) and exact round trips.
"""

import numpy as np
import pytest

from gyrocal.errors import InputError, NonPhysicalEstimateError
from gyrocal.models import KG_NAMES, Affine, ScaleBias


def random_scale_bias(rng) -> ScaleBias:
    return ScaleBias(k=rng.uniform(0.8, 1.2, 3), b=rng.uniform(-0.1, 0.1, 3))


def random_affine(rng) -> Affine:
    return Affine(K=np.diag(rng.uniform(0.8, 1.2, 3)) + rng.uniform(-0.03, 0.03, (3, 3)), B=rng.uniform(-0.1, 0.1, 3))


MODELS = [random_scale_bias, random_affine]


@pytest.mark.parametrize("make", MODELS, ids=["scale-bias", "affine"])
def test_correct_inverts_distort(make, rng):
    model = make(rng)
    w = rng.normal(0, 2, (500, 3))
    np.testing.assert_allclose(model.correct(model.distort(w)), w, rtol=0, atol=1e-12)


@pytest.mark.parametrize("make", MODELS, ids=["scale-bias", "affine"])
def test_canonical_round_trip_is_exact(make, rng):
    model = make(rng)
    again = type(model).from_canonical(model.matrix, model.offset)
    np.testing.assert_allclose(again.params, model.params, rtol=1e-14, atol=1e-15)
    np.testing.assert_array_equal(type(model).from_params(model.params).params, model.params)


def test_scale_bias_matches_wang_eq1(rng):
    model = random_scale_bias(rng)
    m = rng.normal(0, 1, (10, 3))
    np.testing.assert_allclose(model.correct(m), (m + model.b) * model.k, rtol=1e-15)
    np.testing.assert_array_equal(model.matrix, np.diag(model.k))
    np.testing.assert_array_equal(model.offset, -model.b)


def test_scale_bias_to_affine_is_the_same_map(rng):
    model = random_scale_bias(rng)
    aff = model.to_affine()
    m = rng.normal(0, 1, (10, 3))
    np.testing.assert_allclose(aff.correct(m), model.correct(m), rtol=1e-14)
    np.testing.assert_allclose(aff.K, np.diag(1 / model.k), rtol=1e-15)
    np.testing.assert_allclose(aff.B, -model.b, rtol=1e-15)


def test_kg_order_follows_full_temperature_range_eq15():
    # eq. 15, first row of Omega^T: wx = Kxx w~x + Kyx w~y + Kzx w~z + Bx
    kg = np.arange(1.0, 13.0) + np.array([10, 20, 30, 0, 0, 0, 0, 0, 0, 0, 0, 0])  # well-conditioned K
    aff = Affine.from_kg(kg)
    named = dict(zip(KG_NAMES, kg))
    w_ref = np.array([[0.3, -0.7, 1.1]])
    wx = named["Kxx"] * 0.3 + named["Kyx"] * -0.7 + named["Kzx"] * 1.1 + named["Bx"]
    wy = named["Kxy"] * 0.3 + named["Kyy"] * -0.7 + named["Kzy"] * 1.1 + named["By"]
    wz = named["Kxz"] * 0.3 + named["Kyz"] * -0.7 + named["Kzz"] * 1.1 + named["Bz"]
    np.testing.assert_allclose(aff.distort(w_ref)[0], [wx, wy, wz], rtol=1e-14)
    np.testing.assert_array_equal(aff.kg, kg)


def test_models_are_frozen(rng):
    model = random_scale_bias(rng)
    with pytest.raises(ValueError):
        model.k[0] = 2.0
    with pytest.raises(AttributeError):
        model.k = np.ones(3)  # type: ignore[misc]


def test_errors_name_the_argument():
    with pytest.raises(NonPhysicalEstimateError, match="k must be > 0"):
        ScaleBias(k=[1, -1, 1], b=[0, 0, 0])
    with pytest.raises(InputError, match="off-diagonal"):
        ScaleBias.from_canonical(np.ones((3, 3)), np.zeros(3))
    with pytest.raises(NonPhysicalEstimateError, match="singular"):
        Affine(K=np.zeros((3, 3)), B=np.zeros(3))
    with pytest.raises(InputError, match=r"kg must have shape \(\.\.\., 12\)"):
        Affine.from_kg(np.ones(11))


def test_conversion_chain_kb_canonical_affine_kg(rng):
    """k, b -> canonical -> Affine -> Kg -> Affine -> canonical -> k, b, exact to rounding."""
    model = random_scale_bias(rng)
    aff = Affine.from_kg(Affine.from_canonical(model.matrix, model.offset).kg)
    back = ScaleBias.from_canonical(aff.matrix, aff.offset)
    np.testing.assert_allclose(back.k, model.k, rtol=4e-16)
    np.testing.assert_array_equal(back.b, model.b)
    kg = aff.kg
    np.testing.assert_allclose(kg[:3], 1 / model.k, rtol=4e-16)
    np.testing.assert_array_equal(kg[3:9], 0.0)
    np.testing.assert_array_equal(kg[9:], -model.b)


def test_rows_times_is_the_matrix_product_without_blas():
    """Reference: numpy's ``@``. Three products summed differ by at most a few ulps of the sum of their sizes."""
    from gyrocal._arrays import rows_times

    rng = np.random.default_rng(25)
    v, a = rng.normal(size=(70_000, 3)), rng.normal(size=(3, 3))
    bound = 4 * np.finfo(float).eps * (np.abs(v) @ np.abs(a).T)
    assert np.all(np.abs(rows_times(v, a) - v @ a.T) <= bound)
    assert rows_times(v[:5].reshape(5, 1, 3), a).shape == (5, 1, 3)
