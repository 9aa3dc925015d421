"""Benchmark: verify a long log against a reference gyro, and the z-scores of the alignment over seeds.

Run by hand:  python bench/bench_verify.py [--minutes 60] [--seeds 100]

Part 1 (speed): a test gyro at 200 Hz and a reference at 100 Hz record ``--minutes`` of
random smooth motion on two clocks (offset 3.7 s, drift 50 ppm, mounting 10 deg). Prints
the time of ``align`` and of the whole ``verify_rates`` (alignment, reference noise, error
figures with 1000 bootstrap replicates), the alignment's errors against the truth in units
of its 1-sigma, and two naive baselines measured in the same process:

* the coarse search over every lag by direct correlation (``numpy.correlate``) against the
  FFT correlation ``align`` uses, on the first ``--coarse-minutes`` of both logs;
* the refinement by ``scipy.optimize.least_squares`` (dense 3N x 5 Jacobian by finite
  differences, plain linear-interpolation slopes) against ``refine`` (chunked normal
  equations, smoothed slopes, sandwich covariance), both from a start 2 ms off.

Part 2 (honesty of the 1-sigma): ``--seeds`` random pairs (servo and smooth motion, rates 50 to
400 Hz, offsets +-10 s, drifts +-200 ppm, rotations 0 to 60 deg, noises over a decade): the
RMS of the z-scores of offset and drift (1 when the 1-sigma holds) and the mean chi-square
per degree of freedom of the rotation.

Part 3 (honesty of the bootstrap): ``--sessions`` sessions of new random motion with one
imperfect calibration: the spread of the MSE after calibration over the sessions against
the mean block-bootstrap 1-sigma (1 when the 1-sigma holds).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from verify_pairs import make_pair  # noqa: E402

from gyrocal.verify import align, verify_rates  # noqa: E402
from gyrocal.verify.refine import PPM, interpolate, refine  # noqa: E402


def _truth_errors(a, truth) -> tuple[float, float, float]:
    phi = Rotation.from_matrix(a.mounting_rotation @ truth.mounting_rotation.T).as_rotvec()
    return ((a.time_offset_s - truth.time_offset_s) / a.std[0], (a.clock_drift_ppm - truth.clock_drift_ppm) / a.std[1],
            float(phi @ np.linalg.solve(a.covariance[2:, 2:], phi)))


def naive_refine(t, w, t_ref, w_ref, offset, drift, rot):
    """The same least squares by scipy's general solver: residual vector of 3N, Jacobian by differences."""
    def residuals(p):
        tau = (t - p[0]) / (1.0 + p[1] * PPM)
        v, _, _ = interpolate(t_ref, w_ref, tau)
        return (w - v @ (Rotation.from_rotvec(p[2:]).as_matrix() @ rot).T).ravel()

    x0 = np.array([offset, drift, 0.0, 0.0, 0.0])
    return least_squares(residuals, x0, x_scale=[1e-4, 1.0, 1e-4, 1e-4, 1e-4], method="trf")


def coarse_ratio(pair, minutes: float) -> None:
    """Every lag of the magnitude correlation: direct sums against the FFT (same grid, same signals)."""
    from gyrocal.verify._signal import correlate
    from gyrocal.verify.coarse import magnitude_grid

    t, ref_t = pair.test.t, pair.ref.t
    keep, keep_ref = t < t[0] + 60 * minutes, ref_t < ref_t[0] + 60 * minutes
    a = magnitude_grid(t[keep], pair.test.gyro[keep], 100.0)
    b = magnitude_grid(ref_t[keep_ref], pair.ref.gyro[keep_ref], 100.0)
    a, b = a - a.mean(), b - b.mean()
    t0 = time.perf_counter()
    fast = correlate(a, b, "full")
    t_fft = time.perf_counter() - t0
    t0 = time.perf_counter()
    slow = np.correlate(a, b, mode="full")
    t_direct = time.perf_counter() - t0
    assert np.allclose(fast, slow, atol=1e-6 * np.abs(slow).max())
    print(f"coarse search over all {len(fast):,} lags ({minutes:g} min at 100 Hz): FFT {t_fft * 1e3:.1f} ms, direct "
          f"{t_direct:.2f} s; ratio {t_direct / t_fft:.0f}x")


