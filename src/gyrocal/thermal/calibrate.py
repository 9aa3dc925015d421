"""From session recordings to a :class:`ThermalCalibration` in one call."""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import InputError
from ..recording import Recording
from ..units import parse_rate_unit
from .fit import ThermalFit, fit_session
from .model import ThermalCalibration
from .session import session_steps
from .smooth import fit_smooth
from .tempfilter import DEFAULT_TEMP_TAU

__all__ = ["calibrate_thermal", "table_from_fit"]


def table_from_fit(fit: ThermalFit, *, input_units: str = "rad/s", output_units: str | None = None,
                   reference_temp: float = 25.0, max_order: int = 3, temp_tau: float = DEFAULT_TEMP_TAU,
                   settings: dict | None = None) -> ThermalCalibration:
    """Build the temperature table (Lagrange nodes and smooth model) from per-point fits."""
    return ThermalCalibration(
        temps=fit.temps, kg=fit.kg, smooth=fit_smooth(fit.temps, fit.kg, max_order),
        input_units=input_units, output_units=output_units or input_units, reference_temp=reference_temp,
        std=fit.std, std_noise=fit.std_noise, residual_rms=fit.residual_rms, temp_tau=temp_tau,
        settings=dict(settings or {}))


def calibrate_thermal(recordings: Sequence[Recording], *, input_units: str | None = None,
                      output_units: str | None = None, settle: float = 2.0, full_scale: float | None = None,
                      temp_tolerance: float = 2.0, reference_temp: float = 25.0, max_order: int = 3,
                      temp_tau: float = DEFAULT_TEMP_TAU, names: Sequence[str] | None = None,
                      ) -> tuple[ThermalCalibration, ThermalFit]:
    """Calibrate a gyro over temperature from turntable recordings (the full-temperature-range method, whole method).

    Parameters
    ----------
    recordings : sequence of Recording
        One recording with every temperature point, or one per point; each needs
        ``temp`` [degC], ``table_rate`` [rad/s] and ``axis``.
    input_units, output_units : {"rad/s", "deg/s"}, optional
        Units of the raw data and of corrected output; default the recordings'
        ``source_units`` (rad/s for counts with a sensitivity).
    settle : float
        Time dropped at the start of each step [s].
    full_scale : float, optional
        Gyro range [rad/s]; saturated steps are left out with a warning.
    temp_tolerance : float
        Spread allowed inside a step and gap below which points are duplicates [degC].
    reference_temp : float
        Temperature of the traditional baseline [degC].
    max_order : int
        Highest polynomial order tried for the smooth model.
    temp_tau : float
        Temperature smoothing stored for compensation [s].
    names : sequence of str, optional
        Names of the recordings for messages.

    Returns
    -------
    ThermalCalibration, ThermalFit
        The table, and the per-point fits with their steps and residuals.
    """
    recs = list(recordings)
    if not recs:
        raise InputError("no recordings given; a thermal session needs at least one")
    src = {r.source_units for r in recs}
    if input_units is None:
        if len(src) > 1:
            raise InputError(f"the recordings are in different units ({', '.join(sorted(src))}); read them in one unit")
        s = src.pop()
        input_units = "rad/s" if s == "counts" else s
    input_units = parse_rate_unit(input_units, "input_units")
    steps = session_steps(recs, settle=settle, full_scale=full_scale, temp_tolerance=temp_tolerance, names=names)
    fit = fit_session(steps)
    settings = {"settle_s": settle, "full_scale_rad_s": full_scale, "temp_tolerance_degC": temp_tolerance,
                "max_order": max_order, "steps": len(steps)}
    cal = table_from_fit(fit, input_units=input_units, output_units=output_units, reference_temp=reference_temp,
                         max_order=max_order, temp_tau=temp_tau, settings=settings)
    return cal, fit
