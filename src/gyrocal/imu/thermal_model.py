"""One sensor's parameters across temperature: the Lagrange table and the smooth polynomial, with 1-sigma.

The points' parameter vectors (each with its covariance from that point's fit) are the nodes of
the full-temperature-range method's 3-node Lagrange interpolation (:mod:`gyrocal.thermal.lagrange`),
and the data of one smooth polynomial per parameter whose order is chosen by leave-one-temperature-out
error (:func:`gyrocal.thermal.smooth.fit_smooth`); the polynomial's coefficients are then refitted
weighted by the points' 1-sigma, and the points' covariances carried through that least squares
(:func:`gyrocal.thermal.smooth.weighted_coefficients`). Leave-one-out error on a few points is
itself noisy and its one-standard-error rule leans low, so a parameter whose polynomial misfits the
points beyond their 1-sigma (chi-square p-value below :data:`MISFIT_P`) is given one order more,
up to the highest order tried. A parameter kept below the highest order carries that choice's model
error: the difference ``d`` between its polynomial and the highest order's weighted fit estimates
the terms it leaves out (its expectation ``bias^2`` plus the variance the extra terms would add), and
``d d^T`` is added to that parameter's block of the coefficients' covariance (chamber simulations:
without it the RMS z between the points was 1.3 against 1.0). Points are independent of one another (each
comes from its own poses), so the Lagrange value's covariance is ``sum_k w_k^2 C_k``. A parameter whose highest
order tried (``n - 2`` for ``n`` points) still misfits them (a cubic seen at 4 points) has its variance scaled by
``chi2 / dof`` (the Birge ratio squared), so the misfit the model cannot follow is in its 1-sigma.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import stats

from ..errors import InputError
from ..thermal.lagrange import lagrange_weights
from ..thermal.smooth import SmoothModel, fit_smooth, weighted_coefficients

__all__ = ["SCHEMES", "TemperatureModel", "temperature_model"]

#: A parameter whose polynomial misfits its points with a chi-square p-value below this gets one order more.
MISFIT_P = 1e-3
#: How parameters are evaluated between the points.
SCHEMES = ("smooth", "lagrange")


@dataclass(frozen=True)
class TemperatureModel:
    """Parameters of one sensor at temperature points, and their model in temperature.

    Attributes
    ----------
    names : tuple of str
        Parameter names (the per-point fit's order).
    nodes : ndarray, shape (n,)
        Point temperatures [degC], increasing.
    values : ndarray, shape (n, m)
        Each point's fitted parameters.
    covariances : ndarray, shape (n, m, m)
        Of each point's parameters.
    smooth : SmoothModel
        Orders chosen by leave-one-temperature-out error; coefficients weighted by the points' 1-sigma.
    smooth_covariance : ndarray, shape (m * (P + 1), m * (P + 1))
        Of ``smooth.coefs.ravel()``.
    chi2 : ndarray, shape (m,)
        Weighted misfit of each parameter's polynomial at the points (``n - order - 1`` dof).
    misfit_scale : ndarray, shape (m,)
        Factor on each parameter's variance: ``chi2 / dof`` where the highest order tried still misfits the
        points (p-value below :data:`MISFIT_P`), else 1.
    """

    names: tuple[str, ...]
    nodes: np.ndarray
    values: np.ndarray
    covariances: np.ndarray
    smooth: SmoothModel
    smooth_covariance: np.ndarray
    chi2: np.ndarray
    misfit_scale: np.ndarray | None = None

    def smooth_at(self, temp) -> tuple[np.ndarray, np.ndarray]:
        """Values and 1-sigma (N, m) of the smooth polynomials at temperatures (N,) [degC]."""
        temp = np.atleast_1d(np.asarray(temp, dtype=float))
        width = self.smooth.coefs.shape[1]
        u = (temp - self.smooth.centre) / self.smooth.scale
        powers = np.vander(u, width, increasing=True)  # (N, P + 1)
        m = len(self.names)
        cov = self.smooth_covariance.reshape(m, width, m, width)
        var = np.einsum("np,jpjq,nq->nj", powers, cov, powers)
        return self.smooth(temp), np.sqrt(np.maximum(var, 0.0))

    def lagrange_at(self, temp, out_of_range="clamp") -> tuple[np.ndarray, np.ndarray]:
        """Values and 1-sigma (N, m) of the 3-node Lagrange interpolation at temperatures (N,) [degC]."""
        idx, w = lagrange_weights(self.nodes, np.atleast_1d(np.asarray(temp, dtype=float)), out_of_range)
        values = np.einsum("nk,nkj->nj", w, self.values[idx])
        var = np.einsum("nk,nkj->nj", w**2, np.einsum("kjj->kj", self.covariances)[idx])
        return values, np.sqrt(var)

    def at(self, temp, scheme: str = "smooth") -> tuple[np.ndarray, np.ndarray]:
        """Values and 1-sigma (N, m) by `scheme` (``smooth`` or ``lagrange``)."""
        if scheme not in SCHEMES:
            raise InputError(f"scheme must be one of {', '.join(SCHEMES)}, got {scheme!r}")
        return self.smooth_at(temp) if scheme == "smooth" else self.lagrange_at(temp)

    def with_constant_variance(self, variance) -> "TemperatureModel":
        """This model with `variance` (m,) added to each parameter's constant coefficient: a variance at every
        temperature alike (an error the points share, such as half a hysteresis)."""
        m, width = len(self.names), self.smooth.coefs.shape[1]
        idx = np.arange(m) * width
        cov = self.smooth_covariance.copy()
        cov[idx, idx] += np.asarray(variance, dtype=float)
        return replace(self, smooth_covariance=cov)

    def to_dict(self) -> dict:
        """The file's form: points, the smooth model with its coefficients' covariance, the misfit."""
        return {
            "names": list(self.names),
            "points": {"temperature": self.nodes.tolist(), "values": self.values.tolist(),
                       "covariance": self.covariances.tolist()},
            "lagrange": {"equation": "3-node Lagrange interpolation of points.values in temperature"},
            "smooth": {**self.smooth.to_dict(), "covariance": self.smooth_covariance.tolist(),
                       "std": np.sqrt(np.maximum(np.diag(self.smooth_covariance), 0.0))
                       .reshape(self.smooth.coefs.shape).tolist(),
                       "chi2": self.chi2.tolist(),
                       "misfit_scale": (np.ones(len(self.names)) if self.misfit_scale is None
                                        else self.misfit_scale).tolist(),
                       "dof": [len(self.nodes) - int(p) - 1 for p in self.smooth.orders]},
        }


def _order_error(chosen: SmoothModel, nodes, values, covariances, coefs) -> np.ndarray:
    """Covariance (m * (P + 1), m * (P + 1)) added for the orders kept below the top ``P``: for each parameter,
    ``d d^T`` in its own block, ``d`` its coefficients' difference from the top order's weighted fit."""
    top = coefs.shape[1] - 1
    full, _, _ = weighted_coefficients(replace(chosen, orders=np.full_like(chosen.orders, top)), nodes, values,
                                       covariances)
    d = full - coefs
    m, width = d.shape
    out = np.zeros((m, width, m, width))
    out[np.arange(m), :, np.arange(m), :] = d[:, :, None] * d[:, None, :]
    return out.reshape(m * width, m * width)


def temperature_model(names, nodes, values, covariances, max_order: int = 3) -> TemperatureModel:
    """Build the :class:`TemperatureModel` of parameters `values` (n, m) with `covariances` (n, m, m) at `nodes`."""
    nodes = np.asarray(nodes, dtype=float)
    values = np.asarray(values, dtype=float)
    covariances = np.asarray(covariances, dtype=float)
    if len(nodes) < 3:
        raise InputError(f"a model in temperature needs at least 3 temperature points, got {len(nodes)}")
    order = np.argsort(nodes)
    nodes, values, covariances = nodes[order], values[order], covariances[order]
    chosen = fit_smooth(nodes, values, max_order=max_order)
    top = chosen.coefs.shape[1] - 1
    while True:
        coefs, cov, chi2 = weighted_coefficients(chosen, nodes, values, covariances)
        dof = len(nodes) - chosen.orders - 1
        raise_ = (chosen.orders < top) & (stats.chi2.sf(chi2, np.maximum(dof, 1)) < MISFIT_P)
        if not raise_.any():
            break
        chosen = replace(chosen, orders=chosen.orders + raise_)
    misfit = (chosen.orders == top) & (dof > 0) & (stats.chi2.sf(chi2, np.maximum(dof, 1)) < MISFIT_P)
    scale = np.where(misfit, chi2 / np.maximum(dof, 1), 1.0)
    s = np.repeat(np.sqrt(scale), coefs.shape[1])
    cov = cov * np.outer(s, s) + _order_error(chosen, nodes, values, covariances, coefs)
    smooth = SmoothModel(centre=chosen.centre, scale=chosen.scale, orders=chosen.orders, coefs=coefs,
                         loto_rms=chosen.loto_rms)
    return TemperatureModel(names=tuple(names), nodes=nodes, values=values, covariances=covariances, smooth=smooth,
                            smooth_covariance=cov, chi2=chi2, misfit_scale=scale)
