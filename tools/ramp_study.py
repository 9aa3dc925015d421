"""A ramp against plateaus: the corrected accelerometer's 1-sigma and chamber time, measured on seeded boards.

For each board (``random_thermal_imu``), a plateau session (``chamber_session``: POINTS, 24 poses each,
SOAK s unrecorded before each later point) and ramps from -25 to 60 degC at several rates
(``ramp_session``) are simulated with the same noise and fitted (``calibrate_imu_thermal`` /
``calibrate_ramp``). At GRID temperatures and six gravity directions (each sensor axis up and down)
the corrected specific force ``A(T) (u - o(T))`` of the truth's raw reading is compared with ``g d``:

* z = error / predicted 1-sigma (delta method through the smooth model's coefficient covariance);
  RMS z over all boards, temperatures, directions and components;
* sigma_f = RMS of the predicted 1-sigma: the figure of merit whose equality sets the time saved;
* on the ramps, the gyro's 12 parameters against the truth at the same temperatures (RMS z).

Chamber time: plateaus ``(points - 1) * soak + recorded time``; a ramp ``(high - low) / rate``.

    PYTHONPATH=src python tools/ramp_study.py --boards 4 --rates 2,5,10
"""

from __future__ import annotations

import argparse

import numpy as np

from gyrocal.imu.ramp import calibrate_ramp
from gyrocal.imu.thermal import calibrate_imu_thermal
from gyrocal.models import ScaleBias
from gyrocal.simulation.chamber import chamber_session, random_thermal_imu
from gyrocal.simulation.ramp import ramp_session

G = 9.80665
POINTS = np.linspace(-25.0, 60.0, 5)
SOAK = 600.0
GRID = np.linspace(-25.0, 60.0, 18)
DIRS = np.vstack([np.eye(3), -np.eye(3)])
FS, ACCEL_SD, GYRO_SD = 100.0, 0.02, 0.005
_LOWER = [0, 3, 4, 6, 7, 8, 9, 10, 11]
_MASK = np.tril(np.ones((3, 3), bool))


def corrected_z(model, truth) -> tuple[np.ndarray, np.ndarray]:
    """z-scores and predicted 1-sigma (GRID, DIRS, 3) of the corrected specific force of the truth's readings."""
    sm = model.smooth
    width = sm.coefs.shape[1]
    m = len(model.names)
    powers = np.vander((GRID - sm.centre) / sm.scale, width, increasing=True)
    gain = np.einsum("ij,np->nijp", np.eye(m), powers).reshape(len(GRID), m, m * width)
    covs = gain @ model.smooth_covariance @ gain.transpose(0, 2, 1)
    values = sm(GRID)
    zs, sig = np.empty((len(GRID), len(DIRS), 3)), np.empty((len(GRID), len(DIRS), 3))
    for k, temp in enumerate(GRID):
        true_p, _ = truth.params(temp)
        u = np.linalg.solve(true_p[:9].reshape(3, 3), G * DIRS.T).T + true_p[9:]
        a = np.zeros((3, 3))
        a[_MASK] = values[k, :6]
        v = u - values[k, 6:]
        f = v @ a.T
        for d in range(len(DIRS)):  # df_i / dA_ij = v_j, df / do = -A
            jac = np.zeros((3, 9))
            rows, cols = np.nonzero(_MASK)
            jac[rows, np.arange(6)] = v[d, cols]
            jac[:, 6:] = -a
            sig[k, d] = np.sqrt(np.einsum("ij,jk,ik->i", jac, covs[k], jac))
        zs[k] = (f - G * DIRS) / sig[k]
    return zs, sig


def gyro_z(res, truth) -> np.ndarray:
    """z-scores (GRID, 12) of the gyro's model (matrix row-major, offset) against the truth's cubics."""
    value, sigma = res.gyro.at(GRID)
    return (value - np.array([truth.params(t)[1] for t in GRID])) / sigma


def board(seed: int, rates) -> dict:
    """One board: z and sigma_f of the plateau session and of each ramp, and their chamber times [s]."""
    rng = np.random.default_rng(seed)
    truth = random_thermal_imu(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), rng)
    kw = {"gyro_kw": {"noise_std": GYRO_SD}, "sample_rate": FS, "accel_noise_std": ACCEL_SD, "rng": rng}
    rec, _ = chamber_session(truth, POINTS, soak=SOAK, **kw)
    breaks = list(np.flatnonzero(np.diff(rec.t) > 1.0) + 1)
    res = calibrate_imu_thermal(rec.t, rec.gyro, rec.accel, rec.temp, breaks=breaks, threshold=3.0)
    out = {"plateaus": (*corrected_z(res.accel, truth), len(rec) / FS + (len(POINTS) - 1) * SOAK)}
    for rate in rates:
        rec, facts = ramp_session(truth, -25.0, 60.0, rate, **kw)
        res = calibrate_ramp(rec.t, rec.gyro, rec.accel, rec.temp, threshold=3.0)
        out[rate] = (*corrected_z(res.accel, truth), facts["duration_s"], gyro_z(res, truth))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--boards", type=int, default=4)
    parser.add_argument("--rates", default="2,5,10", help="ramp rates [degC/min], comma-separated")
    args = parser.parse_args()
    rates = [float(r) for r in args.rates.split(",")]
    runs = [board(100 + b, rates) for b in range(args.boards)]
    rows = []
    for key in ["plateaus", *rates]:
        z = np.concatenate([r[key][0].ravel() for r in runs])
        sig = np.sqrt(np.mean(np.concatenate([r[key][1].ravel() for r in runs]) ** 2))
        minutes = runs[0][key][2] / 60.0
        rows.append((key, minutes, sig))
        name = "plateaus" if key == "plateaus" else f"ramp {key:g} degC/min"
        print(f"{name:>22}: chamber {minutes:6.1f} min, sigma_f {sig:.3e} m/s^2, RMS z {np.sqrt(np.mean(z**2)):.3f} "
              f"({z.size} z, {args.boards} boards), |z|>3 {np.mean(np.abs(z) > 3):.4f}")
        if key != "plateaus":
            zg = np.concatenate([r[key][3].ravel() for r in runs])
            print(f"{'':>22}  gyro's 12 parameters at the same temperatures: RMS z {np.sqrt(np.mean(zg**2)):.3f} "
                  f"({zg.size} z)")
    ramps = sorted(rows[1:], key=lambda r: r[1])
    t, s = np.log([r[1] for r in ramps]), np.log([r[2] for r in ramps])
    target = np.log(rows[0][2])
    slope, icept = np.polyfit(t, s, 1)
    need = float(np.exp((target - icept) / slope))
    print(f"log sigma_f against log ramp time: slope {slope:.2f} (-0.5: sigma ~ 1/sqrt(time)); the plateaus' "
          f"sigma_f {rows[0][2]:.3e} needs a ramp of {need:.1f} min against {rows[0][1]:.1f} min of plateaus "
          f"({100 * (1 - need / rows[0][1]):.0f} % less chamber time, rate {85.0 / need:.2g} degC/min)")


if __name__ == "__main__":
    main()
