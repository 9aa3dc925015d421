"""The full-temperature-range method, Tables 3-4 analogue: traditional single-temperature calibration against the
temperature table (3-node Lagrange, the full-temperature-range method, eq. 21-22) and the smooth polynomial model.

Each simulated gyro has the full-temperature-range method's eq. 23 parameters at 25 degC, linear scale drift and
a cubic bias drift (:class:`~gyrocal.simulation.thermal_truth.ThermalTruth`), with its
drift coefficients scaled at random per gyro. It is calibrated on the Table 1
temperatures with the Table 2 rates, then tested at temperatures between the nodes.
Steps are shorter than the paper's minute (``step_duration``): step means carry
little white noise either way, and the comparison is about temperature modelling.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Sequence

import numpy as np

from ._common import Progress, StudyOutput
from ._tables import write_table

#: Test temperatures [degC]: between the Table 1 nodes, plus the traditional 25 degC.
TEST_TEMPS = (-35.0, -25.0, -15.0, -5.0, 5.0, 15.0, 25.0, 35.0, 45.0)
METHODS = ("uncompensated", "traditional", "lagrange", "smooth")
GYROS = 3
SAMPLE_RATE = 100.0  # [Hz]
NOISE = 0.005  # per-sample white noise [rad/s]
SETTLE = 2.0  # time dropped at each step start [s], in calibration and test alike


def _gyro(rng: np.random.Generator, noise: float):
    from ..simulation import VirtualGyro
    from ..simulation.thermal_truth import ThermalTruth

    base = ThermalTruth()
    truth = ThermalTruth(scale_slope=tuple(np.asarray(base.scale_slope) * rng.uniform(0.5, 1.5, 3)),
                         bias_poly=np.asarray(base.bias_poly) * rng.uniform(0.5, 1.5, (3, 1)))
    K, B = truth(np.array([truth.ref_temp]))
    from ..models import Affine

    return VirtualGyro(Affine(K[0], B[0]), noise_std=noise, thermal=truth)


def run(
    out: Path,
    *,
    gyros: int = GYROS,
    reps: int = 1,
    seed: int = 0,
    step_duration: float = 10.0,
    sample_rate: float = SAMPLE_RATE,
    noise: float = NOISE,
    test_temps: Sequence[float] = TEST_TEMPS,
    progress: Progress | None = None,
    plot: bool = True,
) -> StudyOutput:
    """Run the study; write ``table34.{csv,md}``, ``by_temperature.{csv,md}`` and ``thermal.png`` (noise floor dashed).

    Parameters
    ----------
    gyros : int
        Simulated gyros, each with its own drift.
    reps : int
        Test sessions per gyro.
    step_duration : float
        Length of each turntable step [s] (paper: 60).
    sample_rate : float
        Sampling rate [Hz].
    noise : float
        Per-sample white noise [rad/s].
    """
    from ..simulation.turntable import TurntableProtocol, simulate_turntable
    from ..thermal import ThermalWarning, calibrate_thermal
    from ..thermal.evaluate import Evaluation, evaluate

    rng = np.random.default_rng(seed)
    cal_protocol = TurntableProtocol(step_duration=step_duration)
    test_protocol = TurntableProtocol(temps=tuple(test_temps), step_duration=step_duration)
    evaluations = []
    for g in range(gyros):
        gyro = _gyro(rng, noise)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ThermalWarning)
            cal, _ = calibrate_thermal([simulate_turntable(gyro, cal_protocol, sample_rate=sample_rate, rng=rng)],
                                       settle=SETTLE)
            for _ in range(reps):
                test = simulate_turntable(gyro, test_protocol, sample_rate=sample_rate, rng=rng)
                evaluations.append(evaluate(cal, [test], settle=SETTLE))
        if progress:
            progress(1, f"gyro {g + 1}/{gyros}")
    from ..thermal.session import Steps

    merged = Evaluation(steps=Steps.concat([e.steps for e in evaluations]),
                        errors={m: np.concatenate([e.errors[m] for e in evaluations]) for m in METHODS})
    out.mkdir(parents=True, exist_ok=True)
    summary = merged.summary("deg/s")
    header = ["rotating axis", "gyro axis"] + [f"{m} {s} [deg/s]" for m in METHODS for s in ("mean", "rms")]
    rows = [[r["rotating_axis"], r["gyro_axis"], *[r[f"{m}_{s}"] for m in METHODS for s in ("mean", "rms")]]
            for r in summary]
    files = list(write_table(out / "table34", header, rows))
    by_temp = merged.by_temperature("deg/s")
    files += write_table(out / "by_temperature", ["temp [degC]"] + [f"{m} rms [deg/s]" for m in METHODS],
                         [[r["temp"], *[r[f"{m}_rms"] for m in METHODS]] for r in by_temp])
    floor = step_noise_floor(noise, sample_rate, step_duration)
    if plot:
        from ..plotting import save_figure
        from ..plotting.studies import rms_by_temperature_figure

        fig = rms_by_temperature_figure([r["temp"] for r in by_temp],
                                        {m: [r[f"{m}_rms"] for r in by_temp] for m in METHODS}, floor=floor,
                                        title=f"the full-temperature-range method, Tables 3-4 analogue ({gyros} simulated gyros)")
        save_figure(fig, out / "thermal.png")
        files.append(out / "thermal.png")
    total = {m: float(np.sqrt(np.mean(merged.errors[m] ** 2)) * 180 / np.pi) for m in METHODS}
    text = ("RMS step error [deg/s]: " + ", ".join(f"{m} {v:.3g}" for m, v in total.items())
            + f"; noise floor of a step mean {floor:.3g}")
    return StudyOutput("thermal-compare", tuple(files), text)


def step_noise_floor(noise: float, sample_rate: float, step_duration: float) -> float:
    """Std of a test step's mean [deg/s]: no compensation can beat it (white noise only).

    ``noise`` [rad/s] per sample, averaged over the samples left after :data:`SETTLE`.
    """
    return float(np.degrees(noise) / np.sqrt(max(round((step_duration - SETTLE) * sample_rate), 1)))


def work_units(gyros: int | None = None) -> int:
    """Progress units this study reports for `gyros` (default :data:`GYROS`)."""
    return GYROS if gyros is None else gyros
