"""``gyrocal capture``: record a live stream from a device, optionally guided, and check the device's answer."""

from __future__ import annotations

import math
import queue
import sys
import threading
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated

import typer

from ..choices import AccelUnit, CaptureWire, GuideName, InputUnit
from ..errors import GyrocalError, InputError
from ._capture_progress import Progress as _Progress
from ._capture_progress import Stop as _Stop
from ._capture_progress import say as _say
from ._options import in_unit
from ._outputs import check_output
from ._station import StationFlags, station_flags
from .app import app, console, warn


def _keys(commands: queue.Queue) -> None:
    """Read the person's commands from stdin: 'r' redoes the last step, 'q' stops."""
    for line in sys.stdin:
        commands.put(line.strip().lower()[:1])


class _Guided:
    """Runs the guide on the samples as they arrive and prints what it says."""

    def __init__(self, name: str, speed_rad, reading, progress: _Progress, stop: _Stop, *, poses: int, hold: float):
        if name == "multi-position":
            from ..capture.pose_guide import PoseGuide

            self.guide = PoseGuide(poses=poses, hold=hold)
        else:
            from ..capture.guide import Guide

            self.guide = Guide(name, speed=speed_rad)
        self.units, self.sensitivity, self.sample_rate = reading.units, reading.sensitivity, reading.sample_rate
        self.accel_sensitivity = reading.accel_sensitivity
        self.progress, self.stop = progress, stop
        self.commands: queue.Queue = queue.Queue()
        self.started = False
        self._judged = -1.0  # data time [s] (or samples, without stamps) of the last look
        threading.Thread(target=_keys, args=(self.commands,), daemon=True).start()

    def keep_from(self) -> int:
        return self.guide.keep_from

    def _due(self, store) -> bool:
        """Whether a quarter second of data came since the last look (the guide judges at fixed points of
        the data, so looking less often changes nothing but the cost)."""
        now = float(store.t[-1]) if store.has_time else len(store) / (self.sample_rate or 1.0)
        if now - self._judged < 0.25:
            return False
        self._judged = now
        return True

    def _events(self, events) -> None:
        for e in events:
            mark = {"accepted": "ok: ", "refused": "NO: ", "redo": "redo: "}.get(e.kind, "")
            _say(self.progress, f"guide: {mark}{e.text}")

    def __call__(self, cap, force: bool = False) -> bool:
        if not self.started:
            self.started = True
            _say(self.progress, "guide: type r + Enter to redo the last step, q + Enter to stop")
            self._events(self.guide.start())
        store, hello = cap.result.store, cap.result.hello
        sens = self.sensitivity or (hello.sensitivity if hello else None)
        while not self.commands.empty():
            key = self.commands.get()
            if key == "r":
                self._events(self.guide.redo(len(store)))
            elif key == "q":
                self.stop.requested = True
        if len(store) < 2 or not (self._due(store) or force):
            return False
        if self.guide.name != "multi-position" and self.units == "counts" and sens is None:
            raise InputError("the guide needs the sensitivity to check the turns' angles (the device's hello frame "
                             "carries it)", param="sensitivity", hint="for text lines in counts give {param} LSB")
        self.sensitivity = sens
        accel = self.accel_sensitivity or (hello.accel_sensitivity if hello else None)
        start = max(self.guide.keep_from, store.first)
        if len(store) - start < 2:  # just after a redo: nothing new to judge yet
            return False
        rec = store.recording(self.units, sens, self.sample_rate, start=start, accel_sensitivity=accel)
        self._events(self.guide.update(rec, offset=start))
        return self.guide.complete


def _on_event(progress: _Progress, unit: str):
    from ..capture.report import device_turn_line, progress_line

    def handle(kind: str, payload) -> None:
        if kind == "open":
            _say(progress, f"listening on {payload}; Ctrl-C ends the capture and keeps everything received")
        elif kind == "progress":
            progress.show(progress_line(payload, unit))
        elif kind == "hello":
            _say(progress, f"device: {payload.firmware or '?'}, {payload.sample_rate:g} Hz, sensitivity "
                           f"{payload.sensitivity:g} counts per {payload.rate_unit}")
        elif kind == "wire":
            _say(progress, f"receiving {payload}")
        elif kind == "turn":
            _say(progress, device_turn_line(payload))
        elif kind == "result":
            _say(progress, f"device: calibration {payload.status_name}" + (
                "" if payload.status else f": k {', '.join(f'{v:.6g}' for v in payload.k)} [deg/s per count], "
                f"b {', '.join(f'{v:.5g}' for v in payload.b)} [counts]"))
        elif kind == "message":
            _say(progress, f"device: {payload}")
        elif kind == "stall":
            progress.clear()
            warn(f"no data for {payload:.1f} s (the device stalled, or the cable?); still listening")
        elif kind == "resumed":
            _say(progress, f"data again after {payload:.1f} s")

    return handle


