"""How a whole-IMU calibration is shown (``gyrocal imu``, ``gyrocal capture --guide multi-position``):
the poses, the accelerometer's and the gyro's corrections with their 1-sigma, and the fits' quality."""

from __future__ import annotations

import math

from .app import console

__all__ = ["print_imu_run"]


#: Full-scale settings of common MEMS parts: LSB per deg/s and LSB per g (MPU-6050/9250, ICM-20xxx).
GYRO_SETTINGS = {131.0: "±250 °/s", 65.5: "±500 °/s", 32.8: "±1000 °/s", 16.4: "±2000 °/s"}
ACCEL_SETTINGS = {16384.0: "±2 g", 8192.0: "±4 g", 4096.0: "±8 g", 2048.0: "±16 g"}


def _nearest(value: float, settings: dict[float, str]) -> str:
    best = min(settings, key=lambda s: abs(math.log(value / s)))
    off = value / best - 1
    return f"{settings[best]} ({best:g} LSB) is {off:+.1%} away" if abs(off) < 0.15 else "no common setting within 15 %"


def _print_accel(run) -> None:
    from ..units import accel_scale

    a, part = run.result.accel, run.calibration.accelerometer
    units = part["units"]
    matrix, offset = part["correction"]["matrix"], part["correction"]["offset"]
    c_in = accel_scale(units["input"], units["sensitivity"], units["gravity"])
    console.print(f"accelerometer: {a.model} model, a_true = matrix @ (raw - offset), raw in {units['input']}, "
                  f"a_true in {units['output']}; |a_true| = {units['gravity']:g} m/s^2 at rest", highlight=False,
                  soft_wrap=True)
    for line in a.choice:
        console.print(f"  model: {line}", highlight=False, soft_wrap=True, markup=False)
    std = dict(zip(a.param_names, a.std))
    d_out = 1.0 if units["output"] == "m/s^2" else units["gravity"]
    sigma = [[std.get(f"A_{r}{c}", 0.0) * c_in / d_out for c in "xyz"] for r in "xyz"]
    console.print(_matrix_table(matrix, sigma, offset, [std[f"o_{r}"] / c_in for r in "xyz"], units["input"]))
    axes = a.sensor_axes()
    sens = ", ".join(f"{k[-1]} {axes[k][0]:.6g} ±{axes[k][1]:.2g}" for k in ("sens_x", "sens_y", "sens_z"))
    angles = ", ".join(f"{k[-2:]} {axes[k][0]:.4f} ±{axes[k][1]:.2g}" for k in ("angle_xy", "angle_xz", "angle_yz"))
    console.print(f"  sensor axes (frame-free): reading per m/s^2 along each axis {sens}; angles between axes [deg] "
                  f"{angles}", highlight=False, soft_wrap=True, markup=False)
    if units["input"] == "counts" and units["sensitivity"] is None:
        lsb = [axes[f"sens_{k}"][0] * units["gravity"] for k in "xyz"]
        console.print("  implied sensitivity: " + ", ".join(f"{v:.5g} LSB/g" for v in lsb) + "; nearest setting: "
                      + _nearest(float(sum(lsb) / 3), ACCEL_SETTINGS), highlight=False, soft_wrap=True)
    console.print(f"  fit: {_summary(a.fit)}", highlight=False, soft_wrap=True, markup=False)


def _matrix_table(matrix, matrix_std, offset, offset_std, input_units: str):
    """Rows x, y, z: the correction matrix and offset, each entry with its 1-sigma."""
    from rich import box
    from rich.markup import escape
    from rich.table import Table

    table = Table(box=box.SIMPLE_HEAD, pad_edge=False)
    for col in ("axis", "matrix x", "matrix y", "matrix z", escape(f"offset [{input_units}]")):
        table.add_column(col, justify="right")
    for r, axis in enumerate("xyz"):
        table.add_row(axis, *(f"{matrix[r][c]:.6g}" for c in range(3)), f"{offset[r]:.6g}")
        table.add_row("±1σ", *(f"{matrix_std[r][c]:.2g}" if matrix_std[r][c] > 0 else "" for c in range(3)),
                      f"{offset_std[r]:.2g}", style="dim")
    return table


def _summary(q) -> str:
    if q.dof == 0:
        return f"chi2 {q.chi2:.3g}, no spare equations"
    scaled = ", 1-sigma scaled by it" if q.covariance_scaled else ""
    return f"chi2 {q.chi2:.4g} for {q.dof} dof (p = {q.p_value:.2g}), Birge ratio {q.birge_ratio:.3g}{scaled}"


