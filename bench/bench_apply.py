"""Apply a thermal table to a paper-size turntable session, against pyarrow reading and writing the same table.

Run by hand:  python bench/bench_apply.py [--step 60] [--repeat 2] [--keep DIR]

The session is the full-temperature-range method's protocol (10 temperatures x 3 positions x 21 rates,
`--step` seconds per rate at 200 Hz: 7.56 M rows at the paper's 60 s), written with a text ``axis``
column as ``gyrocal simulate --protocol turntable`` writes it. Each stage runs in a fresh process, so
its peak memory (maximum resident set) is its own:

* ``pyarrow``: ``pyarrow.csv.read_csv`` and ``write_csv`` of the same file: the floor;
* ``apply``: what ``gyrocal apply thermal.json session.csv -o out.csv`` does (read, compensate, write);
* ``apply (previous)``: the same with the previous implementation kept below: the whole session's
  per-sample tables at once and a CSV writer that formats every float with ``repr``;
* ``simulate`` / ``simulate (previous)``: the session simulated and written, new writer against previous.

Prints seconds and peak MiB per stage, the memory above what the imports alone take as a multiple of
the numeric data (rows x 6 float64 columns), apply / pyarrow, and previous / new. The previous stages
share the current reader; bench/bench_read.py measures the reader.
"""

from __future__ import annotations

import argparse
import csv
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

FS = 200.0


def _peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def previous_write_csv(path, columns: dict, header_comment: str) -> None:
    """The writer before streaming: every cell through repr() or str(), the whole table at once."""
    arrays = {k: np.asarray(v) for k, v in columns.items()}

    def text(a):
        return [repr(float(x)) for x in a] if a.dtype.kind == "f" else [str(x) for x in a.tolist()]

    with open(path, "w", encoding="utf-8", newline="") as f:
        f.write(f"# {header_comment}\n")
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(list(arrays))
        writer.writerows(zip(*(text(a) for a in arrays.values())))


def previous_compensate(cal, gyro, temp):
    """The compensation before chunking: Kg, K and B for every sample of the session at once."""
    from gyrocal.models import kg_to_kb

    K, B = kg_to_kb(cal.kg_at(temp, "lagrange", "refuse"))
    return np.linalg.solve(K, (gyro - B)[..., None])[..., 0]


def _session(step: float):
    from gyrocal.simulation.thermal_truth import ThermalTruth
    from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable

    truth = ThermalTruth()
    rng = np.random.default_rng(7)
    return simulate_turntable(truth.gyro(np.radians(0.05)), TurntableProtocol(step_duration=step),
                              sample_rate=FS, rng=rng)


def stage(name: str, work: Path, step: float) -> dict:
    t0 = time.perf_counter()
    session, out = work / "session.csv", work / f"out-{name.replace(' ', '_')}.csv"
    if name == "imports":  # what every stage loads before it reads a byte: the fixed part of its memory
        import pyarrow.csv  # noqa: F401

        import gyrocal.io  # noqa: F401
        import gyrocal.results.files  # noqa: F401
        import gyrocal.thermal  # noqa: F401
    elif name == "pyarrow":
        import pyarrow.csv as pcsv

        table = pcsv.read_csv(session, read_options=pcsv.ReadOptions(skip_rows=1))
        pcsv.write_csv(table, out)
    elif name.startswith("apply"):
        from gyrocal.io import read_recording, recording_columns, write_recording
        from gyrocal.results.files import load

        cal = load(work / "thermal.json")
        rec = read_recording(session, units="deg/s", saturation="ignore")
        if name == "apply":
            write_recording(out, cal.apply(rec), header_comment="corrected by gyrocal")
        else:
            from gyrocal.thermal import smooth_temperature

            temp = smooth_temperature(rec.temp, rec.sample_rate, cal.temp_tau)
            cols = recording_columns(rec)
            g = previous_compensate(cal, rec.gyro, temp) / np.radians(1.0)
            cols.update(gx=g[:, 0], gy=g[:, 1], gz=g[:, 2])
            previous_write_csv(out, cols, "corrected by gyrocal")
    elif name.startswith("simulate"):
        from gyrocal.io import recording_columns, write_recording

        rec = _session(step)
        if name == "simulate":
            write_recording(out, rec, units="deg/s", header_comment="gyrocal simulate --protocol turntable")
        else:
            previous_write_csv(out, recording_columns(rec, "deg/s"), "gyrocal simulate --protocol turntable")
    else:
        raise SystemExit(f"unknown stage {name!r}")
    return {"seconds": time.perf_counter() - t0, "peak_mib": _peak_mib()}


def _prepare(work: Path, step: float) -> int:
    from gyrocal.io import write_recording
    from gyrocal.results.files import save
    from gyrocal.simulation.thermal_truth import ThermalTruth
    from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable
    from gyrocal.thermal import calibrate_thermal

    rec = _session(step)
    write_recording(work / "session.csv", rec, units="deg/s", header_comment="gyrocal simulate --protocol turntable")
    small = simulate_turntable(ThermalTruth().gyro(np.radians(0.05)), TurntableProtocol(step_duration=3.0),
                               sample_rate=50.0, rng=np.random.default_rng(8))
    cal, _ = calibrate_thermal([small], settle=1.0, input_units="deg/s", output_units="deg/s")
    save(cal, work / "thermal.json")
    return len(rec)


def _run(name: str, work: Path, step: float) -> dict:
    out = subprocess.run([sys.executable, __file__, "--stage", name, "--keep", str(work), "--step", str(step)],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--step", type=float, default=60.0, help="seconds per rate step (60: the paper's)")
    parser.add_argument("--keep", type=Path, help="work folder to keep (default: a temporary one)")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each stage, in turn; the best is shown")
    parser.add_argument("--stage", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.stage == "prepare":
        print(json.dumps({"rows": _prepare(args.keep, args.step)}))
        return
    if args.stage:
        print(json.dumps(stage(args.stage, args.keep, args.step)))
        return
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        # every stage, the session's preparation included, runs in a process of its own: a child forked from
        # a parent holding the session would inherit its resident memory in the peak it reports
        rows = _run("prepare", work, args.step)["rows"]
        numeric_mib = rows * 6 * 8 / 2**20
        print(f"session: {rows:,} rows ({(work / 'session.csv').stat().st_size / 2**20:.0f} MiB of CSV, "
              f"{numeric_mib:.0f} MiB of numbers)")
        results: dict = {}
        names = ("imports", "pyarrow", "apply", "apply (previous)", "simulate", "simulate (previous)")
        for _ in range(args.repeat):  # stages take turns, so a busy machine slows them alike
            for name in names:
                r = _run(name, work, args.step)
                best = results.get(name)
                results[name] = r if best is None else {k: min(best[k], r[k]) for k in r}
        for name in names:
            r = results[name]
            grown = r["peak_mib"] - results["imports"]["peak_mib"]
            print(f"{name:>20}: {r['seconds']:7.2f} s  peak {r['peak_mib']:7.0f} MiB, {grown:6.0f} MiB above the "
                  f"imports ({grown / numeric_mib:.2f}x the numbers)")
        a, p = results["apply"], results["pyarrow"]
        print(f"apply / pyarrow read+write: {a['seconds'] / p['seconds']:.2f}x time, "
              f"{a['peak_mib'] / p['peak_mib']:.2f}x memory")
        for new in ("apply", "simulate"):
            old = results[f"{new} (previous)"]
            print(f"{new}: previous / new {old['seconds'] / results[new]['seconds']:.2f}x time, "
                  f"{old['peak_mib'] / results[new]['peak_mib']:.2f}x memory")


if __name__ == "__main__":
    main()