@app.command()
@station_flags
def capture(
    port: Annotated[str, typer.Option("--port", help="Serial port: /dev/ttyACM0, COM3, a pseudo-terminal, "
                                      "socket://HOST:PORT (anything pyserial opens).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Recording to write (CSV: t, gx, gy, gz[, temp]).")],
    baud: Annotated[int, typer.Option("--baud", help="Baud rate [bit/s].")] = 115200,
    wire: Annotated[CaptureWire, typer.Option("--wire", help="Wire format: auto, frames (gyrocal frames) or text "
                                      "(lines such as t,gx,gy,gz).")] = "auto",
    columns: Annotated[str | None, typer.Option("--columns", help="Text lines without a header: column "
                                                   "numbers from 1, e.g. t=1,gx=2,gy=3,gz=4 (default: the header's names).")] = None,
    units: Annotated[InputUnit, typer.Option("--units", help="Unit of the rates received: counts, deg/s or rad/s "
                                       "(frames always send counts).")] = "counts",
    sensitivity: Annotated[float | None, typer.Option("--sensitivity", help="For --units counts: LSB per deg/s "
                                                      "(frames: the device says) (default: none; counts are kept).")]
    = None,
    sample_rate: Annotated[float | None, typer.Option("--sample-rate", help="[Hz], for text lines without "
                                                         "a time column (default: from the time column).")] = None,
    duration: Annotated[float | None, typer.Option("--duration", help="Stop after S seconds of data (default: no limit).")] = None,
    samples: Annotated[int | None, typer.Option("--samples", help="Stop after N samples (default: no limit).")] = None,
    silence: Annotated[float | None, typer.Option("--silence", help="Stop after S seconds without a "
                                                     "byte (default: no limit).")] = None,
    guide: Annotated[GuideName | None, typer.Option("--guide", help="Guided session: servo (the six turns of the "
                                                 "servo method of Wang et al.), hand, or multi-position (the whole "
                                                 "IMU from still poses; needs the accelerometer) (default: none, "
                                                 "plain recording).")] = None,
    speed: Annotated[str | None, typer.Option("--speed", help="servo: known turn speed, deg/s unless a unit is "
                                                 "written, e.g. 1.05rad/s (default: none, whole 360 deg turns at "
                                                 "any speed).")] = None,
    poses: Annotated[int, typer.Option("--poses", help="multi-position: poses needed (more if they do not yet "
                                                       "cover the sphere).")] = 12,
    hold: Annotated[float, typer.Option("--hold", help="multi-position: still time asked for in each pose [s].")]
    = 2.0,
    accel_units: Annotated[AccelUnit, typer.Option("--accel-units", help="Unit of text lines' ax, ay, az (frames "
                                                   "send counts).")] = "counts",
    accel_sensitivity: Annotated[float | None, typer.Option("--accel-sensitivity", help="For --accel-units counts: "
                                                            "LSB per g (frames: the device says) (default: none).")] = None,
    calibration: Annotated[Path | None, typer.Option("--cal", help="Calibration file to write when the "
                                                        "guide completes (default: beside -o, .cal.json).")] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace existing output files.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", help="No progress line.")] = False,
    next_unit: Annotated[bool, typer.Option("--next", help="After each unit, ask for the next serial (typed, or "
        "from a barcode scanner) and capture again, until an empty line or Ctrl-C; -o and --cal take {serial}.",
        rich_help_panel="Production station")] = False,
    write_back: Annotated[bool, typer.Option("--write-back", help="After a pass (or without --limits), send the "
        "calibration to the device (gyrocal frames) and check what it reads back from its storage; a failed unit is "
        "never written (default: off).", rich_help_panel="Production station")] = False,
    write_back_timeout: Annotated[float, typer.Option("--write-back-timeout", help="Longest wait for the device's "
        "answer to --write-back [s].", rich_help_panel="Production station")] = 5.0,
    flags: StationFlags = StationFlags(),
) -> None:
    """Record a live stream from a serial port; with --guide, walk through a calibration and calibrate."""
    if columns:
        from ..io.columns import parse_columns

        columns = parse_columns(columns)
    if next_unit and (guide is None or flags.unit is None or "{serial}" not in str(output)):
        raise InputError("--next captures unit after unit: give --guide, the first --unit SERIAL, and an -o whose "
                         "name holds {serial} (for example -o 'runs/{serial}.csv')")
    if write_back and (guide not in ("servo", "hand") or not write_back_timeout > 0):
        raise InputError("--write-back sends the gyro correction of a guided servo or hand session: give --guide "
                         "servo (and a --write-back-timeout > 0)")
    speed = in_unit("--speed", speed, "deg/s")
    if speed is not None and not (math.isfinite(speed) and speed > 0):
        raise InputError(f"--speed must be > 0 deg/s, got {speed:g}")
    session = dict(port=port, baud=baud, wire=wire, columns=columns, duration=duration, samples=samples,
                   silence=silence, guide=guide, speed=speed, poses=poses, hold=hold, force=force, quiet=quiet,
                   reading=_ReadAs(units, sensitivity, sample_rate, accel_units, accel_sensitivity),
                   write_back=write_back_timeout if write_back else None)
    failed = False
    while True:
        serial = flags.unit or ""
        named = Path(str(output).replace("{serial}", serial))
        cal = None if calibration is None else Path(str(calibration).replace("{serial}", serial))
        failed |= _one_unit(named, cal, flags, **session) == "fail"
        if not next_unit or (serial := _next_serial()) is None:
            break
        flags = replace(flags, unit=serial)
        flags.check()
    if failed:
        raise typer.Exit(1)


