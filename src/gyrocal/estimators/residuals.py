"""Each window's residual against a fitted model, in noise units (for :func:`gyrocal.checks.quality.assess_fit`).

* first moment: a rotation window's ``|diag(k)(m_mean + b)| - rate``, and a static window's
  ``diag(k)(m_mean + b)`` (three values), each divided by its standard deviation from the
  window mean's variance (white noise, or the window's own long-run variance);
* Algorithm 1 and LM (the servo method of Wang et al., eq. 4): a window's
  ``beta0 + x . beta - omega^2``, divided by its white-noise standard deviation. The noise power
  in the mean of squares biases these rows too, so a large chi2 can come from it.
"""

from __future__ import annotations

import numpy as np

from ..observations import ObservationSet
from ._result import FitResult
from .first_moment import residuals_and_jacobian, row_noise_var, row_variance
from .paper_model import gamma, paper_row_var, regressors

__all__ = ["window_residuals"]


def _first_moment(fit: FitResult, obs: ObservationSet) -> list[np.ndarray]:
    o = obs.as_batch()
    r, _, S = residuals_and_jacobian(fit.model.params[None], o)
    nu = row_noise_var(o, np.square(fit.noise_std)[None])
    z = r[0] / np.sqrt(row_variance(o, S, nu)[0])
    n_rot = int((~o.static).sum())
    rot, sta = iter(z[:n_rot]), iter(z[n_rot:].reshape(-1, 3))
    return [next(sta) if s else np.array([next(rot)]) for s in o.static]


def _paper(fit: FitResult, obs: ObservationSet) -> list[np.ndarray]:
    o = obs.as_batch()
    k, b = fit.model.k, fit.model.b
    beta = np.concatenate([k**2, 2 * k**2 * b])[None]
    X, Y = regressors(o)
    resid = (X @ beta[..., None])[..., 0] + gamma(beta)[:, None] - Y
    z = resid[0] / np.sqrt(paper_row_var(beta, o, np.square(fit.noise_std)[None])[0])
    return [np.array([v]) for v in z]


def window_residuals(fit: FitResult, obs: ObservationSet) -> list[np.ndarray]:
    """Residuals in noise units, one array per window of `obs` (one gyro), in window order.

    Parameters
    ----------
    fit : FitResult
        The fit of `obs`; its ``noise_std`` is the white noise it assumed [reading units].
    obs : ObservationSet
        The windows the fit used.
    """
    if fit.noise_std is None:
        raise ValueError("window_residuals needs the fit's noise_std")
    return _first_moment(fit, obs) if fit.method == "first-moment" else _paper(fit, obs)
