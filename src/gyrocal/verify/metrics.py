"""Error figures of a gyro against a reference, per axis, with block-bootstrap 1-sigma.

The servo method of Wang et al. (Tables IV and V) reports the mean squared error (MSE)
between the gyro and its reference before and after calibration. Here each axis also gets
the RMSE, the 99th percentile of the absolute error and the reduction of the MSE in %.
The reference's own noise adds its interpolated variance (the *floor*) to every MSE; the
MSE after calibration net of that floor is the part the calibration is answerable for.

The 1-sigma come from a block bootstrap over the test log (:mod:`.bootstrap`): they say how
much each figure would move if a session of the same kind of motion were recorded again.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import percentile
from .bootstrap import BlockBootstrap, optimal_block_length

__all__ = ["FIGURES", "Metrics", "error_metrics"]

#: Figures per axis, in report order: name -> what it is.
FIGURES: dict[str, str] = {
    "mse_before": "MSE before calibration (raw readings)",
    "mse_after": "MSE after calibration",
    "reduction_pct": "MSE reduction [%]",
    "rmse_before": "RMSE before calibration",
    "rmse_after": "RMSE after calibration",
    "p99_before": "99th percentile of |error| before calibration",
    "p99_after": "99th percentile of |error| after calibration",
    "reference_floor": "MSE the reference's own noise adds",
    "mse_after_net": "MSE after calibration, net of the reference floor",
}
_BEFORE = ("mse_before", "reduction_pct", "rmse_before", "p99_before")


@dataclass(frozen=True)
class Metrics:
    """Per-axis error figures and their 1-sigma.

    Attributes
    ----------
    values, std : dict of str to ndarray, shape (3,)
        One entry per name of :data:`FIGURES`; MSE in [unit^2], RMSE and percentiles in
        [unit], reduction in [%]. Figures before calibration are NaN when the raw
        readings cannot be put in the output unit (raw counts without a sensitivity).
    block : int
        Bootstrap block length [samples].
    blocks : int
        Number of blocks.
    replicates : int
        Bootstrap replicates.
    """

    values: dict[str, np.ndarray]
    std: dict[str, np.ndarray]
    block: int
    blocks: int
    replicates: int

    def axis(self, j: int) -> dict[str, float]:
        """Figures of axis `j` as ``{name: value, name_std: 1-sigma}``."""
        out: dict[str, float] = {}
        for name in FIGURES:
            out[name] = float(self.values[name][j])
            out[f"{name}_std"] = float(self.std[name][j])
        return out


def _summary(boot: BlockBootstrap, err: np.ndarray) -> tuple[dict, dict]:
    """Point values (3,) and bootstrap replicates (B, 3) of MSE, RMSE and P99 of `err` (n, 3)."""
    sq = err * err
    mse = sq.mean(axis=0)
    mse_b = boot.means(sq)
    absolute = np.abs(err)
    p99 = percentile(absolute, 99.0, axis=0)
    p99_b = np.stack([boot.quantiles(absolute[:, j], 0.99) for j in range(3)], axis=1)
    return {"mse": mse, "rmse": np.sqrt(mse), "p99": p99}, {"mse": mse_b, "rmse": np.sqrt(mse_b), "p99": p99_b}


def error_metrics(err_before: np.ndarray | None, err_after: np.ndarray, floor: np.ndarray, floor_std: np.ndarray,
                  *, rng: np.random.Generator, replicates: int = 1000) -> Metrics:
    """Figures of the errors against the reference, before and after calibration.

    Parameters
    ----------
    err_before : ndarray, shape (n, 3), or None
        Raw readings minus reference, at the test log's sample times [unit]; None when the
        raw readings are not in a rate unit.
    err_after : ndarray, shape (n, 3)
        Calibrated readings minus reference, same samples [unit].
    floor, floor_std : ndarray, shape (3,)
        MSE the reference's noise adds, and its 1-sigma [unit^2].
    rng : numpy.random.Generator
        Drives the bootstrap.
    replicates : int
        Bootstrap replicates.
    """
    n = len(err_after)
    series = [err_after] if err_before is None else [err_after, err_before]
    block = max(optimal_block_length(e[:, j] ** 2) for e in series for j in range(3))
    boot = BlockBootstrap(n, block, replicates, rng)
    after, after_b = _summary(boot, err_after)
    values = {"mse_after": after["mse"], "rmse_after": after["rmse"], "p99_after": after["p99"],
              "reference_floor": np.asarray(floor, float), "mse_after_net": after["mse"] - floor}
    std = {"mse_after": after_b["mse"].std(axis=0), "rmse_after": after_b["rmse"].std(axis=0),
           "p99_after": after_b["p99"].std(axis=0), "reference_floor": np.asarray(floor_std, float)}
    std["mse_after_net"] = np.hypot(std["mse_after"], std["reference_floor"])
    nan = np.full(3, np.nan)
    if err_before is None:
        values.update(dict.fromkeys(_BEFORE, nan))
        std.update(dict.fromkeys(_BEFORE, nan))
    else:
        before, before_b = _summary(boot, err_before)
        for key in ("mse", "rmse", "p99"):
            values[f"{key}_before"], std[f"{key}_before"] = before[key], before_b[key].std(axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            values["reduction_pct"] = 100.0 * (1.0 - after["mse"] / before["mse"])
            std["reduction_pct"] = (100.0 * (1.0 - after_b["mse"] / before_b["mse"])).std(axis=0)
    return Metrics(values={k: values[k] for k in FIGURES}, std={k: std[k] for k in FIGURES},
                   block=boot.block, blocks=boot.blocks, replicates=replicates)