def _next_serial() -> str | None:
    """The next unit's serial from stdin (a barcode scanner types it and Enter); None to stop."""
    console.print("next unit: scan or type its serial (empty line or Ctrl-C ends)", highlight=False)
    try:
        line = sys.stdin.readline()
    except KeyboardInterrupt:
        return None
    return line.strip() or None


def _one_unit(output: Path, calibration: Path | None, flags: StationFlags, *, port, baud, wire, columns, duration,
              samples, silence, guide, speed, poses, hold, force, quiet, reading, write_back) -> str | None:
    """Capture (and with a guide, calibrate, accept and store) one unit; its verdict."""
    from ..capture.recorder import Capture
    from ..io import check_csv_name

    check_output(output, force=force, holds="another file (a recording?)")
    check_csv_name(output)
    cal_path = calibration or (output.with_suffix(".cal.json") if guide else None)
    if guide:
        check_output(cal_path, flag="--cal", inputs=(output,), outputs=(output,), force=force, holds="another file")
    progress = _Progress(quiet)
    speed_rad = None if speed is None else math.radians(speed)
    with _Stop() as stop:
        guided = None if guide is None else _Guided(guide, speed_rad, reading, progress, stop, poses=poses, hold=hold)
        cap = Capture(port, output, baud=baud, wire=wire, columns=columns, duration=duration, samples=samples,
                      silence=silence, on_event=_on_event(progress, reading.units))
        result = cap.run(stop=stop, each=guided, keep_from=None if guided is None else guided.keep_from,
                         keep_open=write_back is not None)
        if guided is not None and not guided.guide.complete:
            guided(cap, force=True)  # the last samples, read after the last look
    progress.clear()
    try:
        from ._write_back import WriteBack

        send = None if write_back is None else WriteBack(cap.link, result.wire, write_back, result.hello)
        return _finish(result, port, reading, guided, cal_path, speed_rad, flags, send)
    finally:
        cap.close()


@dataclass(frozen=True)
class _ReadAs:
    """How the samples received are to be read: the flags, before the device's hello fills in its part."""

    units: str
    sensitivity: float | None
    sample_rate: float | None
    accel_units: str
    accel_sensitivity: float | None

    def completed(self, hello) -> _ReadAs:
        """With the sensitivities the device's hello frame gives, where no flag gave them."""
        if hello is None:
            return self
        return replace(self, sensitivity=self.sensitivity or hello.sensitivity,
                       accel_sensitivity=self.accel_sensitivity or hello.accel_sensitivity)


