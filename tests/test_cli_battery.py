"""A battery of what users really do wrong or oddly, for every command (issue 11's hidden battery, played).

Each case runs the real command line in-process (:mod:`cli_runner`, through the real error boundary), in an
empty working folder, and checks the contract of README's command reference against the case's expected
exit code:

* exit 2 for bad input with exactly one line on stderr, ``error: ...``, that names what is wrong (the
  case's pattern) and the flags to fix it: never a Python parameter name (``sample_rate``, ``units='x'``),
  never a traceback or a Python/numpy warning;
* exit 0 (or 1 for ``compare --tolerance``) where the input is odd but fine;
* a refused run leaves no file behind, and no case changes an input (checked at the end).

The fixtures are small simulated sessions (``gyrocal simulate``) and files written to be broken; the
independent reference of each case is the documented behaviour it names. A few subprocess runs check what
only a real process shows: a closed pipe, a narrow terminal, Ctrl-C.
"""

from __future__ import annotations

import gzip
import hashlib
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from cli_runner import invoke

from gyrocal.cli._flags import FLAGS

ULOG = Path(__file__).parent / "data" / "px4_ulog" / "sample_log_small.ulg"
V1_CAL = Path(__file__).parent / "data" / "v1_calibration.json"
V1_THERMAL = Path(__file__).parent / "data" / "v1_thermal.json"


def _ok(*args) -> None:
    code, out, err = invoke(*args)
    assert code == 0, (args, out, err)


@pytest.fixture(scope="module")
def fx(tmp_path_factory) -> Path:
    """Every kind of file the commands take, made by the commands themselves, and broken ones beside them."""
    d = tmp_path_factory.mktemp("battery")
    _ok("simulate", "-o", d / "rec.csv", "--sample-rate", "100", "--reference", d / "ref.csv", "--ref-offset", "0.5")
    _ok("calibrate", d / "rec.csv", "--units", "deg/s", "--speed", "60", "-o", d / "cal.json")
    _ok("simulate", "-o", d / "rec2.csv", "--sample-rate", "100", "--seed", "5")
    _ok("calibrate", d / "rec2.csv", "--units", "deg/s", "--speed", "60", "-o", d / "cal2.json")
    _ok("simulate", "-o", d / "static.csv", "--protocol", "static", "--duration", "60", "--sample-rate", "100",
        "--units", "rad/s", "--noise", "0.005", "--accel-noise-density", "0.002")
    _ok("noise", d / "static.csv", "--units", "rad/s", "--accel-units", "m/s^2", "--json", d / "noise.json")
    _ok("simulate", "-o", d / "warm.csv", "--protocol", "static", "--duration", "300", "--sample-rate", "20",
        "--temp-start", "0", "--temp-end", "40", "--warmup-tau", "80", "--bias-tempco", "2e-4,-1e-4,5e-5")
    _ok("thermal-bias", d / "warm.csv", "--units", "deg/s", "-o", d / "bias.json")
    _ok("simulate", "-o", d / "hand.csv", "--protocol", "multi-position", "--poses", "12", "--sample-rate", "100")
    _ok("imu", d / "hand.csv", "--units", "deg/s", "--accel-units", "m/s^2", "-o", d / "imu.json")
    _ok("simulate", "-o", d / "session.csv", "--protocol", "turntable", "--temps", "-20,0,20,40", "--rates",
        "0,100", "--step-duration", "2", "--sample-rate", "20")
    _ok("thermal", d / "session.csv", "--units", "deg/s", "--settle", "0.5", "-o", d / "thermal.json")
    _ok("verify", d / "cal.json", d / "rec.csv", "--reference", d / "ref.csv", "--ref-units", "deg/s",
        "--no-figures", "--replicates", "50", "-o", d / "verify")
    _broken_files(d)
    return d