def speed(minutes: float, coarse_minutes: float) -> None:
    rng = np.random.default_rng(2026)
    pair = make_pair(rng, duration=60.0 * minutes, fs_test=200.0, fs_ref=100.0, noise_test=0.02, noise_ref=0.001,
                     offset=3.7, drift=50.0, mounting_deg=10.0)
    t, w = pair.test.t, np.asarray(pair.test.gyro)
    head = make_pair(np.random.default_rng(1), duration=20.0)  # imports (scipy.signal) outside the timing
    align(head.test.t, head.test.gyro, head.ref.t, head.ref.gyro)
    print(f"{minutes:g} min: {len(t):,} test samples at 200 Hz, {len(pair.ref.t):,} reference samples at 100 Hz")
    t0 = time.perf_counter()
    a = align(t, w, pair.ref.t, pair.ref.gyro)
    t_align = time.perf_counter() - t0
    t0 = time.perf_counter()
    verify_rates(t, w, w, pair.ref.t, pair.ref.gyro, units="deg/s", seed=1)
    t_verify = time.perf_counter() - t0
    z_off, z_drift, chi2 = _truth_errors(a, pair.truth)
    print(f"align: {t_align:.2f} s; verify_rates (alignment + figures, 1000 replicates): {t_verify:.2f} s")
    print(f"  offset {a.time_offset_s:.6f} s (truth 3.7, 1-sigma {a.std[0] * 1e6:.1f} us, z {z_off:+.2f}); "
          f"drift {a.clock_drift_ppm:.3f} ppm (truth 50, 1-sigma {a.std[1]:.3f}, z {z_drift:+.2f}); "
          f"rotation chi2 (3 dof) {chi2:.2f}, 1-sigma {math.degrees(a.std[2:].max()) * 3600:.1f} arcsec")
    inside = (t - a.time_offset_s >= pair.ref.t[0] + 1) & (t - a.time_offset_s <= pair.ref.t[-1] - 1)
    ti, wi = t[inside], w[inside]
    start = a.time_offset_s + 2e-3
    t0 = time.perf_counter()
    tc = 0.5 * (ti[0] + ti[-1])
    mine = refine(ti, wi, pair.ref.t, pair.ref.gyro, (tc - start) / (1 + a.clock_drift_ppm * PPM), a.clock_drift_ppm,
                  a.mounting_rotation)
    t_mine = time.perf_counter() - t0
    t0 = time.perf_counter()
    fit = naive_refine(ti, wi, pair.ref.t, pair.ref.gyro, start, a.clock_drift_ppm, a.mounting_rotation)
    t_naive = time.perf_counter() - t0
    mine_offset = tc - mine.a * (1 + mine.drift_ppm * PPM)
    print(f"refinement from a start 2 ms off: refine {t_mine:.2f} s ({mine.iterations} iterations, with its "
          f"covariance), scipy least_squares {t_naive:.2f} s ({fit.nfev} evaluations, no covariance); ratio "
          f"{t_naive / t_mine:.1f}x; offsets {abs(fit.x[0] - mine_offset) / a.std[0]:.2f} sigma apart; Jacobian in "
          f"memory: {3 * len(ti) * 5 * 8 / 1e6:.0f} MB against {3 * min(len(ti), 1 << 18) * 5 * 8 / 1e6:.0f} MB")
    coarse_ratio(pair, min(coarse_minutes, minutes))


def zscores(seeds: int) -> None:
    z = []
    t0 = time.perf_counter()
    for seed in range(seeds):
        rng = np.random.default_rng(50_000 + seed)
        pair = make_pair(rng, motion=("smooth", "servo")[seed % 2], duration=40.0,
                         fs_test=float(rng.choice([100.0, 200.0, 400.0])), fs_ref=float(rng.choice([50.0, 100.0, 200.0])),
                         noise_test=rng.uniform(0.005, 0.05), noise_ref=rng.uniform(0.0005, 0.005),
                         offset=rng.uniform(-10, 10), drift=rng.uniform(-200, 200), mounting_deg=rng.uniform(0, 60))
        z.append(_truth_errors(align(pair.test.t, pair.test.gyro, pair.ref.t, pair.ref.gyro), pair.truth))
    z = np.array(z)
    band = 1.0 / math.sqrt(2 * seeds)
    print(f"{seeds} random pairs ({time.perf_counter() - t0:.0f} s): RMS z offset {math.sqrt(np.mean(z[:, 0] ** 2)):.3f}, "
          f"RMS z drift {math.sqrt(np.mean(z[:, 1] ** 2)):.3f} (1 +- {band:.3f} expected), rotation mean chi2/3 "
          f"{np.mean(z[:, 2]) / 3:.3f} (1 +- {math.sqrt(2 / 3 / seeds):.3f}); largest |z| "
          f"{np.abs(z[:, :2]).max():.2f}, largest chi2 {z[:, 2].max():.1f}")


def sessions(count: int) -> None:
    from gyrocal import ScaleBias
    from gyrocal.models import correct

    true = ScaleBias(k=(1.01, 0.99, 1.02), b=(0.02, -0.01, 0.015))
    cal = ScaleBias(k=true.k * 1.003, b=true.b + 0.004)
    mse, sd = [], []
    for seed in range(count):
        pair = make_pair(np.random.default_rng(seed), duration=40.0, noise_test=0.01, noise_ref=0.001, model=true)
        calibrated = correct(cal.matrix, cal.offset, pair.test.gyro)
        report, _ = verify_rates(pair.test.t, pair.test.gyro, calibrated, pair.ref.t, pair.ref.gyro, units="rad/s",
                                 seed=seed, replicates=200)
        mse.append(report.metrics.values["mse_after"])
        sd.append(report.metrics.std["mse_after"])
    ratio = np.std(mse, axis=0, ddof=1) / np.mean(sd, axis=0)
    print(f"{count} sessions: spread of the MSE after calibration / mean bootstrap 1-sigma = "
          f"{', '.join(f'{r:.2f}' for r in ratio)} (x, y, z; 1 +- {1 / math.sqrt(2 * (count - 1)):.2f} expected)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0, help="length of the long log [min]")
    parser.add_argument("--coarse-minutes", type=float, default=10.0, help="length of the direct-correlation baseline")
    parser.add_argument("--seeds", type=int, default=100, help="random pairs for the z-scores (0: skip)")
    parser.add_argument("--sessions", type=int, default=40, help="sessions for the bootstrap check (0: skip)")
    args = parser.parse_args(argv)
    speed(args.minutes, args.coarse_minutes)
    if args.seeds:
        zscores(args.seeds)
    if args.sessions:
        sessions(args.sessions)
    return 0


if __name__ == "__main__":
    sys.exit(main())