def _finish(result, port, reading: _ReadAs, guided, cal_path, speed_rad, flags: StationFlags, send) -> str | None:
    from ..capture.report import calibrate_capture, summary

    if result.path is None:
        raise InputError(f"no samples received from {port}: check the baud rate (--baud), the wire format (--wire) "
                         "and, for text lines, the header or --columns")
    for line in summary(result):
        console.print(line, highlight=False, soft_wrap=True, markup=False)
    reading = reading.completed(result.hello)
    units, sens, sample_rate = reading.units, reading.sensitivity, reading.sample_rate
    calibrate_args = {"units": units, "sensitivity": sens, "sample_rate": sample_rate}
    doc = verdict = None
    if guided is not None and guided.guide.complete and guided.guide.name == "multi-position":
        doc, verdict = _calibrate_imu(result.path, reading, guided.guide.windows(), cal_path, flags)
    elif guided is not None and guided.guide.complete:
        run = calibrate_capture(result.path, windows=guided.guide.windows(), speed=speed_rad, **calibrate_args)
        doc, verdict = _station_result(run.calibration, cal_path, flags, result.path, "calibration", send)
        console.print(run.report(), highlight=False, soft_wrap=True, markup=False)
        console.print(f"wrote {cal_path}", highlight=False, markup=False)
    elif guided is not None:
        warn(f"the guided session stopped at {guided.guide.status()}; no calibration written (the recording is "
             "complete)")
    else:
        how = f"--units {units}" + (f" --sensitivity {sens:g}" if units == "counts" and sens else "")
        how += "" if result.store.has_time else f" --sample-rate {sample_rate:g}" if sample_rate else " --sample-rate HZ"
        console.print(f"next: gyrocal calibrate {result.path} {how} --angle 360 -o cal.json", highlight=False,
                      soft_wrap=True, markup=False)
    _device_answer(result, calibrate_args, speed_rad)
    if doc is not None and (flags.unit is not None or verdict is not None):
        from ._station import print_verdict

        print_verdict(console, doc)
    return verdict


def _station_result(cal, cal_path: Path, flags: StationFlags, recording: Path, kind: str,
                    send=None) -> tuple[dict, str | None]:
    """The calibration file with the unit and its acceptance (and with `send`, written back to the device after a
    pass), written and stored; the document and verdict. A failed write-back is refused once both are written."""
    from ._station import finish, write_and_store

    doc, verdict = finish(cal.to_document(), flags, inputs=(recording,))
    refusal = None
    if send is not None and verdict in (None, "pass"):
        doc, refusal = send(cal, doc)
    record = write_and_store(doc, flags, cal_path, verdict, inputs=(recording,), kind=kind, job="capture")
    if record is not None:
        console.print(f"stored as record {record} in {flags.store}", highlight=False)
    if refusal is not None:
        raise refusal
    return doc, verdict


def _calibrate_imu(path, reading: _ReadAs, windows, cal_path, flags: StationFlags) -> tuple[dict, str | None]:
    """The whole-IMU calibration of a guided multi-position session, from the written recording."""
    from ..capture.report import calibrate_imu_capture
    from ._imu_report import print_imu_run

    run = calibrate_imu_capture(path, units=reading.units, sensitivity=reading.sensitivity,
                                sample_rate=reading.sample_rate, accel_units=reading.accel_units,
                                accel_sensitivity=reading.accel_sensitivity, windows=windows)
    doc, verdict = _station_result(run.calibration, cal_path, flags, path, "imu")
    print_imu_run(run, windows_from="the guide")
    for line in run.warnings:
        warn(line)
    console.print(f"wrote {cal_path}", highlight=False, markup=False)
    return doc, verdict


def _device_answer(result, calibrate_args: dict, speed_rad) -> None:
    """The device's own calibration, recomputed on the host and set beside the host's calibration."""
    from ..capture.report import calibrate_capture, device_check, host_versus_device

    agreement = device_check(result)
    if agreement is None:
        return
    console.print(agreement.report(), highlight=False, soft_wrap=True, markup=False)
    if not agreement.agrees:
        warn("the device's calibration differs from the host's recomputation beyond float32 rounding: "
             "the firmware does not compute what the gyrocal C library computes on these samples")
    sens = calibrate_args["sensitivity"]
    if sens is not None and calibrate_args["units"] == "counts":
        try:
            run = calibrate_capture(result.path, speed=speed_rad, **calibrate_args)
        except GyrocalError as exc:  # the host's own segmentation found too little: say so, the recording stands
            warn(f"the host could not calibrate the recording itself: {exc}")
            return
        for line in host_versus_device(run, agreement, sens):
            console.print(line, highlight=False, soft_wrap=True, markup=False)
