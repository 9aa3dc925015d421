"""What the 1-sigma of a first-moment fit covers: where the windows' noise came from, a given white level,
and the Earth's rate in the bias.

* The windows' noise: the static windows' long-run variance, or without them the turns' quiet axes
  (:mod:`gyrocal.observations.window_stats`), or the white noise of first differences; a note says which when it is
  not the static windows'.
* ``noise_std`` given (``--noise-std``, ``--noise-density``): it sets the white level, a floor on every
  measured mean variance; the data's long-run correlation (a chip's filter, wander) still counts where
  it is larger.
* b is the sensor's own bias averaged over the session. The Earth's rate is not part of it (the
  calibration is applied in other orientations), yet it sits in every reading and the fit takes it into
  b. Its projection on an axis of unknown orientation has a standard deviation of ``15.04 deg/h /
  sqrt(3) = 8.7 deg/h``; that goes into b's variance (in reading units, divided by k).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..estimators import FitResult

__all__ = ["EARTH_RATE", "sigma_covers", "with_earth_rate", "noise_notes"]

EARTH_RATE = 7.2921159e-5  # [rad/s] the Earth's rotation rate (sidereal)
_EARTH_SD = EARTH_RATE / math.sqrt(3.0)  # its projection on an axis of unknown orientation


def with_earth_rate(fit: FitResult) -> FitResult:
    """`fit` whose b variances carry the Earth's rate on an axis of unknown orientation (``(8.7 deg/h / k)^2``)."""
    if fit.covariance is None:
        return fit
    cov = np.array(fit.covariance, dtype=float)
    idx = np.arange(3, 6)
    cov[idx, idx] += (_EARTH_SD / np.asarray(fit.model.k, dtype=float)) ** 2
    return dataclasses.replace(fit, covariance=cov)


def _noise_source(observations, reference: str) -> str:
    """Where the windows' mean variances come from, in words."""
    statics = [o for o in observations if o.kind == "static"]
    turns = [o for o in observations if o.kind != "static"]
    if statics and statics[0].mean_var is not None:
        return "the static windows' long-run variance"
    if reference == "angle" and turns and turns[0].mean_var is not None:
        return "the long-run variance of the turns' non-rotating axes (no static window)"
    if reference == "speed" and turns and turns[0].mean_var is not None:
        return "the plateaus' residuals (long-run and vibration terms)"
    return "the white noise of first differences"


def noise_notes(observations, reference: str, given: bool) -> list[str]:
    """Notes for people: where the turns' noise came from when no static window gave it, and a given level."""
    source = _noise_source(observations, reference)
    notes = []
    if reference == "angle" and not source.startswith("the static"):
        notes.append(f"the turns' noise is {source}" + (
            ": a chip's low-pass filter makes it too small; add static windows" if "white" in source else ""))
    if given:
        notes.append("the given noise sets the white level, a floor on each window's noise; " + source +
                     " counts where it is larger")
    return notes


def sigma_covers(observations, reference: str, given: bool) -> dict:
    """The ``fit`` section's ``sigma_covers``: what the 1-sigma of k and of b hold, in words."""
    noise = _noise_source(observations, reference) + (" (at least the given white level)" if given else "")
    return {"k": f"the windows' noise ({noise}), their scatter beyond it where the fit saw some, and any declared "
                 "reference accuracy",
            "b": f"b is the sensor's bias averaged over the session; its 1-sigma holds the windows' noise ({noise}), "
                 "the bias's wander between them where the fit saw it, and the Earth's rate on an axis of unknown "
                 "orientation (15.04 deg/h / sqrt(3) = 8.7 deg/h); not the bias's change from run to run or with "
                 "temperature"}
