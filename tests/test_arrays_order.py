"""gyrocal._arrays' median, percentile and distinct against numpy's own np.median, np.percentile and
np.unique (the independent reference): the same values bit for bit, the same shapes, types and dtypes,
NaN where numpy gives NaN, over odd and even lengths, every axis, keepdims, float32 and integers."""

from __future__ import annotations

import numpy as np
import pytest

from gyrocal._arrays import distinct, median, percentile

LENGTHS = (1, 2, 3, 4, 5, 8, 9, 100, 101, 1000)


def _same(expected, got) -> None:
    assert type(got) is type(expected)
    assert np.shape(got) == np.shape(expected)
    assert np.asarray(got).dtype == np.asarray(expected).dtype
    np.testing.assert_array_equal(got, expected)  # NaN matches NaN; every other value is equal


def _cases(rng, n):
    for shape, axes in (((n,), (None, 0)), ((n, 3), (None, 0, 1, -1)), ((3, n), (None, 0, 1)),
                        ((2, n, 3), (None, 0, 1, 2))):
        yield rng.normal(size=shape) * 10, axes


@pytest.mark.parametrize("n", LENGTHS)
@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.int64])
def test_median_is_numpys(n, dtype):
    rng = np.random.default_rng(n)
    for x, axes in _cases(rng, n):
        x = x.astype(dtype)
        for with_nan in (False, True) if dtype is not np.int64 else (False,):
            if with_nan:
                x.flat[rng.integers(x.size)] = np.nan
            for axis in axes:
                for keepdims in (False, True):
                    _same(np.median(x, axis=axis, keepdims=keepdims), median(x, axis=axis, keepdims=keepdims))


def test_median_of_lists_and_empty_input_is_numpys():
    _same(np.median([3.0, 1.0, 2.0, 10.0]), median([3.0, 1.0, 2.0, 10.0]))
    _same(np.median([[1, 5], [2, 7]], axis=1), median([[1, 5], [2, 7]], axis=1))
    with pytest.warns(RuntimeWarning):
        assert np.isnan(median(np.array([])))


@pytest.mark.parametrize("n", LENGTHS + (11, 1001))
def test_percentile_is_numpys(n):
    rng = np.random.default_rng(100 + n)
    for x, axes in _cases(rng, n):
        for with_nan in (False, True):
            if with_nan:
                x.flat[rng.integers(x.size)] = np.nan
            for q in (0, 10, 25, 33.3, 37.5, 50, 90, 99.9, 100):
                for axis in axes:
                    _same(np.percentile(x, q, axis=axis), percentile(x, q, axis=axis))


def test_percentile_hands_what_it_does_not_compute_to_numpy():
    x = np.random.default_rng(7).normal(size=(50, 3))
    _same(np.percentile(x, [2.5, 97.5], axis=0), percentile(x, [2.5, 97.5], axis=0))
    _same(np.percentile(x.astype(np.float32), 10), percentile(x.astype(np.float32), 10))
    with pytest.raises(ValueError):
        percentile(x, 101)


def test_distinct_is_numpys_unique():
    rng = np.random.default_rng(3)
    cases = [np.array([3, 1, 2, 3, 1]), np.array([5]), np.array([], dtype=int), rng.integers(0, 5, 100),
             np.array([np.nan, 1.0, np.nan, 0.5, 1.0]), np.array([np.nan]), rng.normal(size=200).round(1),
             rng.integers(0, 4, (6, 7))]
    for values in cases:
        expected, got = np.unique(values), distinct(values)
        assert got.dtype == expected.dtype
        np.testing.assert_array_equal(got, expected)
