"""The protocol runs of ``gyrocal simulate`` that need no flag parsing of their own (kept apart to keep
``sim_cmds`` small): each returns the recording and its truth, and fills the settings."""

from __future__ import annotations

import math

from ..errors import InputError
from ._options import list_in_unit, numbers

__all__ = ["multi_position", "profile_run", "turntable", "turntable_protocol"]


def turntable_protocol(temps: str | None, rates: str | None, step_duration: float | None, temp_noise: float,
                        temp_quantum: float | None):
    """The full-temperature-range method's protocol; unset flags keep the paper's values."""
    from ..simulation.turntable import TurntableProtocol

    kw: dict = {}
    if temps is not None:
        kw["temps"] = tuple(numbers("--temps", temps))
    if rates is not None:
        kw["rates"] = tuple(list_in_unit("--rates", rates, "deg/s"))
    if step_duration is not None:
        kw["step_duration"] = step_duration
    return TurntableProtocol(**kw, temp_noise=temp_noise, temp_quantum=temp_quantum)


def multi_position(model, gyro_kw, flags: dict, sample_rate, rng, settings):
    """A hand multi-position session of a whole IMU: the recording (with ax, ay, az), gyro model, facts.

    `flags`: the command's parameters (``poses``, ``tilt``, ``still``, ``accel_noise_density``, ``misalignment``).
    """
    from .._validation import at_least
    from ..simulation.multiposition import hand_session

    density = 0.002 if flags["accel_noise_density"] is None else flags["accel_noise_density"]
    at_least("accel_noise_density", density, 0.0, " m/s^2/sqrt(Hz)")
    if flags["temp_points"] is not None and flags["temp_ramp"] is not None:
        raise InputError("--temp-points (plateaus) and --temp-ramp (a ramp) are two chamber sessions; give one")
    if flags["temp_ramp"] is not None:
        return _chamber(model, gyro_kw, flags, density * math.sqrt(sample_rate), sample_rate, rng, settings,
                        ramp=flags["temp_ramp"])
    if flags["temp_points"] is not None:
        return _chamber(model, gyro_kw, flags, density * math.sqrt(sample_rate), sample_rate, rng, settings)
    for name in ("temp_soak", "temp_hysteresis", "temp_noise"):
        if flags[name] != {"temp_soak": 600.0}.get(name, 0.0):
            raise InputError(f"--{name.replace('_', '-')} describes a chamber session; add --temp-points T1,T2,.. "
                             "or --temp-ramp LOW:HIGH")
    rec, gyro, facts, extra = hand_session(model, gyro_kw=gyro_kw, poses=flags["poses"], tilt_deg=flags["tilt"],
                                           still=flags["still"], accel_noise_std=density * math.sqrt(sample_rate),
                                           misalignment_deg=flags["misalignment"], sample_rate=sample_rate, rng=rng)
    settings.update(extra)
    return rec, gyro, facts

def _ramp_flag(text: str) -> tuple[float, float, float]:
    """LOW:HIGH[:RATE] of --temp-ramp [degC, degC/min]."""
    from ..simulation.ramp import DEFAULT_RATE

    form = f"--temp-ramp takes LOW:HIGH or LOW:HIGH:RATE [degC, degC/min], e.g. -25:60:1, got {text!r}"
    try:
        parts = [float(v) for v in text.split(":")]
    except ValueError:
        raise InputError(form) from None
    if len(parts) not in (2, 3) or not all(map(math.isfinite, parts)):
        raise InputError(form)
    rate = parts[2] if len(parts) == 3 else DEFAULT_RATE
    if not rate > 0:
        raise InputError(f"--temp-ramp's RATE must be > 0 degC/min, got {rate:g}")
    return parts[0], parts[1], rate


