"""What the self-checks cost: one calibration of a 1-million-sample recording with and without them.

Run by hand:  python bench/bench_selfcheck.py [--samples 1000000] [--repeat 9] [--stamps sensor|receive|gaps]

Simulates a long servo session at 1 kHz (the servo method of Wang et al.: six turns at 60 deg/s,
repeated; MPU9250 errors of Table III; ramps, vibration, 5 % speed ripple, 5 deg misalignment),
optionally with receive-time stamps (and packet gaps), then times in the same process, alternating:

* the calibration without its self-checks, ``calibrate(rec, ..., checks=False)``: segmentation,
  window means on the stamps, the speed ripple regressed out of each plateau and long-run
  (Newey-West) variances of the window means, the fit and its covariance;
* the same with the self-checks (the default, ``checks=True``): the time base read from the
  stamps (rate, gaps, late deliveries, the sensor clock rebuilt), turns across gaps screened,
  goodness of fit with Birge scaling, plausibility of k, the ``fit`` and ``observed`` sections;
* the plain estimate, ``checks=False, long_run=False``: white-noise covariance, plain means, as
  before the self-checks existed (to show the cost of everything together).

Prints the best CPU time of `repeat` runs of each, for the speed and the angle reference, and what
the checks add, against the calibration alone and against reading the CSV plus calibrating (what
``gyrocal calibrate`` does; target: the checks cost under 10 % of a calibration). The naive baseline,
timed in the same runs: the same calibrations with the straightforward implementations the fast
paths replaced (``tests/naive_selfcheck.py``: window by window, whole-log arrays of steps and clock
residuals, the clock rebuilt sample by sample), which ``tests/test_fast_paths.py`` checks the fast
paths against.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import naive_selfcheck  # noqa: E402  (the straightforward implementations: the naive baseline)


def cpu_time(fn) -> float:
    """CPU time of one call [s]: this process's own, so other programs on a shared machine count less."""
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def session(samples: int, rate: float, stamps: str, seed: int):
    from gyrocal.models import ScaleBias
    from gyrocal.simulation import VirtualGyro
    from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo
    from gyrocal.simulation.timestamps import ReceiveClock, with_time_defects

    one = ServoProtocol()
    per_protocol = (one.lead_in + 6 * (one.turn_angle / one.speed + one.ramp) + 5 * 3.0) * rate
    protocol = ServoProtocol(turns=PAPER_TURNS * math.ceil(samples / per_protocol), misalignment_deg=5.0,
                             ripple=0.05)
    gyro = VirtualGyro(ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076]), noise_std=0.035)
    rng = np.random.default_rng(seed)
    rec, _ = simulate_servo(gyro, protocol, sample_rate=rate, rng=rng)
    if stamps != "sensor":  # receive-time stamps, with six 170 ms packet gaps for "gaps"
        rec, _ = with_time_defects(rec, rng, clock=ReceiveClock(read_time=0.0003, jitter=0.0002),
                                   gaps=6 if stamps == "gaps" else 0, gap_length=0.17)
    return rec


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--rate", type=float, default=1000.0)
    parser.add_argument("--repeat", type=int, default=9)
    parser.add_argument("--stamps", choices=("sensor", "receive", "gaps"), default="sensor")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    from gyrocal.io import read_recording, write_recording
    from gyrocal.pipeline import calibrate

    rec = session(args.samples, args.rate, args.stamps, args.seed)
    print(f"recording: {len(rec):,} samples at {rec.sample_rate:.6g} Hz ({args.stamps} stamps); best CPU time of "
          f"{args.repeat} alternating runs each")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "session.csv"
        write_recording(path, rec, units="deg/s")
        read = min(cpu_time(lambda: read_recording(path, units="deg/s")) for _ in range(args.repeat))
    print(f"reading the CSV (read_recording): {read:.3f} s")
    for name, ref in (("speed 60 deg/s", {"speed": math.radians(60)}), ("angle 360 deg", {"angle": 2 * math.pi})):
        run = calibrate(rec, **ref)
        best = _alternating(rec, ref, args.repeat)
        print(f"{name} ({len(run.observations)} windows), best CPU time [s]:")
        for label, key in (("plain estimate (checks=False, long_run=False)", "plain"),
                           ("calibration without the self-checks (checks=False)", "estimate"),
                           ("calibration with them (the default)", "checked")):
            fast, slow = best[key], best["naive " + key]
            print(f"  {label:52s} {fast:6.3f}   naive {slow:6.3f}   {slow / fast:4.1f}x faster")
        from gyrocal.observations import ObservationSet

        windows = ObservationSet.from_observations(run.observations)  # built by the calibration either way
        from gyrocal.estimators import make_estimator

        start = make_estimator("first-moment").fit(windows)  # the fit the checks start from (made either way)
        own = min(cpu_time(lambda run=run, w=windows, f=start: _check_steps(rec, run, w, f)) for _ in range(args.repeat))
        print(f"  the self-check steps on their own (time base, gap screening, wandering axes, fit quality with the "
              f"extra variances and their refits, plausibility, the file's sections): {own:.4f} s = {100 * own / best['estimate']:.1f} % of the calibration without them")
        pair = _pair(rec, ref, args.repeat)
        print(f"  the two alone, alternating without the naive code between them (its whole-log arrays move the "
              f"allocator's pages): without {pair['estimate']:.3f} s, with {pair['checked']:.3f} s: the self-checks "
              f"cost {100 * (pair['checked'] / pair['estimate'] - 1):.1f} % of the calibration (target < 10 %)")
        for tag in ("", "naive "):
            extra, estimate = best[tag + "checked"] - best[tag + "estimate"], best[tag + "estimate"]
            print(f"  {tag or 'now: '}the self-checks cost {100 * extra / estimate:5.1f} % of the calibration"
                  f"{' (target < 10 %)' if not tag else ''}, {100 * extra / (estimate + read):4.1f} % of reading + "
                  f"calibrating; everything added to the plain estimate (ripple, long-run variances, self-checks): "
                  f"{100 * (best[tag + 'checked'] / best[tag + 'plain'] - 1):5.1f} % of it")


