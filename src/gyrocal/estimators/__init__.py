"""Estimators of the scale-bias model of the servo method of Wang et al.

Each estimator holds only its configuration; ``fit`` returns a frozen
:class:`FitResult` and ``fit_batch`` a :class:`BatchFit` over many gyros.

Layer 4 (the fits) of docs/architecture.md: imports the package root and layers 1 to 4 only.
"""

import sys

from .._lazy import lazy_names
from ._checks import require_count, require_full_rank
from ._result import BatchFit, FitResult, Method
from .first_moment import FirstMoment, first_moment_batch
from .residuals import window_residuals

__all__ = [
    "Algorithm1",
    "BatchFit",
    "FirstMoment",
    "FitResult",
    "Method",
    "PaperLM",
    "algorithm1_batch",
    "first_moment_batch",
    "make_estimator",
    "paper_lm_batch",
    "require_count",
    "require_full_rank",
    "window_residuals",
]


def make_estimator(method: Method, **options):
    """The estimator for a method name: ``first-moment`` (default), ``algorithm1`` or ``lm``."""
    from ..errors import InputError

    table = {"first-moment": "FirstMoment", "algorithm1": "Algorithm1", "lm": "PaperLM"}
    if method not in table:
        raise InputError(f"{{param}}={method!r} is not one of {', '.join(table)}", param="method", value=method)
    return getattr(sys.modules[__name__], table[method])(**options)  # loads the module of that one alone


# the paper's own two fits load on first use: a calibration by the first moment never needs them
__getattr__, __dir__ = lazy_names(__name__, {"Algorithm1": "algorithm1", "algorithm1_batch": "algorithm1",
                                             "PaperLM": "paper_lm", "paper_lm_batch": "paper_lm"}, globals())
