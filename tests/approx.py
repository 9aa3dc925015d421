"""Compare nested JSON-like values with numbers equal to a relative tolerance.

A number computed by a BLAS kernel can differ in its last bits from one CPU to the next, so no test
compares computed floats bit for bit: structure, strings and integers must be equal, floats within
``rtol`` (a few ulps times the condition of the computation that made them).
"""

import math


def assert_close_tree(got, want, rtol: float, path: str = "$") -> None:
    """Assert ``got`` equals ``want`` with floats within ``rtol`` relative (``rtol`` absolute near 0)."""
    if isinstance(want, dict):
        assert isinstance(got, dict) and got.keys() == want.keys(), f"{path}: keys {got!r} != {want!r}"
        for key in want:
            assert_close_tree(got[key], want[key], rtol, f"{path}.{key}")
    elif isinstance(want, list | tuple):
        assert isinstance(got, list | tuple) and len(got) == len(want), f"{path}: {got!r} != {want!r}"
        for i, (g, w) in enumerate(zip(got, want)):
            assert_close_tree(g, w, rtol, f"{path}[{i}]")
    elif isinstance(want, float) and not isinstance(want, bool):
        assert isinstance(got, int | float), f"{path}: {got!r} is not a number"
        assert math.isclose(got, want, rel_tol=rtol, abs_tol=rtol), f"{path}: {got!r} != {want!r} (rtol {rtol})"
    else:
        assert got == want, f"{path}: {got!r} != {want!r}"
