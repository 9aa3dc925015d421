"""Output pieces of ``simulate``: counts with a sensitivity, and a size estimate and a progress bar for
large sessions (a paper-size turntable session is 7.6 M samples, about 600 MB of CSV)."""

from __future__ import annotations

from ..errors import InputError
from ._options import in_unit, triple_in_unit
from ._sim_runs import turntable_protocol

__all__ = ["announce", "as_counts", "output_unit", "rate_flags", "write_output", "writing_bar"]


def rate_flags(speed, noise, bias_instability, rate_random_walk, quantum, full_scale, b):
    """The rate flags as numbers in the unit each names (speed, full scale deg/s; the rest rad/s); a number
    written with another unit (2deg/s, 0.035rad/s) is converted to it."""
    return (60.0 if speed is None else in_unit("--speed", speed, "deg/s"), in_unit("--noise", noise, "rad/s"),
            in_unit("--bias-instability", bias_instability, "rad/s") or 0.0,
            in_unit("--rrw", rate_random_walk, "rad/s") or 0.0, in_unit("--quantum", quantum, "rad/s"),
            in_unit("--full-scale", full_scale, "deg/s"), triple_in_unit("--b", b, "rad/s", (0.0, 0.0, 0.0)))


def write_output(output, rec, unit: str, sensitivity: float | None, settings: dict, what: str, *, large: bool) -> None:
    """Write the simulated recording in `unit` (counts through the sensitivity), with a bar when `large`."""
    from ..io import write_recording

    if unit == "counts":
        rec = as_counts(rec, sensitivity)
        settings["sensitivity_lsb_per_deg_s"] = sensitivity
    note = f"{what}; gyro in {unit}" + (f" ({sensitivity:g} LSB per deg/s)" if unit == "counts" else "") + ", t in s"
    with writing_bar(len(rec) if large else None) as advance:
        write_recording(output, rec, units=unit, header_comment=note, progress=advance)


def output_unit(units: str, sensitivity: float | None) -> str:
    """The written unit; counts need the sensitivity that makes them."""
    from .._validation import positive
    from ..units import parse_input_unit

    unit = parse_input_unit(units, "units")
    if unit == "counts" and sensitivity is None:
        raise InputError("{param} counts needs the sensitivity of the counts", param="units",
                         hint="give {param:sensitivity} LSB per deg/s, e.g. 131 (MPU-9250 at +-250 deg/s)")
    if unit != "counts" and sensitivity is not None:
        raise InputError(f"{{param}} applies to --units counts, not {unit}", param="sensitivity",
                         hint="leave it out, or write counts")
    if sensitivity is not None:
        positive("sensitivity", sensitivity)
    return unit


def as_counts(rec, sensitivity: float):
    """The recording as a sensor's integers: deg/s times the sensitivity, rounded."""
    import dataclasses

    import numpy as np

    counts = np.round(np.degrees(rec.gyro) * sensitivity)
    return dataclasses.replace(rec, gyro=counts, units="counts", source_units="counts", sensitivity=sensitivity)


#: Sessions from this many samples on get a size estimate up front and a progress bar.
_LARGE = 1_000_000


def announce(protocol: str, flags: dict, sample_rate: float, temps, rates, step_duration, unit: str,
             console) -> int | None:
    """For a large session, print its size before the long work starts; the sample count, or None."""
    n = None
    if protocol == "turntable":
        proto = turntable_protocol(temps, rates, step_duration, flags["temp_noise"], flags["temp_quantum"])
        n = len(proto.temps) * len(proto.signed_rates()) * len(proto.axes) * round(proto.step_duration * sample_rate)
    elif protocol in ("static", "profile") and flags.get("duration"):
        n = int(flags["duration"] * sample_rate)
    if n is None or n < _LARGE:
        return None
    cells = 3 * (7 if unit == "counts" else 21) + 12 + (14 if protocol == "turntable" else 0) + (
        20 if protocol == "static" else 0) + (63 if flags.get("accel_noise_density") is not None else 0)
    console.print(f"simulating {n / 1e6:.3g} M samples ({n / sample_rate / 3600:.3g} h of data at {sample_rate:g} Hz): "
                  f"about {n * cells / 1e6:.0f} MB of CSV", highlight=False, soft_wrap=True)
    return n


class _NoBar:
    def __enter__(self):
        return None

    def __exit__(self, *exc):
        return False


def writing_bar(rows: int | None):
    """A progress bar on stderr while `rows` rows are written (nothing for a small session)."""
    if rows is None:
        return _NoBar()
    import contextlib

    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from .app import err_console

    @contextlib.contextmanager
    def bar():
        with Progress(TextColumn("writing"), BarColumn(), TextColumn("{task.percentage:>3.0f} %"),
                      TimeRemainingColumn(), console=err_console, transient=True,
                      disable=not err_console.is_terminal) as progress:  # a log file gets no bar (nor its blank line)
            task = progress.add_task("write", total=rows)
            yield lambda n: progress.advance(task, n)

    return bar()