def _broken_files(d: Path) -> None:
    """Recordings and JSON files as users have them when something went wrong."""
    lines = (d / "rec.csv").read_text().splitlines()
    header, body = lines[1], lines[2:]
    arr = np.loadtxt(d / "rec.csv", delimiter=",", skiprows=2)

    def table(name, a, head="t,gx,gy,gz", fmt="%.9g", sep=","):
        np.savetxt(d / name, a, delimiter=sep, header=head, comments="", fmt=fmt)

    (d / "empty.csv").write_text("")
    (d / "header_only.csv").write_text(header + "\n")
    (d / "binary.csv").write_bytes(bytes(np.random.default_rng(1).integers(0, 256, 4000, dtype=np.uint8)))
    (d / "truncated.csv").write_text("\n".join(lines[:3000]) + "\n" + lines[3000][:7])
    cal = (d / "cal.json").read_text()
    (d / "truncated.json").write_text(cal[: len(cal) // 2])
    (d / "other_tool.json").write_text(json.dumps({"name": "imu0", "T_cam_imu": [[1, 0], [0, 1]]}))
    (d / "list.json").write_text("[1, 2, 3]")
    (d / "cal.json.gz").write_bytes(gzip.compress(cal.encode()))
    (d / "folder.csv").mkdir()
    (d / "folder.json").mkdir()
    (d / "meta.csv").write_text("Fs,100\nDevice,MPU9250\n" + header + "\n" + "\n".join(body) + "\n")
    (d / "rec.csv.gz").write_bytes(gzip.compress((d / "rec.csv").read_bytes()))
    a = arr.copy()
    a[500, 1] = np.nan
    table("nan.csv", a)
    a = arr.copy()
    a[:, 1:] = np.deg2rad(a[:, 1:])
    table("rad.csv", a)  # truly rad/s
    table("huge.csv", np.column_stack([arr[:, 0], arr[:, 1:] * 1e300]))
    table("nogz.csv", arr[:, :3], head="t,gx,gy")
    table("dupcol.csv", np.column_stack([arr, arr[:, 1]]), head="t,gx,gy,gz,gx")
    table("headerless.csv", arr, head="")
    table("zeros.csv", np.column_stack([arr[:, 0], np.zeros((len(arr), 3))]))
    table("notime.csv", arr[:, 1:], head="gx,gy,gz")
    a = arr.copy()
    a[100:, 0] -= 1.0
    table("backwards.csv", a)  # a second part glued on: a break, not an error
    a = arr.copy()
    a[100, 0] = a[99, 0] - 0.002
    table("jitterback.csv", a)  # one stamp back by less than a period: refused
    a = arr.copy()
    a[:, 0] *= 1000
    table("ms.csv", a)
    table("semicolon.csv", arr, head="t;gx;gy;gz", sep=";")
    doc = json.loads(cal)
    for name, change in (("cal_v99.json", lambda x: x.update(version=99)),
                         ("cal_typo.json", lambda x: x.update(format="gyrocal.calbration")),
                         ("cal_units.json", lambda x: x["units"].update(input="furlongs"))):
        x = json.loads(cal)
        change(x)
        (d / name).write_text(json.dumps(x))
    doc["correction"]["matrix"][0][0] = float("nan")
    (d / "cal_nan.json").write_text(json.dumps(doc))
    noise = json.loads((d / "noise.json").read_text())
    noise["gyroscope"]["x"]["density"].update(value=0.0, low=0.0, high=0.0)
    (d / "noise_zero.json").write_text(json.dumps(noise))


#: (command line, expected exit code, what the one error line must say). {name} is a file of the fixture
#: folder; bare names are written in the (empty) working folder of the case.
CASES = [
    # calibrate: arguments and flag values
    ("calibrate", 2, "give a recording"),
    ("calibrate {rec.csv}", 2, "--units is required"),
    ("calibrate {rec.csv} --units", 2, r"--units.*requires an argument.*gyrocal calibrate --help"),
    ("calibrate {rec.csv} --units furlongs", 2, r"--units 'furlongs' is not a known unit"),
    ("calibrate {rec.csv} --units deg/s --speed -60", 2, "--speed must be a positive number"),
    ("calibrate {rec.csv} --units deg/s --speed nan", 2, "--speed must be a positive number"),
    ("calibrate {rec.csv} --units deg/s --angle 0", 2, "--angle must be a positive number"),
    ("calibrate {rec.csv} --units deg/s --speed 60 --angle 360", 2, "not both"),
    ("calibrate {rec.csv} --units deg/s --speed abc", 2, r"--speed must be a number, with a unit if you like"),
    ("calibrate {rec.csv} --units deg/s --sample-rate 0", 2, "--sample-rate must be finite and > 0"),
    ("calibrate {rec.csv} --units deg/s --sample-rate -200", 2, "--sample-rate must be finite and > 0"),
    ("calibrate {notime.csv} --units deg/s --speed 60", 2, r"--sample-rate HZ.*--columns t=NAME"),
    ("calibrate {notime.csv} --units deg/s --speed 60 --sample-rate 100", 0, ""),
    ("calibrate {rec.csv} --units deg/s --sensitivity 131", 2, "--sensitivity applies only to --units counts"),
    ("calibrate {rec.csv} --units deg/s --output-units counts", 2, "--output-units 'counts' is not a known unit"),
    ("calibrate {rec.csv} --units deg/s --noise-std 0", 2, "--noise-std must be a positive number"),
    ("calibrate {rec.csv} --units deg/s --noise-density {noise_zero.json}", 2, "zero noise density"),
    ("calibrate {rec.csv} --units deg/s --noise-density {cal.json}", 2, "expected 'gyrocal.noise'"),
    ("calibrate {rec.csv} --units deg/s --method foo", 2, r"--method: 'foo' is not one of"),
    ("calibrate {rec.csv} --units deg/s --windows {other_tool.json}", 2, "section list"),
    ("calibrate {rec.csv} --units deg/s --columns gx=gyroX", 2, r"column 'gyroX' \(given for gx\)"),
    ("calibrate {rec.csv} --units deg/s --columns gx=9", 2, "a number from 1 to 4"),
    ("calibrate {rec.csv} --units deg/s --columns garbage", 2, "is not NAME=COLUMN"),
    ("calibrate {rec.csv} --units deg/s --columns gx=gy,gy=gy,gz=gz", 2, "given for both gx and gy"),
    ("calibrate {rec.csv} --units deg/s --columns gx=gy,gy=gx,gz=gz --speed 60", 0, ""),
    ("calibrate {rec.csv} --units deg/s --skip-rows -1", 2, "--skip-rows must be a whole number"),
    ("calibrate {rec.csv} --units deg/s --topic /imu", 2, "--topic applies to ROS bags only"),
    ("calibrate {rec.csv} --units deg/s --plot out.txt", 2, r"\.png, \.pdf or \.svg"),
    ("calibrate {rec.csv} --units deg/s --speed 60 --example", 2, "not both"),
    ("calibrate {rec.csv} extra.csv --units deg/s", 2, "unexpected extra argument"),
    ("calibrate {rec.csv} --units deg/s --bogus", 2, "no such option: --bogus"),
    # calibrate: files users have
    ("calibrate /nonexistent.csv --units deg/s", 2, "does not exist"),
    ("calibrate {folder.csv} --units deg/s", 2, "a folder"),
    ("calibrate {empty.csv} --units deg/s", 2, "no header row"),
    ("calibrate {header_only.csv} --units deg/s", 2, "no data rows"),
    ("calibrate {binary.csv} --units deg/s", 2, "binary data, not a text table"),
    ("calibrate {truncated.csv} --units deg/s", 2, "cannot parse the table"),
    ("calibrate {nan.csv} --units deg/s", 2, "NaN, inf or empty cells"),
    ("calibrate {huge.csv} --units deg/s", 2, "beyond any sensor in any unit"),
    ("calibrate {huge.csv} --units deg/s --no-unit-check", 2, "beyond any sensor in any unit"),
    ("calibrate {nogz.csv} --units deg/s", 2, "no column for gz"),
    ("calibrate {dupcol.csv} --units deg/s", 2, "appears 2 times"),
    ("calibrate {headerless.csv} --units deg/s", 2, r"--columns t=1,gx=2,gy=3,gz=4"),
    ("calibrate {headerless.csv} --units deg/s --columns t=1,gx=2,gy=3,gz=4 --speed 60", 0, ""),
    ("calibrate {zeros.csv} --units deg/s", 2, "every reading is the same"),
    ("calibrate {backwards.csv} --units deg/s --speed 60", 0, ""),
    ("calibrate {jitterback.csv} --units deg/s", 2, "time going backwards"),
    ("calibrate {ms.csv} --units deg/s --speed 60", 2, "time_ms"),
    ("calibrate {semicolon.csv} --units deg/s --speed 60", 0, ""),
    ("calibrate {meta.csv} --units deg/s --speed 60", 0, ""),
    ("calibrate {rec.csv.gz} --units deg/s --speed 60", 0, ""),
    ("calibrate {rad.csv} --units deg/s --speed 60", 2, r"are the data in rad/s\? \(--units rad/s\)"),
    ("calibrate {rec.csv} --units rad/s --speed 60", 2, "almost surely in deg/s: use --units deg/s"),
    ("calibrate {rec.csv} --units counts --speed 60", 2, "non-integer readings"),
    ("calibrate {cal.json} --units deg/s", 2, r"holds a gyrocal file \(gyrocal.calibration\), not a recording"),
    ("calibrate {noise.json} --units deg/s", 2, "not a recording"),
    ("calibrate {static.csv} --units rad/s", 2, "still log"),
    # calibrate: outputs
    ("calibrate {rec.csv} --units deg/s --speed 60 -o {rec.csv}", 2, "also an input"),
    ("calibrate {rec.csv} --units deg/s --speed 60 -o {cal2.json}", 2, "pass --force"),
    ("calibrate {rec.csv} --units deg/s --speed 60 -o {rec.csv}/cal.json", 2, "is a file, not a folder"),
    ("calibrate {rec.csv} --units deg/s --speed 60 -o .", 2, "is a folder"),
    ("calibrate {rec.csv} --units deg/s --speed 60 -o same.png --plot same.png", 2, "its own file name"),
    ("calibrate {rec.csv} --units deg/s --speed 60 -o c.json --plot {rec.csv}", 2, "also an input"),
    # segments
    ("segments", 2, "missing argument 'recording'.*gyrocal segments --help"),
    ("segments {rec.csv} --units deg/s --speed -1", 2, "--speed must be a positive number"),
    ("segments {zeros.csv} --units deg/s", 2, "every reading is the same"),
    ("segments {cal.json} --units deg/s", 2, "not a recording"),
    ("segments {rec.csv} --units deg/s --plot {rec.csv}", 2, "also an input"),
    # apply
    ("apply {cal.json}", 2, "missing option '-o'"),
    ("apply {cal.json} {rec.csv}", 2, "missing option '-o'"),
    ("apply {rec.csv} {cal.json} -o out.csv", 2, "arguments look swapped; the calibration file comes first"),
    ("apply {cal.json} {rec.csv} -o out.csv", 0, ""),
    ("apply {cal.json} {cal2.json} -o out.csv", 2, "not a recording"),
    ("apply {noise.json} {rec.csv} -o out.csv", 2, "'gyrocal.noise'; expected 'gyrocal.calibration' or"),
    ("apply {bias.json} {rec.csv} -o out.csv", 2, "'gyrocal.thermal-bias'; expected"),
    ("apply {verify}/verify.json {rec.csv} -o out.csv", 2, "'gyrocal.verify'; expected"),
    ("apply {rec.truth.json} {rec.csv} -o out.csv", 2, "'gyrocal.simulation-truth'; expected"),
    ("apply {other_tool.json} {rec.csv} -o out.csv", 2, "field 'format' is None; gyrocal reads"),
    ("apply {list.json} {rec.csv} -o out.csv", 2, "a JSON object at the top level"),
    ("apply {truncated.json} {rec.csv} -o out.csv", 2, "not valid JSON"),
    ("apply {cal_v99.json} {rec.csv} -o out.csv", 2, "field 'version' is 99"),
    ("apply {cal_typo.json} {rec.csv} -o out.csv", 2, "'gyrocal.calbration'; gyrocal reads"),
    ("apply {cal_nan.json} {rec.csv} -o out.csv", 2, "field 'correction.matrix'"),
    ("apply {cal_units.json} {rec.csv} -o out.csv", 2, "'furlongs' is not a known unit"),
    ("apply {cal.json.gz} {rec.csv} -o out.csv", 2, "not valid JSON"),
    ("apply {folder.json} {rec.csv} -o out.csv", 2, "a folder, not a file"),
    ("apply {cal.json} {rad.csv} -o out.csv", 2, r"look like rad/s.*--units rad/s \(gyrocal converts them\)"),
    ("apply {cal.json} {rad.csv} -o out.csv --units rad/s", 0, ""),
    ("apply {cal.json} {rec.csv} -o out.csv --units counts", 2, "does not match the calibration's input units"),
    ("apply {cal.json} {rec.csv} -o out.csv --model smooth", 2, "--model does not apply"),
    ("apply {cal.json} {rec.csv} -o out.csv --gravity 0", 2, "--gravity must be finite and > 0"),
    ("apply {cal.json} {rec.csv} -o {rec.csv} --force", 2, "also an input"),
    ("apply {cal.json} {rec.csv} -o {cal2.json}", 2, "pass --force"),
    ("apply {cal.json} {rec.csv} -o out.parquet", 2, "give the file a .csv name"),
    ("apply {cal.json} {rec.csv} -o out.csv.gz", 2, "give the file a .csv name"),
    ("apply {imu.json} {hand.csv} -o out.csv --accel-units m/s^2", 0, ""),
    ("apply {imu.json} {hand.csv} -o out.csv --accel-units g", 2, r"reads 9\.\d+ g.*--accel-units m/s\^2"),
    # a gyro-only log: the gyro is corrected (no g-sensitivity needs the accelerometer), unless ax ay az are asked for
    ("apply {imu.json} {rec.csv} -o out.csv", 0, ""),
    ("apply {imu.json} {rec.csv} -o out.csv --accel-units m/s^2", 2, "no accelerometer column"),
    ("apply {thermal.json} {rec.csv} -o out.csv", 2, "needs a temperature for every sample"),
    ("apply {v1_cal} {rec.csv} -o out.csv", 0, ""),
    # export
    ("export {cal.json}", 2, r"missing option '--format'\. Choose from: json, yaml, c-header"),
    ("export {cal.json} --format toml -o x", 2, r"--format: 'toml' is not one of"),
    ("export {cal.json} --format c-header -o x.h --prefix 'my sensor'", 2, "--prefix must be a C identifier"),
    ("export {cal.json} --format json -o x.json --prefix ABC", 2, "--prefix does not apply to json export"),
    ("export {noise.json} --format vins -o x.yaml --prefix ABC", 2, r"it takes --update-rate, --inflate"),
    ("export {cal.json} --format kalibr -o x.yaml", 2, r"kalibr export takes gyrocal\.noise, not gyrocal\.calibration \(gyrocal\.noise is made by 'gyrocal noise LOG --json"),
    ("export {cal.json} --format imucal -o x.json", 2, "no accelerometer part"),
    ("export {imu.json} --format imucal -o x.json", 0, ""),
    ("export {noise.json} --format c-header -o x.h", 2, "c-header export takes"),
    ("export {noise.json} --format kalibr -o x.yaml", 2, r"--gyro-random-walk.*--random-walk-bound"),
    ("export {noise.json} --format kalibr -o x.yaml --random-walk-bound", 0, ""),
    ("export {noise.json} --format kalibr -o x.yaml --random-walk-bound --inflate 0.5", 2, "--inflate must be"),
    ("export {noise.json} --format vins -o x.yaml --random-walk-bound --update-rate -200", 2,
     "--update-rate must be > 0"),
    ("export {noise.json} --format vins -o x.yaml --random-walk-bound --update-rate 0", 2, "--update-rate must"),
    ("export {noise.json} --format kalibr -o x.yaml --gyro-random-walk -1 --accel-random-walk 1e-4", 2,
     "--gyro-random-walk must be > 0"),
    ("export {noise.json} --format kalibr -o x.yaml --random-walk-bound --rostopic 'a b: c'", 2,
     "--rostopic 'a b: c' is not a ROS topic name"),
    ("export {noise_zero.json} --format kalibr -o x.yaml", 2, "density.value' must be a number > 0"),
    ("export {verify}/verify.json --format c-header -o x.h", 2, "c-header export takes"),
    ("export {bias.json} --format px4 -o x.params", 2, "--device-id"),
    ("export {bias.json} --format px4 -o x.params --device-id -5", 2, "--device-id -5 is not a PX4 device id"),
    ("export {bias.json} --format px4 -o x.params --device-id 1 --slot 7", 2, "TC_G0..TC_G3"),
    ("export {bias.json} --format ardupilot -o x.parm --slot 0", 2, "INS_TCAL1..INS_TCAL3"),
    ("export {bias.json} --format ardupilot -o x.parm --caltemp nan", 2, "--caltemp must be finite"),
    ("export {bias.json} --format ardupilot -o x.parm --caltemp -300", 2, "-273.15 degC"),
    ("export {bias.json} --format kalibr -o x.yaml", 2, "kalibr export takes gyrocal.noise"),
    ("export {thermal.json} --format imucal -o x.json", 2, "imucal export takes gyrocal.calibration"),
    ("export {v1_thermal} --format json -o x.json", 0, ""),
    ("export {rec.csv} --format json -o x.json", 2, "a recording \\(CSV\\), not a gyrocal JSON file"),
    ("export {cal.json} --format json -o {cal.json}", 2, "also an input"),
    ("export {cal.json} --format c-header -o {rec.csv}", 2, "pass --force"),
    # imu
    ("imu {hand.csv} --units deg/s", 2, "--accel-units is required"),
    ("imu {hand.csv} --units deg/s --accel-units g", 2, r"--accel-units m/s\^2 \(or --no-unit-check\)"),
    ("imu {hand.csv} --units rad/s --accel-units m/s^2", 2, "use --units deg/s"),
    ("imu {hand.csv} --units deg/s --accel-units m/s^2 --gravity 0", 2, "--gravity must be finite and > 0"),
    ("imu {hand.csv} --units deg/s --accel-units counts --accel-sensitivity 0", 2, "--accel-sensitivity must be"),
    ("imu {hand.csv} --units deg/s --accel-units m/s^2 --min-static -1", 2, "--min-static must be finite"),
    ("imu {hand.csv} --units deg/s --accel-units m/s^2 --accel-columns ax=1", 2, "--accel-columns is for --accel-log"),
    ("imu {rec.csv} --units deg/s --accel-units m/s^2", 2, "no accelerometer column"),
    ("imu {static.csv} --units rad/s --accel-units m/s^2", 2, "6 distinct orientations"),
    ("imu {thermal.json} --units deg/s --accel-units m/s^2", 2, "not a recording"),
    ("imu {hand.csv} --units deg/s --accel-units m/s^2 -o i.json --plot i.json", 2, "its own file name"),
    ("imu {hand.csv} --units deg/s --accel-units m/s^2 -o {hand.csv}", 2, "also an input"),
    # verify and compare
    ("verify {cal.json} {rec.csv}", 2, "--reference REF"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv}", 2, "--ref-units is required"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv} --ref-units furlongs", 2, "--ref-units 'furlongs'"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv} --ref-units rad/s", 2, "use --ref-units deg/s"),
    ("verify {cal.json} {rec.csv} --reference {rec.csv} --ref-units deg/s", 2, "is the test log itself"),
    ("verify {noise.json} {rec.csv} --reference {ref.csv} --ref-units deg/s", 2, "'gyrocal.noise'; expected"),
    ("verify {cal.json} {static.csv} --reference {static.csv} --ref-units rad/s --units rad/s -o v", 2,
     "is the test log itself"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv} --ref-units deg/s --replicates 10", 2, "--replicates"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv} --ref-units deg/s --stretch 5:2", 2, "must run forward"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv} --ref-units deg/s --replicates 50 --stretch 1000:2000",
     2, "fewer than 2 compared samples"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv} --ref-units deg/s --ref-sample-rate 0", 2,
     "--ref-sample-rate must be finite and > 0"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv} --ref-units deg/s --seed -1", 2, "--seed"),
    ("verify {cal.json} {rec.csv} --reference {ref.csv} --ref-units deg/s -o {rec.csv}", 2, "give a folder"),
    ("compare {cal.json}", 2, "at least two files"),
    ("compare {cal.json} {cal.json}", 0, ""),
    ("compare {cal.json} {cal2.json} --tolerance 1e-6", 1, ""),
    ("compare {cal.json} {cal2.json} --tolerance -1", 2, "--tolerance"),
    ("compare {cal.json} {noise.json}", 2, ""),
    ("compare {cal.json} {thermal.json}", 2, "thermal files with thermal files"),
    ("compare {cal.json} /nonexistent.json", 2, "no such file"),
    # thermal and thermal-report
    ("thermal {session.csv} --units deg/s", 2, "missing option '-o'"),
    ("thermal {session.csv} --units deg/s -o t.json --settle 10", 2, "keeps 10 samples.*lower --settle"),
    ("thermal {session.csv} --units deg/s -o t.json --settle -1", 2, "--settle must be >= 0"),
    ("thermal {session.csv} --units deg/s -o t.json --settle 0.5 --max-order -1", 2, "--max-order must be >= 0"),
    ("thermal {session.csv} --units deg/s -o t.json --settle 0.5 --ref-temp -300", 2, "--ref-temp must be"),
    ("thermal {session.csv} --units deg/s -o t.json --settle 0.5 --temp-tau -1", 2, "--temp-tau must be"),
    ("thermal {session.csv} --units deg/s -o t.json --settle 0.5 --full-scale -1", 2, "--full-scale .* got -1"),
    ("thermal {rec.csv} --units deg/s -o t.json", 2, "needs the column"),
    ("thermal {cal.json} --units deg/s -o t.json", 2, "not a recording"),
    ("thermal {session.csv} --units deg/s -o {session.csv}", 2, "also an input"),
    ("thermal-report {session.csv} {thermal.json} -o r", 2, "arguments look swapped"),
    ("thermal-report {cal.json} {session.csv} -o r", 2, "expected 'gyrocal.thermal'"),
    ("thermal-report {thermal.json} {session.csv} -o r --no-figures --settle 0.5", 0, ""),
    ("thermal-report {thermal.json} {session.csv} -o {rec.csv} --no-figures", 2, "give a folder"),
    # noise
    ("noise {static.csv}", 2, "--units is required"),
    ("noise {static.csv} --units counts", 2, "give --sensitivity"),
    ("noise {static.csv} --units rad/s --accel-units counts", 2, "give --accel-sensitivity"),
    ("noise {static.csv} --units rad/s --accel-units g", 2, r"reads 0\.\d+ g.*--accel-units g|--accel-units"),
    ("noise {rec.csv} --units deg/s", 2, "the log moves"),
    ("noise {zeros.csv} --units deg/s", 2, "constant column"),
    ("noise {static.csv} --units rad/s --imu 1", 2, "--imu applies only to PX4"),
    ("noise {ulog} --units rad/s", 2, r"3 IMUs.*--imu N"),
    ("noise {ulog} --units rad/s --imu 7", 2, "no IMU 7"),
    ("noise {static.csv} --units rad/s --json n.json --plot n.json", 2, "its own file name"),
    ("noise {static.csv} --units rad/s --json n.json --plot n.jpg", 2, r"\.png, \.pdf or \.svg"),
    ("noise {static.csv} --units rad/s --json a.png --plot a.png", 2, "its own file name"),
    ("noise {static.csv} --units rad/s --json {static.csv}", 2, "also an input"),
    # thermal-bias
    ("thermal-bias {warm.csv} --units deg/s --max-order 7", 2, "--max-order must be 0..3"),
    ("thermal-bias {warm.csv} --units deg/s --min-span -5", 2, "--min-span must be"),
    ("thermal-bias {warm.csv} --units deg/s --min-span 500", 2, "needs at least 500 degC"),
    ("thermal-bias {rec.csv} --units deg/s", 2, "no temperature column"),
    ("thermal-bias {static.csv} --units rad/s", 2, "spans only 0.0 degC"),
    ("thermal-bias {ulog} --imu 0", 2, r"spans only 0\.\d degC"),
    ("thermal-bias {ulog} --imu 0 --units deg/s", 2, "give --units rad/s"),
    ("thermal-bias {warm.csv} --units deg/s -o {warm.csv}", 2, "also an input"),
    # simulate
    ("simulate", 2, "give -o FILE.csv"),
    ("simulate -o s.csv --protocol foo", 2, "--protocol: 'foo' is not one of"),
    ("simulate -o s.csv --speed -60", 2, "--speed must be finite and > 0"),
    ("simulate -o s.csv --speed 60furlongs", 2, "the unit is not one of"),
    ("simulate -o s.csv --turns +x,+q", 2, r"'\+q' is not one of"),
    ("simulate -o s.csv --misalignment 45", 2, r"--misalignment must be in \[0, 10\]"),
    ("simulate -o s.csv --bias-instability -1", 2, "--bias-instability must be >= 0"),
    ("simulate -o s.csv --rrw -1", 2, "--rrw must be >= 0"),
    ("simulate -o s.csv --full-scale -10", 2, "--full-scale must be > 0"),
    ("simulate -o s.csv --k 0,1,1", 2, "must be > 0"),
    ("simulate -o s.csv --seed -1", 2, "--seed"),
    ("simulate -o s.csv --units counts", 2, "--sensitivity"),
    ("simulate -o s.csv --protocol static", 2, "--duration"),
    ("simulate -o s.csv --protocol static --duration 10 --temp-start -300", 2, "--temp-start must be"),
    ("simulate -o s.csv --protocol static --duration 10 --temp-noise -1", 2, "--temp-noise must be"),
    ("simulate -o s.csv --protocol static --duration 10 --accel-noise-density -1", 2, "--accel-noise-density must"),
    ("simulate -o s.csv --protocol static --duration 10 --speed 60", 2, "--speed"),
    ("simulate -o s.csv --protocol multi-position --tilt 0", 2, r"--tilt must be in \(0, 180\]"),
    ("simulate -o s.csv --protocol multi-position --still -1", 2, "--still must be"),
    ("simulate -o s.csv --protocol multi-position --accel-noise-density -1", 2, "--accel-noise-density must"),
    ("simulate -o s.csv --protocol turntable --temps -300,20", 2, "--temps must be"),
    ("simulate -o s.csv --reference r.csv --ref-sample-rate -100", 2, "--ref-sample-rate must be finite and > 0"),
    ("simulate -o s.csv --reference r.csv --ref-units counts", 2, "--ref-units 'counts' is not a known unit"),
    ("simulate -o s.csv --reference s.csv", 2, "its own file name"),
    ("simulate -o s.csv --reference s.truth.json", 2, "its own file name"),
    ("simulate -o s.csv --ref-offset 1", 2, "add --reference"),
    ("simulate -o s.csv --wire text", 2, "--device"),
    ("simulate -o .", 2, "is a folder"),
    ("simulate -o s.parquet", 2, "give the file a .csv name"),
    ("simulate -o s.json", 2, "give the file a .csv name"),
    ("simulate -o {cal.json}", 2, "pass --force"),
    # plan and study
    ("plan --speed -60", 2, "--speed"),
    ("plan --noise 0", 2, "--noise must be > 0"),
    ("plan --wait -1", 2, "--wait must be"),
    ("plan --max-speed -10", 2, "--max-speed must be"),
    ("plan --noise-density {cal.json}", 2, "expected 'gyrocal.noise'"),
    ("plan --design poses --tilt 0", 2, r"--tilt must be in \(0, 180\]"),
    ("plan --design poses --poses 2", 2, "--poses must be a whole number >= 6"),
    ("plan --design poses --target-cross -1", 2, "--target-cross must be"),
    ("plan --design poses --target-accel-scale 0", 2, "--target-accel-scale must be"),
    ("plan --design six --tilt 45", 2, "--tilt does not apply"),
    ("study", 2, r"missing argument 'name'\. Choose from: servo-normal"),
    ("study servo-normal -o out --gyros 0", 2, "--gyros must be a positive integer"),
    ("study servo-speed -o out --methods foo", 2, "--methods takes"),
    ("study servo-normal -o out --seed -1", 2, "--seed"),
    # capture: what is checked before a port is opened, and ports that do not open
    ("capture -o c.csv", 2, "missing option '--port'"),
    ("capture --port /nonexistent -o c.csv", 2, "check --port"),
    ("capture --port {rec.csv} -o c.csv --duration 1", 2, "check --port"),
    ("capture --port /dev/null -o c.csv --duration -1", 2, "--duration must be > 0"),
    ("capture --port /dev/null -o c.csv --guide foo", 2, "--guide: 'foo' is not one of"),
    ("capture --port /dev/null -o {rec.csv}", 2, "pass --force"),
    ("capture --port /dev/null -o c.parquet", 2, "give the file a .csv name"),
    ("capture --port /dev/null -o c.csv --cal c.csv --guide servo", 2, "its own file name"),
    # the command itself
    ("--version", 0, ""),
    ("frobnicate", 2, "no such command"),
]