def _check_steps(rec, run, windows, fit) -> None:
    """The steps only the self-checks take, as ``calibrate`` takes them (on the `windows` `run` used): time
    base, gap screening, the wandering-axis pass (angles), goodness of fit with the groups' extra variances and
    their refits, plausibility, the file's sections."""
    from gyrocal.checks.fit import check_fit
    from gyrocal.checks.plausibility import Context
    from gyrocal.estimators import make_estimator
    from gyrocal.observations.turn_angle import follow_wander
    from gyrocal.pipeline import _observed
    from gyrocal.results.sections import FitQuality, Observed
    from gyrocal.segmentation.screening import screen_gaps

    tb = rec.time_base()
    screen_gaps(run.segmentation, rec, tb, run.reference, tb.clock_times() if tb.gaps else None)
    estimator = make_estimator("first-moment")  # `fit` is its fit of `windows`, before any check
    if run.reference == "angle":
        follow_wander(rec, rec.t, run.segmentation.windows, run.observations, windows,
                      fit, estimator)
    labels = [w.get("label") or w["kind"] for w in run.calibration.windows]
    ctx = Context(units="rad/s", counts_scale=False, reference=run.reference, declared=run.reference_value,
                  sample_rate=rec.sample_rate, has_time=rec.has_time, sensitivity=None, counted=tb.counted)
    fit, _, quality, _, _ = check_fit(fit, windows, estimator, labels, reference=run.reference, ctx=ctx,
                                      input_scale=1.0)
    FitQuality(quality.to_document())
    Observed(_observed(rec, tb, run.fit.noise_std, 1.0, "rad/s"))


def _alternating(rec, ref: dict, repeat: int) -> dict[str, float]:
    """Best CPU time of each variant over `repeat` rounds; the variants take turns, so load hits all alike."""
    from gyrocal.pipeline import calibrate

    variants = {"plain": {"checks": False, "long_run": False}, "estimate": {"checks": False}, "checked": {}}
    best = dict.fromkeys([*variants, *("naive " + v for v in variants)], math.inf)
    for _ in range(repeat):
        for key, kw in variants.items():
            best[key] = min(best[key], cpu_time(lambda kw=kw: calibrate(rec, **kw, **ref)))
            with naive_selfcheck.installed():
                best["naive " + key] = min(best["naive " + key], cpu_time(lambda kw=kw: calibrate(rec, **kw, **ref)))
    return best

def _pair(rec, ref: dict, repeat: int) -> dict[str, float]:
    """Best CPU time of the calibration without and with the self-checks, taking turns."""
    from gyrocal.pipeline import calibrate

    best = {"estimate": math.inf, "checked": math.inf}
    for _ in range(repeat):
        for key, kw in (("estimate", {"checks": False}), ("checked", {})):
            best[key] = min(best[key], cpu_time(lambda kw=kw: calibrate(rec, **kw, **ref)))
    return best


if __name__ == "__main__":
    main()
