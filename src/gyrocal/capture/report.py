"""What a capture tells the person: the live progress line, the summary, and the device's answer next to the host's."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..io import read_recording
from ..pipeline import CalibrationRun, calibrate
from .agreement import Agreement
from .frames import Turn
from .recorder import Capture, CaptureResult

__all__ = ["calibrate_capture", "calibrate_imu_capture", "device_check", "device_turn_line", "host_versus_device",
           "progress_line", "summary"]


def _rate(store) -> float | None:
    """Samples per second of device time over the last 2 s (None without time stamps)."""
    if not store.has_time or len(store) < 2:
        return None
    t = store.t[-4000:]
    recent = t[t >= t[-1] - 2.0]
    return (len(recent) - 1) / (recent[-1] - recent[0]) if len(recent) > 1 and recent[-1] > recent[0] else None


def progress_line(cap: Capture, unit: str) -> str:
    """``12.3 s  2,460 samples  200.0 Hz  gx -3 gy 5 gz 130 [counts]  lost 0  crc 0``."""
    store, st = cap.result.store, cap.link_stats()
    n = len(store)
    if not n:
        return "waiting for data"
    parts = [f"{store.t[-1]:.1f} s" if store.has_time else "", f"{n:,} samples"]
    fs = _rate(store)
    if fs:
        parts.append(f"{fs:.1f} Hz")
    last = store.gyro[-min(n, 20):].mean(axis=0)
    parts.append("  ".join(f"g{a} {v:.5g}" for a, v in zip("xyz", last)) + f" [{unit}]")
    parts += [f"{k} {v:,}" for k, v in losses(st).items() if v]
    return "  ".join(p for p in parts if p)


def losses(stats) -> dict[str, int]:
    """What was lost on the link, by kind (zero entries included)."""
    if stats is None:
        return {}
    if hasattr(stats, "crc_errors"):
        return {"lost samples": stats.lost_samples, "gaps": stats.gaps, "CRC errors": stats.crc_errors,
                "bytes skipped": stats.skipped}
    return {"bad lines": stats.bad_lines, "lines before a header": stats.before_header}


def summary(result: CaptureResult) -> list[str]:
    """The lines printed when a capture ends."""
    store = result.store
    n = len(store)
    span = f", {store.t[-1]:.2f} s" if store.has_time and n else ""
    fs = (n - 1) / store.t[-1] if store.has_time and n > 1 and store.t[-1] > 0 else None
    lines = [f"capture ended ({result.ended}): {n:,} samples{span}" + (f" at {fs:.2f} Hz" if fs else "")
             + (f", wrote {result.path}" if result.path else "")]
    lost = {k: v for k, v in losses(result.stats).items() if v}
    if store.out_of_order:
        lost["samples out of time order (left out)"] = store.out_of_order
    if store.missing_accel:
        lost["samples without the accelerometer (left out)"] = store.missing_accel
    if result.sent is not None:  # the device's end frame says how many it sent: losses before the first or
        gaps = getattr(result.stats, "lost_samples", 0)  # after the last sample received show only here
        unseen = result.sent - (n + store.out_of_order + store.missing_accel + gaps)
        if unseen > 0:
            lost[f"of the {result.sent:,} samples the device sent, missing at the start or end"] = unseen
    lines.append("link: " + (", ".join(f"{v:,} {k}" for k, v in lost.items()) if lost else "nothing lost")
                 + (f"; {len(result.stalls)} stall(s), longest {max(result.stalls):.1f} s" if result.stalls else ""))
    return lines


def device_turn_line(t: Turn) -> str:
    state = "accepted" if t.reason is None else f"ignored ({t.reason})"
    return f"device: turn {t.label} {state}: {t.angle:.1f} deg, samples {t.start}:{t.stop}, rate {t.rate:.4g} deg/s"


def device_check(result: CaptureResult) -> Agreement | None:
    """Recompute the device's last successful result on the host (None when it sent none)."""
    return result.device.check()


def calibrate_capture(path: Path, *, units: str, sensitivity: float | None, sample_rate: float | None = None,
                      windows=None, speed: float | None = None) -> CalibrationRun:
    """Calibrate the written recording as ``gyrocal calibrate`` would read it (windows from the guide, if any)."""
    rec = read_recording(path, units=units, sensitivity=sensitivity, sample_rate=sample_rate)
    ref = {"speed": speed} if speed is not None else {"angle": 2 * math.pi}
    return calibrate(rec, windows=windows, output_units="deg/s" if units == "counts" else None, **ref)


def calibrate_imu_capture(path: Path, *, units: str, sensitivity: float | None, accel_units: str,
                          accel_sensitivity: float | None, sample_rate: float | None = None, windows=None):
    """Calibrate gyro and accelerometer from the written recording, as ``gyrocal imu`` would read it (the guide's
    poses, if any); an :class:`~gyrocal.imu.run.ImuRun`."""
    from ..imu.run import calibrate_recording

    rec = read_recording(path, units=units, sensitivity=sensitivity, sample_rate=sample_rate, accel_units=accel_units,
                         accel_sensitivity=accel_sensitivity, need_accel=True)
    return calibrate_recording(rec, windows=windows)


def host_versus_device(run: CalibrationRun, agreement: Agreement, sensitivity: float) -> list[str]:
    """The device's k, b next to the host's own calibration (its windows), in the host's units with its 1-sigma."""
    cal = run.calibration
    k_dev = agreement.device_k * sensitivity  # [deg/s per count] x [counts per deg/s]
    b_dev = np.radians(agreement.device_b / sensitivity)
    p = cal.model.params
    sd = np.sqrt(np.diag(cal.covariance)) if cal.covariance is not None else np.full(6, np.nan)
    lines = [("device against the host's own calibration of the same recording (servo method of Wang et al., "
             "first-moment estimator; b in deg/s):"),
             f"{'':<4}{'device':>13}{'host':>13}{'1-sigma':>10}{'diff/sigma':>12}"]
    scale = np.r_[np.ones(3), np.full(3, 180 / math.pi)]
    for i, (name, dev) in enumerate(zip(["kx", "ky", "kz", "bx", "by", "bz"], np.r_[k_dev, b_dev])):
        z = (dev - p[i]) / sd[i] if sd[i] > 0 else math.nan
        lines.append(f"{name:<4} {dev * scale[i]:>12.6g} {p[i] * scale[i]:>12.6g} {sd[i] * scale[i]:>9.2g} {z:>11.2f}")
    return lines
