"""Estimators of the scale-bias model of the servo method of Wang et al.

Each estimator holds only its configuration; ``fit`` returns a frozen
:class:`FitResult` and ``fit_batch`` a :class:`BatchFit` over many gyros.

Layer 4 (the fits) of docs/architecture.md: imports the package root and layers 1 to 4 only.
"""

from ._checks import require_count, require_full_rank
from ._result import BatchFit, FitResult, Method
from .algorithm1 import Algorithm1, algorithm1_batch
from .first_moment import FirstMoment, first_moment_batch
from .paper_lm import PaperLM, paper_lm_batch
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

    table = {"first-moment": FirstMoment, "algorithm1": Algorithm1, "lm": PaperLM}
    if method not in table:
        raise InputError(f"{{param}}={method!r} is not one of {', '.join(table)}", param="method", value=method)
    return table[method](**options)