def _argv(case: str, fx: Path) -> list[str]:
    names = {"ulog": ULOG, "v1_cal": V1_CAL, "v1_thermal": V1_THERMAL}
    text = re.sub(r"\{([^}]+)\}", lambda m: shlex.quote(str(names.get(m.group(1), fx / m.group(1)))), case)
    return shlex.split(text)


#: Python names that must never reach a user: the library's parameters that have flags, and ``name='x'``.
_PYTHON_NAME = re.compile(r"(?<![-\w.'])(" + "|".join(re.escape(k) for k in FLAGS if "_" in k) + r")(?![\w-])"
                          r"|(?<![-\w])[a-z]+(?:_[a-z]+)*=['\"]")
_PYTHON_TEXT = re.compile(r"Traceback|Warning:|RuntimeWarning|UserWarning|DeprecationWarning|numpy\.")


@pytest.fixture(scope="module")
def inputs_before(fx) -> dict[str, str]:
    """The fixture files' contents before the battery (the reference of the last test)."""
    return {str(p): hashlib.sha256(p.read_bytes()).hexdigest() for p in fx.rglob("*") if p.is_file()}


@pytest.mark.parametrize("case, code, says", CASES, ids=[c[0][:70] for c in CASES])
def test_the_battery(case, code, says, fx, inputs_before, tmp_path, monkeypatch):
    """One mistake (or odd input): the expected exit code, and for a refusal one ``error:`` line that says
    what is wrong in flags (the case's pattern), no traceback or warning text, no file left behind."""
    monkeypatch.chdir(tmp_path)
    rc, out, err = invoke(*_argv(case, fx))
    assert rc == code, (out, err)
    assert not _PYTHON_TEXT.search(out + err), err
    assert not _PYTHON_NAME.search(err), err
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), err
        assert re.search(says, lines[0]), lines[0]
        assert list(tmp_path.iterdir()) == [], "a refused run left a file"


