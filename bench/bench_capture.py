"""Sustained capture rate without loss at 115200 and 921600 baud (run by hand).

For each baud rate and wire format (gyrocal frames, 6-axis frames with the accelerometer, text lines):
the byte budget (baud / 10 for 8N1) over the bytes per sample
gives the highest possible sample rate; a virtual device in another process then sends a session
at 95 % of that budget through a pseudo-terminal, paced at baud / 10 bytes per second, and
``gyrocal.capture.Capture`` records it. The run passes when every sample arrives (no sequence gap,
no CRC error, no bad line). It prints the capture's CPU time against the link time, and, as the
naive baseline in the same process, the decoder alone against a plain ``struct.unpack`` loop.

    .venv/bin/python bench/bench_capture.py [--seconds 15]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import multiprocessing as mp
import tempfile
import time
from pathlib import Path

import numpy as np

from gyrocal.capture import frames as fr
from gyrocal.capture.device import VirtualDevice, device_bytes
from gyrocal.capture.recorder import Capture
from gyrocal.capture.simulated import simulate_device_session
from gyrocal.models import ScaleBias
from gyrocal.simulation import ServoProtocol


def session(rate: float, seconds: float, accel: bool = False):
    turns = max(1, int(seconds // 9))
    proto = ServoProtocol(turns=("+x", "-x", "+y", "-y", "+z", "-z")[:turns], lead_in=1.0, lead_out=1.0)
    model = ScaleBias(k=np.array([1.02, 0.98, 1.01]), b=np.radians([1.5, -2.0, 0.8]))
    rng = np.random.default_rng(1)
    s = simulate_device_session(proto, model=model, noise_std=0.01, rng=rng, sample_rate=rate)
    if not accel:
        return s
    a = np.round(rng.normal([0.0, 0.0, 16384.0], 65.0, (len(s), 3))).astype(np.int16)  # flat, MPU-6050 noise
    return dataclasses.replace(s, accel=a, accel_sensitivity=16384)


def serve(data: bytes, byte_rate: float, conn) -> None:
    with VirtualDevice(data, byte_rate=byte_rate) as dev:
        conn.send(dev.start())
        conn.recv()  # the capture has the port open
        dev.release()
        dev.wait(600)


def run(baud: int, wire: str, seconds: float) -> dict:
    per_sample = {"frames": fr.OVERHEAD + fr.Sample.FORMAT.size, "6-axis": fr.OVERHEAD + fr.ImuSample.FORMAT.size}
    probe = session(200.0, 9)
    if wire == "text":
        per_sample["text"] = len(device_bytes(probe, "text")) / len(probe)
    budget = baud / 10 / per_sample[wire]
    rate = math.floor(0.95 * budget)
    s = session(rate, seconds, accel=wire == "6-axis")
    data = device_bytes(s, "text" if wire == "text" else "frames", encoder="python")
    parent, child = mp.Pipe()
    proc = mp.Process(target=serve, args=(data, baud / 10, child))
    proc.start()
    port = parent.recv()
    with tempfile.TemporaryDirectory() as tmp:
        cap = Capture(port, Path(tmp) / "rec.csv", wire="text" if wire == "text" else "frames", silence=30,
                      on_event=lambda kind, _: parent.send("go") if kind == "open" else None)
        wall, cpu = time.monotonic(), time.process_time()
        result = cap.run()
        wall, cpu = time.monotonic() - wall, time.process_time() - cpu
    proc.join(60)
    st = result.stats
    lost = st.bad_lines if wire == "text" else st.lost_samples + st.crc_errors + len(s) - result.samples
    return {"baud": baud, "wire": wire, "bytes_per_sample": per_sample[wire], "budget_hz": budget, "rate_hz": rate,
            "sent": len(s), "received": result.samples, "lost": lost, "wall_s": wall, "cpu_s": cpu}


def decoder_against_struct(n: int = 200_000) -> tuple[float, float]:
    """Samples per second: the frame decoder (CRC, resync) against a bare struct loop without checks."""
    raw = np.zeros((n, 3), int)
    data = fr.encode_samples(np.arange(n), 5000 * np.arange(n), raw)
    t = time.perf_counter()
    fr.FrameDecoder().feed(data)
    dec = n / (time.perf_counter() - t)
    size, unpack = fr.OVERHEAD + fr.Sample.FORMAT.size, fr.Sample.FORMAT.unpack_from
    t = time.perf_counter()
    [unpack(data, i * size + 4) for i in range(n)]
    naive = n / (time.perf_counter() - t)
    return dec, naive


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=15.0)
    args = ap.parse_args()
    print(f"{'baud':>7} {'wire':>6} {'B/sample':>9} {'budget Hz':>10} {'sent Hz':>8} {'sent':>7} {'received':>9} "
          f"{'lost':>5} {'link s':>7} {'capture CPU':>12}")
    for baud in (115200, 921600):
        for wire in ("frames", "6-axis", "text"):
            r = run(baud, wire, args.seconds)
            print(f"{r['baud']:>7} {r['wire']:>6} {r['bytes_per_sample']:>9.1f} {r['budget_hz']:>10.0f} "
                  f"{r['rate_hz']:>8} {r['sent']:>7} {r['received']:>9} {r['lost']:>5} {r['wall_s']:>7.1f} "
                  f"{100 * r['cpu_s'] / r['wall_s']:>11.0f}%")
    dec, naive = decoder_against_struct()
    print(f"decoder alone: {dec:,.0f} samples/s with CRC and resync; bare struct loop {naive:,.0f}/s "
          f"(ratio {dec / naive:.2f})")


if __name__ == "__main__":
    main()