def _print_gyro(run) -> None:
    import numpy as np

    g, cal = run.result.gyro, run.calibration
    matrix, offset = cal.correction
    c, d = cal.input_scale, {"rad/s": 1.0, "deg/s": math.pi / 180}[cal.output_units]
    console.print(f"gyro: {g.model} model, w_true = matrix @ (raw - offset), raw in {cal.input_units}, w_true in "
                  f"{cal.output_units}", highlight=False, soft_wrap=True)
    for line in g.choice:
        console.print(f"  model: {line}", highlight=False, soft_wrap=True, markup=False)
    n = 9 if g.model == "affine" else 3
    a_std = np.zeros((3, 3))
    a_std[(np.ones((3, 3), bool) if n == 9 else np.eye(3, dtype=bool))] = g.std[:n]
    console.print(_matrix_table(matrix, a_std * c / d, offset, g.std[n:n + 3] / c, cal.input_units))
    if g.g_sensitivity is not None:
        gs = g.g_sensitivity / c
        console.print(f"  g-sensitivity [{cal.input_units} per m/s^2]: "
                      + "; ".join(" ".join(f"{v:.3g}" for v in row) for row in gs)
                      + f" (1-sigma up to {g.std[-9:].max() / c:.2g})", highlight=False, soft_wrap=True)
    if cal.input_units == "counts" and cal.sensitivity is None:
        lsb = 1.0 / np.diag(g.matrix) * math.pi / 180
        console.print("  implied sensitivity: " + ", ".join(f"{v:.5g} LSB/(deg/s)" for v in lsb) + "; nearest "
                      "setting: " + _nearest(float(np.mean(lsb)), GYRO_SETTINGS), highlight=False, soft_wrap=True)
    factors = ", ".join(f"{k} {v:.3g}" for k, v in g.noise_factors.items())
    console.print(f"  fit: {_summary(g.fit)}; scatter over the noise model: {factors}", highlight=False,
                  soft_wrap=True, markup=False)
    _print_pairs(g)


def _print_pairs(g) -> None:
    import numpy as np

    from .._arrays import median

    pairs = list(g.checks)
    if not pairs:
        return
    worst = max(pairs, key=lambda c: c.chi2)
    misfit = np.array([c.residual_deg for c in pairs])
    bad = [c.label for c in pairs if c.disagrees]
    z = median([np.sqrt(c.noise_chi2 / (2 if c.kind == "pair" else 3)) for c in pairs])
    beyond = sum(c.beyond_noise for c in pairs)
    console.print(f"  turns between poses: {len(pairs)}; misfit median {median(misfit):.2g} deg ({z:.2g} times "
                  f"its noise), largest {worst.residual_deg:.2g} deg ({worst.label}); beyond their noise: {beyond} of "
                  f"{len(pairs)}; " + (f"disagreeing with the others: {', '.join(bad)}" if bad else
                                       "none disagrees with the others")
                  + (f"; left out: {', '.join(g.left_out)}" if g.left_out else ""), highlight=False, soft_wrap=True,
                  markup=False)


def _thresholds(det) -> str:
    """Which multiplier of the stillness thresholds was used, and why."""
    if len(det.sweep) == 1:
        return f"stillness thresholds x{det.multiplier:g} those measured at rest, given by --threshold"
    counts = {n for _, n, _ in det.sweep}
    tried = ("" if len(counts) == 1 else "; poses found " + ", ".join(f"x{m:g}: {n}" for m, n, _ in det.sweep))
    return (f"stillness thresholds x{det.multiplier:g} those measured at rest, kept by the accelerometer fit of "
            f"x{det.sweep[0][0]:g}..x{det.sweep[-1][0]:g}{tried}")


def _print_poses(run, windows_from: str) -> None:
    r = run.result
    cov = r.coverage
    where = " ".join(f"{v:+.2f}" for v in cov.empty_cap_centre)
    source = f"from {windows_from}" if r.detection is None else "detected"
    console.print(f"{len(r.statics)} still poses {source} ({cov.poses} distinct orientations), a {r.kind} session; "
                  f"they cover the sphere with spread {cov.spread:.2f} of 1, largest empty cap {cov.empty_cap_deg:.0f}"
                  f" deg around ({where})", highlight=False, soft_wrap=True)
    if r.detection is not None:
        console.print(f"  {_thresholds(r.detection)}", highlight=False, soft_wrap=True)


def print_imu_run(run, windows_from: str = "--windows") -> None:
    """Poses, accelerometer and gyro of an :class:`~gyrocal.imu.run.ImuRun`, on stdout; `windows_from` names
    where given still poses came from."""
    _print_poses(run, windows_from)
    _print_accel(run)
    _print_gyro(run)
    _print_thermal(run)


def _print_thermal(run) -> None:
    """The temperature points and the smooth models' orders, when the log held several points."""
    th = getattr(run, "thermal", None)
    if th is None:
        return
    temps = ", ".join(f"{p.temperature:.1f} ({p.poses} poses)" for p in th.points)
    console.print(f"across temperature: {len(th.points)} points at {temps} degC; file section accelerometer.thermal",
                  highlight=False, soft_wrap=True, markup=False)
    for name, model in (("accelerometer", th.accel), ("gyro", th.gyro)):
        orders = ", ".join(f"{n} {int(o)}" for n, o in zip(model.names, model.smooth.orders))
        console.print(f"  {name}: smooth polynomial orders {orders} (and 3-node Lagrange)", highlight=False,
                      soft_wrap=True, markup=False)
    console.print(f"  frame: {th.to_dict()['frame']}", highlight=False, soft_wrap=True, markup=False)
    limits = getattr(th, "limits", None)
    for sensor in ("accelerometer", "gyro"):
        h = None if limits is None else getattr(limits, sensor)
        if h is not None:
            console.print(f"  branches: {h.describe(sensor)}", highlight=False, soft_wrap=True, markup=False)