def test_no_case_changed_an_input(fx, inputs_before):
    """After the whole battery every input file holds what it held before (nothing replaced, nothing
    half-written beside it)."""
    after = {str(p): hashlib.sha256(p.read_bytes()).hexdigest() for p in fx.rglob("*") if p.is_file()}
    assert after == inputs_before


def _gyrocal() -> str:
    return shutil.which("gyrocal", path=str(Path(sys.executable).parent))


def test_a_closed_pipe_stops_the_printing_not_the_command(fx, tmp_path):
    """``gyrocal calibrate ... -o cal.json | head -1`` with the reader gone before the first line: the
    command still writes its calibration and exits 0 (rich alone would exit 1 before writing)."""
    out = tmp_path / "cal.json"
    proc = subprocess.Popen([_gyrocal(), "calibrate", str(fx / "rec.csv"), "--units", "deg/s", "--speed", "60",
                             "-o", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader went away at once
    err = proc.stderr.read().decode()
    proc.stderr.close()
    assert proc.wait(timeout=60) == 0, err
    assert out.is_file() and "Traceback" not in err


def test_tables_keep_every_digit_on_a_narrow_terminal_and_without_colour(fx):
    """40 columns (COLUMNS=40, as a narrow terminal or a pipe reports them) and NO_COLOR: the windows table
    of ``segments`` keeps every number whole (no '…') and holds no escape code (the reference: the same
    table printed in-process at 120 columns)."""
    env = {**os.environ, "COLUMNS": "40", "NO_COLOR": "1"}
    args = ["segments", str(fx / "rec.csv"), "--units", "deg/s", "--speed", "60"]
    narrow = subprocess.run([_gyrocal(), *args], env=env, capture_output=True, text=True, timeout=60)
    assert narrow.returncode == 0, narrow.stderr
    assert "…" not in narrow.stdout and "\x1b[" not in narrow.stdout
    _, wide, _ = invoke(*args)
    row = next(line for line in wide.splitlines() if "rotation" in line)
    assert [c.strip() for c in row.split("│")] in [[c.strip() for c in r.split("│")]
                                                   for r in narrow.stdout.splitlines()]


def test_ctrl_c_while_writing_leaves_nothing_and_says_so(tmp_path):
    """Ctrl-C (SIGINT) during the write of a large simulated log: exit 130, the one line that says no
    output was left half written, and the folder as it was before the run."""
    out = tmp_path / "long.csv"
    proc = subprocess.Popen([_gyrocal(), "simulate", "-o", str(out), "--protocol", "static", "--duration", "6000",
                             "--sample-rate", "200"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not any(p.name.endswith(".tmp.csv") for p in tmp_path.iterdir()):
            assert proc.poll() is None and time.monotonic() < deadline, "the writer never started"
            time.sleep(0.02)
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=60) == 130
        assert proc.stderr.read().strip() == "interrupted; no output was left half written"
    finally:
        proc.kill()
        proc.stderr.close()
    assert list(tmp_path.iterdir()) == []
