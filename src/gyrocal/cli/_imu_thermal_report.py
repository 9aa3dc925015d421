"""``thermal-report`` on an IMU thermal calibration (``gyrocal imu``'s ``accelerometer.thermal``).

The test log's still poses are corrected by the single-temperature baseline, the 3-node Lagrange
table and the smooth model (:mod:`gyrocal.imu.thermal_eval`); the report folder gets
``summary.csv``/``summary.md`` (RMS per scheme and the factor on the baseline), ``by_temperature.csv``
and ``poses.csv``.
"""

from __future__ import annotations

from pathlib import Path

from .app import console

__all__ = ["imu_thermal_report"]


def _write(ev, output: Path) -> list[Path]:
    import numpy as np

    from .._atomic import write_text_atomic
    from ..imu.thermal_eval import SCHEMES
    from ..io import write_csv
    from ..plotting.thermal_report import markdown_table

    output.mkdir(parents=True, exist_ok=True)
    summary, by_temp = ev.summary(), ev.by_temperature()
    poses = {"temperature": ev.temperature, **{f"raw_a{a}": ev.raw_accel[:, i] for i, a in enumerate("xyz")},
             **{f"{s}_accel": ev.accel[s] for s in SCHEMES},
             **{f"{s}_gyro_{a}": ev.gyro[s][:, i] for s in SCHEMES for i, a in enumerate("xyz")},
             "smooth_accel_z": ev.accel_z}
    paths = []
    for name, rows in (("summary.csv", summary), ("by_temperature.csv", by_temp)):
        write_csv(output / name, {k: np.array([r[k] for r in rows]) for k in rows[0]})
        paths.append(output / name)
    write_csv(output / "poses.csv", poses)
    paths.append(output / "poses.csv")
    text = ["# IMU thermal calibration report\n",
            f"{len(ev.temperature)} still poses at {ev.temperature.min():.1f} to {ev.temperature.max():.1f} degC. "
            "Still, the corrected accelerometer's magnitude is g and the corrected gyro reads no rate: errors are "
            "|f| - g [m/s^2] and the still rate [rad/s]; factor: the single-temperature baseline's RMS over the "
            f"scheme's. The smooth model's RMS z of |f| - g against its own 1-sigma: "
            f"{np.sqrt(np.mean(ev.accel_z**2)):.2f}.\n",
            "## RMS error per scheme\n", markdown_table(summary),
            "\n## By test temperature\n", markdown_table(by_temp)]
    write_text_atomic(output / "summary.md", "\n".join(text))
    return paths + [output / "summary.md"]


def imu_thermal_report(cal, test: Path, output: Path, *, units, accel_units, columns, skip_rows, sample_rate,
                       figures: bool) -> None:
    """Evaluate `cal`'s ``accelerometer.thermal`` on the chamber test log `test` and write the report."""
    import numpy as np
    from rich.markup import escape
    from rich.table import Table

    from ..errors import InputError
    from ..imu.thermal_eval import SCHEMES, evaluate_imu_thermal
    from ._reading import read_from_flags

    part = cal.accelerometer
    rec = read_from_flags(test, units=units or cal.input_units, columns=columns, skip_rows=skip_rows,
                          sample_rate=sample_rate, sensitivity=cal.sensitivity,
                          accel_units=accel_units or part["units"]["input"],
                          accel_sensitivity=part["units"]["sensitivity"], gravity=part["units"]["gravity"],
                          need_accel=True, saturation="ignore")
    if rec.temp is None:
        raise InputError(f"{test} has no temperature column; the IMU thermal report evaluates each still pose at "
                         "its temperature", hint="map it with --columns temp=NAME")
    ev = evaluate_imu_thermal(part["thermal"], rec.t, rec.gyro, rec.accel, rec.temp,
                              gravity=float(part["units"]["gravity"]), breaks=rec.time_base().breaks)
    if len(ev.temperature) < 1:
        raise InputError(f"{test} holds no still pose to evaluate the calibration at")
    paths = _write(ev, output)
    if figures:
        console.print("note: the IMU thermal report draws no figures (tables only)", highlight=False)
    table = Table(title=escape("still poses: RMS of |f| - g [m/s^2] and of the still rate [rad/s]"))
    for col in ("scheme", "accel RMS", "x baseline", "gyro RMS", "x baseline"):
        table.add_column(col, justify="right", no_wrap=True)
    for r in ev.summary():
        table.add_row(r["scheme"], f"{r['accel_rms_m_s2']:.3g}", f"{r['accel_factor']:.1f}",
                      f"{r['gyro_rms_rad_s']:.3g}", f"{r['gyro_factor']:.1f}")
    console.print(table)
    console.print(f"{len(ev.temperature)} still poses at {ev.temperature.min():.1f} to {ev.temperature.max():.1f} "
                  f"degC; smooth model's RMS z of |f| - g against its 1-sigma {np.sqrt(np.mean(ev.accel_z**2)):.2f} "
                  f"(schemes: {', '.join(SCHEMES)})", highlight=False, soft_wrap=True)
    console.print(f"wrote {len(paths)} files to {output}", highlight=False)