def _chamber(model, gyro_kw, flags: dict, accel_sd: float, sample_rate, rng, settings, ramp: str | None = None):
    """A chamber session on plateaus (:func:`gyrocal.simulation.chamber.chamber_session`) or on a ramp
    (:func:`gyrocal.simulation.ramp.ramp_session`): recording, gyro at 25 degC, facts."""
    import numpy as np

    from .._validation import at_least, positive
    from ..models import Affine
    from ..simulation.chamber import chamber_session, random_thermal_imu
    from ..simulation.ramp import ramp_session

    ends = _ramp_flag(ramp) if ramp is not None else None
    temps = numbers("--temp-points", flags["temp_points"]) if ramp is None else None
    positive("static_duration", flags["still"])
    at_least("temp_soak", flags["temp_soak"], 0.0, " s")
    at_least("temp_hysteresis", flags["temp_hysteresis"], 0.0, " m/s^2")
    if ramp is not None and flags["temp_soak"] != 600.0:
        raise InputError("--temp-soak is the unrecorded soak between plateaus; a --temp-ramp has none")
    truth = random_thermal_imu(model, rng, misalignment_deg=flags["misalignment"],
                               hysteresis=flags["temp_hysteresis"])
    kw = dict(gyro_kw=gyro_kw, poses=flags["poses"], tilt_deg=flags["tilt"], still=flags["still"],
              accel_noise_std=accel_sd, temp_noise=flags["temp_noise"], sample_rate=sample_rate, rng=rng)
    if ramp is None:
        rec, points = chamber_session(truth, temps, soak=flags["temp_soak"], **kw)
        chamber = {"temp_points_degC": temps, "temp_soak_s": flags["temp_soak"]}
        facts = {"imu_thermal": {**truth.to_dict(), "points": points}}
    else:
        rec, facts = ramp_session(truth, *ends, **kw)
        chamber = {"temp_ramp": {"low_degC": ends[0], "high_degC": ends[1], "rate_degC_per_min": ends[2]}}
        facts = {"imu_thermal": {**truth.to_dict(), "ramp": facts}}
    _, gyro = truth.params(truth.ref_temp)
    settings.update(poses=flags["poses"], tilt_deg=flags["tilt"], still_s=flags["still"], accel_noise_std=accel_sd,
                    misalignment_deg=flags["misalignment"], **chamber,
                    temp_hysteresis_m_s2=flags["temp_hysteresis"], temp_noise_degC=flags["temp_noise"])
    return rec, Affine(K=np.linalg.inv(gyro[:9].reshape(3, 3)), B=gyro[9:]), facts


def turntable(gyro_kw, proto, sample_rate, rng, settings):
    """A turntable session of a gyro following the thermal truth: recording, model at 25 degC, facts."""
    import numpy as np

    from ..models import Affine
    from ..simulation import VirtualGyro
    from ..simulation.thermal_truth import ThermalTruth
    from ..simulation.turntable import simulate_turntable

    thermal = ThermalTruth()
    K, B = thermal(np.array([thermal.ref_temp]))
    model = Affine(K[0], B[0])
    rec = simulate_turntable(VirtualGyro(model, thermal=thermal, **gyro_kw), proto, sample_rate=sample_rate, rng=rng)
    settings.update(temps_degC=list(proto.temps), rates_deg_s=list(proto.rates), axes=list(proto.axes),
                    step_duration_s=proto.step_duration, table_tau_s=proto.table_tau,
                    temp_noise_degC=proto.temp_noise, temp_quantum_degC=proto.temp_quantum)
    return rec, model, {"thermal": thermal.to_dict()}


def profile_run(model, gyro_kw, profile, profile_units, duration, sample_rate, rng, settings):
    """A recording of a rate profile read from a CSV file."""
    from ..io import read_profile
    from ..simulation import VirtualGyro
    from ..simulation.profiles import simulate_profile

    if profile is None or duration is None:
        raise InputError("--protocol profile needs --profile FILE.csv and --duration SECONDS")
    rec, true_rates = simulate_profile(VirtualGyro(model, **gyro_kw), read_profile(profile, units=profile_units),
                                       duration=duration, sample_rate=sample_rate, rng=rng)
    settings.update(profile=str(profile), duration_s=duration)
    return rec, {}, true_rates
