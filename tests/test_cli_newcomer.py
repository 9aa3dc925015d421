"""The command line a newcomer trusts: apply's checks (data corrected twice, data in another unit),
the printed k and offset, swapped arguments, reading flags named as flags.

In-process through the real error boundary (:mod:`cli_runner`); each refusal is one line, exit 2.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from cli_runner import invoke, refused

from gyrocal.io import write_csv
from gyrocal.models import ScaleBias
from gyrocal.observations.observed import check_observed, observe, quiet_noise
from gyrocal.results.files import load_calibration
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import ServoProtocol, simulate_servo

TRUE = ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076])
NOISE = 0.01  # rad/s per sample


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    """A servo session (Wang et al.'s protocol, 60 deg/s, 200 Hz) written in deg/s, in rad/s and in counts
    (131 LSB per deg/s), and a calibration made from the deg/s file."""
    folder = tmp_path_factory.mktemp("session")
    rec, _ = simulate_servo(VirtualGyro(model=TRUE, noise_std=NOISE), ServoProtocol(), sample_rate=200.0,
                            rng=np.random.default_rng(11))
    deg = np.degrees(rec.gyro)
    for name, g in (("deg.csv", deg), ("rad.csv", rec.gyro), ("counts.csv", np.round(deg * 131.0))):
        write_csv(folder / name, {"t": rec.t, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
    code, _, err = invoke("calibrate", folder / "deg.csv", "--units", "deg/s", "--speed", "60",
                          "-o", folder / "cal.json")
    assert code == 0, err
    return folder


def test_the_calibration_records_what_its_data_looked_like(session):
    """Reference: the simulated noise (0.01 rad/s per sample) and the 60 deg/s turns with 5 % vibration."""
    observed = load_calibration(session / "cal.json").observed
    assert observed["units"] == "deg/s" and observed["sample_rate"] == pytest.approx(200.0)
    # pooled over ~4000 still samples: relative sd ~1.2 %; 4 sigma
    np.testing.assert_allclose(observed["quiet_noise_std"], math.degrees(NOISE), rtol=0.05)
    assert all(60 < v < 90 for v in observed["max_abs_rate"])


def test_quiet_noise_is_the_noise_of_the_still_parts(rng):
    """Reference: white noise of known sd, half of it under a servo's 60 deg/s turn with 5 % speed
    vibration; sd of the estimate 1/sqrt(2 n) with n = 10 000 still samples, so 4 sigma = 2.8 %."""
    n = 20_000
    raw = rng.normal(0.0, [0.3, 1.0, 2.0], (n, 3))
    raw[n // 2:] += 60.0 + rng.normal(0.0, 3.0, (n // 2, 1))
    np.testing.assert_allclose(quiet_noise(raw, 100.0), [0.3, 1.0, 2.0], rtol=0.028)
    # a steady turn without vibration is as quiet as a standstill, and counts as such
    steady = rng.normal(0.0, 1.0, (n, 3)) + np.where(np.arange(n) < n // 2, 0.0, 60.0)[:, None]
    np.testing.assert_allclose(quiet_noise(steady, 100.0), 1.0, rtol=0.02)


def test_apply_refuses_data_in_radians_against_a_degree_calibration(session, tmp_path):
    line = refused("apply", session / "cal.json", session / "rad.csv", "-o", tmp_path / "out.csv")
    assert "rad.csv: the data look like rad/s, not deg/s as cal.json expects" in line
    assert "give --units rad/s (gyrocal converts them), or --no-unit-check to apply anyway" in line
    assert not (tmp_path / "out.csv").exists()
    # the advice works, and gives what the deg/s file gives (the reference)
    for name, extra in (("rad.csv", ("--units", "rad/s")), ("deg.csv", ())):
        code, _, err = invoke("apply", session / "cal.json", session / name, "-o", tmp_path / f"c_{name}", *extra)
        assert code == 0 and err == "", err
    a, b = (np.loadtxt(tmp_path / f"c_{n}", delimiter=",", skiprows=2) for n in ("rad.csv", "deg.csv"))
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    code, _, _ = invoke("apply", session / "cal.json", session / "rad.csv", "-o", tmp_path / "x.csv",
                        "--no-unit-check")
    assert code == 0


def test_check_observed_names_counts_and_keeps_quiet_when_data_match(session, rng):
    observed = load_calibration(session / "cal.json").observed
    t_noise = math.degrees(NOISE)
    same = rng.normal(0.0, t_noise, (4000, 3))
    assert check_observed(observed, same, 200.0, source="d", calibration="c") is None
    louder = rng.normal(0.0, 3 * t_noise, (4000, 3))  # another sensor of the kind: no unit explains it, no refusal
    assert check_observed(observed, louder, 200.0, source="d", calibration="c") is None
    counts = np.round(same * 131.0)
    with pytest.raises(Exception, match=r"the data look like counts, not deg/s"):
        check_observed(observed, counts, 200.0, source="d", calibration="c")
    odd = rng.normal(0.0, t_noise / 15, (4000, 3))  # quieter by 15: no unit, a warning
    assert "differs from the calibration's by" in check_observed(observed, odd, 200.0, source="d", calibration="c")
    # a counts calibration (131 LSB per deg/s) given rates in deg/s
    cal_counts = observe(counts, 200.0, "counts")
    with pytest.raises(Exception, match=r"the data look like deg/s, not counts"):
        check_observed(cal_counts, same, 200.0, source="d", calibration="c", sensitivity=131.0, output_units="deg/s")


def test_apply_refuses_its_own_output_unless_forced(session, tmp_path):
    first = tmp_path / "corrected.csv"
    assert invoke("apply", session / "cal.json", session / "deg.csv", "-o", first)[0] == 0
    line = refused("apply", session / "cal.json", first, "-o", tmp_path / "twice.csv")
    assert "corrected.csv was written by 'gyrocal apply'" in line and "would correct them twice" in line
    assert "--force to correct it again" in line
    assert invoke("apply", session / "cal.json", first, "-o", tmp_path / "twice.csv", "--force")[0] == 0


def test_swapped_arguments_say_which_comes_first(session, tmp_path):
    line = refused("apply", session / "deg.csv", session / "cal.json", "-o", tmp_path / "o.csv")
    assert "the arguments look swapped; the calibration file comes first" in line
    line = refused("thermal-report", session / "deg.csv", session / "cal.json", "-o", tmp_path / "rep")
    assert "the arguments look swapped; the thermal file from 'gyrocal thermal' comes first" in line


def test_counts_with_a_sensitivity_print_the_k_the_file_stores(session, tmp_path):
    out = tmp_path / "c.json"
    code, stdout, err = invoke("calibrate", session / "counts.csv", "--units", "counts", "--sensitivity", "131",
                               "--speed", "60", "-o", out)
    assert code == 0, err
    stored = load_calibration(out)
    k = json.loads(out.read_text())["parameters"]["scale_bias"]["k"]
    for axis, value in zip("xyz", k):
        assert f"k{axis} [1]" in stdout and f"{value:.6g}" in stdout
    assert "bx [deg/s]" in stdout
    assert "measured sensitivity is " + ", ".join(f"{131 / v:.5g}" for v in k) in stdout
    # the printed sensitivity against the simulation's truth: 131 / k_true within 4 sigma of k
    np.testing.assert_array_less(np.abs(np.asarray(k) - TRUE.k), 4 * stored.std[:3])
    code, stdout, _ = invoke("calibrate", session / "counts.csv", "--units", "counts", "--speed", "60")
    assert code == 0 and "kx [deg/s per count]" in stdout and "bx [counts]" in stdout


def test_offset_is_printed_beside_b(session):
    code, stdout, _ = invoke("calibrate", session / "deg.csv", "--units", "deg/s", "--speed", "60")
    assert code == 0 and "at rest" in stdout
    cal = load_calibration(session / "cal.json")
    b = -cal.correction[1]
    for j, axis in enumerate("xyz"):
        row = next(line for line in stdout.splitlines() if f"b{axis} [deg/s]" in line)
        assert f"{b[j]:.6g}" in row and f"{-b[j]:+.6g}" in row


def test_reading_flags_are_named_as_flags(session, tmp_path):
    lines = (session / "deg.csv").read_text().splitlines()
    pre = tmp_path / "pre.csv"
    pre.write_text("sensor,gyro,range,2000\n0,1,2,3\n" + "\n".join(lines) + "\n")
    line = refused("calibrate", pre, "--units", "deg/s", "--speed", "60")
    assert "map them with --columns gx=NAME" in line and "skip the lines above it with --skip-rows N" in line
    assert invoke("calibrate", pre, "--units", "deg/s", "--speed", "60", "--skip-rows", "2")[0] == 0
    bare = tmp_path / "bare.csv"
    bare.write_text("\n".join(line.split(",", 1)[1] for line in lines[1:]) + "\n")
    line = refused("segments", bare, "--units", "deg/s", "--speed", "60")
    assert "(--columns gx=1,gy=2,gz=3 with --sample-rate HZ)" in line
    code, stdout, err = invoke("segments", bare, "--units", "deg/s", "--speed", "60", "--columns", "gx=1,gy=2,gz=3",
                               "--sample-rate", "200")
    assert code == 0, err


# ---------------------------------------------------------------- the command itself


def test_version_help_and_bare_command():
    from gyrocal._version import __version__

    code, out, err = invoke("--version")
    assert (code, out.strip(), err) == (0, f"gyrocal {__version__}", "")
    for args in ((), ("-h",), ("--help",)):
        code, out, err = invoke(*args)
        assert code == 0 and err == "" and "Commands:" in out, args
    code, out, _ = invoke("apply", "-h")
    assert code == 0 and "Usage: gyrocal apply" in out


def test_command_list_starts_with_calibrate_and_keeps_every_description_whole():
    import typer

    from gyrocal.cli import app

    code, out, _ = invoke("--help")
    listing = " ".join(out[out.index("Commands:"):].split())
    assert "..." not in listing
    for name, cmd in typer.main.get_command(app).commands.items():
        first = " ".join((cmd.help or "").split("\n\n")[0].split())
        assert f"{name} {first}" in listing, name


@pytest.mark.parametrize(("args", "expected"), [
    (("calibrate", "x.csv", "--method", "foo"),
     "error: invalid value for --method: 'foo' is not one of 'first-moment', 'algorithm1', 'lm' "
     "(see 'gyrocal calibrate --help')"),
    (("calibrate", "x.csv", "--angle", "fast"),
     "error: invalid value for --angle: 'fast' is not a number (see 'gyrocal calibrate --help')"),
    (("apply", "cal.json", "rec.csv"), "error: missing option '-o' / '--output' (see 'gyrocal apply --help')"),
    (("segments",), "error: missing argument 'recording' (see 'gyrocal segments --help')"),
    (("calibrat",), "error: no such command 'calibrat'"),
])
def test_parser_errors_are_one_line_pointing_to_the_commands_help(args, expected):
    line = refused(*args)
    assert line.startswith(expected) and "Value error" not in line, line


def test_every_option_states_its_default_or_that_it_is_required():
    """A newcomer reads --help to learn what happens when a flag is left out."""
    import typer

    from gyrocal.cli import app

    missing = []
    for name, cmd in typer.main.get_command(app).commands.items():
        for p in cmd.params:
            if p.param_type_name != "option" or getattr(p, "is_flag", False) or p.required or p.default is not None:
                continue
            text = (p.help or "").lower()
            if "default" not in text and "(required" not in text:
                missing.append(f"{name} {max(p.opts, key=len)}")
    assert not missing, missing


def test_units_show_their_choices():
    for command in ("calibrate", "segments", "apply", "noise", "thermal"):
        code, out, _ = invoke(command, "--help")
        assert code == 0 and "--units <rad/s|deg/s|counts>" in out, command
    code, out, _ = invoke("calibrate", "--help")
    assert "(required)" in " ".join(out.split())


# ---------------------------------------------------------------- what was found instead of the turns


def test_no_rotation_says_what_was_measured_and_the_likely_fix(session, tmp_path):
    """Reference: the session's turns are 360 deg at 60 deg/s, 200 Hz, in deg/s (as simulated)."""
    cases = [
        (("rad.csv", "--units", "deg/s", "--angle", "360", "--no-unit-check"),
         "are the data in rad/s? (--units rad/s)"),
        (("rad.csv", "--units", "deg/s", "--speed", "60", "--no-unit-check"), "are the data in rad/s? (--units rad/s)"),
        (("deg.csv", "--units", "deg/s", "--angle", "36"), "were the turns 360 deg (--angle 360)?"),
        # the raw plateau level is k times the speed: 60 deg/s reads 59.5-60.3
        (("deg.csv", "--units", "deg/s", "--speed", "6"), re.compile(r"was the speed 60(\.\d)? deg/s \(--speed 60")),
    ]
    for args, fix in cases:
        line = refused("calibrate", session / args[0], *args[1:])
        assert "the turns left out measure +x" in line and "most likely: every" in line, line
        assert (fix.search(line) if isinstance(fix, re.Pattern) else fix in line), line
    # a wrong sample rate on a log without a time column: the rate that explains the turns is named
    lines = (session / "deg.csv").read_text().splitlines()
    bare = tmp_path / "g.csv"
    bare.write_text("gx,gy,gz\n" + "\n".join(line.split(",", 1)[1] for line in lines[2:]) + "\n")
    line = refused("calibrate", bare, "--units", "deg/s", "--sample-rate", "1000")
    assert re.search(r"is the sample rate 20\d Hz \(--sample-rate 20\d\)\?", line), line
    # turns about two axes only
    code, _, err = invoke("simulate", "-o", tmp_path / "two.csv", "--turns", "+x,-x,+y,-y")
    assert code == 0, err
    line = refused("calibrate", tmp_path / "two.csv", "--units", "deg/s")
    assert "no rotation about z" in line and "turn about the missing axes too" in line


# ---------------------------------------------------------------- plan


def test_plan_says_when_the_protocol_as_given_meets_the_target_and_never_worsens_it():
    """Reference: the Cramer-Rao prediction of the protocol as given (the first row), computed by predict()."""
    import math

    from gyrocal.planning import predict

    given = predict("six", speed=math.radians(60), noise_density=0.035 / math.sqrt(200.0))
    code, out, _ = invoke("plan", "--target-bias", "0.05deg/s")
    flat = " ".join(out.split())
    assert code == 0 and "the protocol as given already meets the target std b <= 0.05 deg/s" in flat
    assert "suggested" not in out  # every shorter protocol on the grid has a larger bias std
    assert given.max_bias_std < math.radians(0.05)
    code, out, _ = invoke("plan", "--target-scale", "1e-3")
    rows = {cells[1]: cells for line in out.splitlines()
            if len(cells := [c.strip() for c in line.split("\u2502")]) > 6 and cells[1] in ("as given", "suggested")}
    k_given, k_suggested = (float(rows[key][5]) for key in ("as given", "suggested"))
    assert k_suggested <= k_given and "already meets the target std k <= 0.001" in " ".join(out.split())
    code, out, _ = invoke("plan", "--target-bias", "0.01deg/s")
    assert code == 0 and "misses the target" in " ".join(out.split()) and "suggested" in out


def test_sigterm_during_simulate_leaves_no_partial_output(tmp_path):
    """A real 'gyrocal simulate' of a long static log, stopped by SIGTERM once its temporary file exists:
    no .tmp is left and no output appears (the reference: the folder as it was before the run)."""
    import shutil
    import signal
    import subprocess
    import sys
    import time

    exe = shutil.which("gyrocal", path=str(Path(sys.executable).parent))
    out = tmp_path / "long.csv"
    proc = subprocess.Popen([exe, "simulate", "-o", str(out), "--protocol", "static", "--duration", "20000",
                             "--sample-rate", "200"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not any(p.name.endswith(".tmp.csv") for p in tmp_path.iterdir()):
            assert proc.poll() is None and time.monotonic() < deadline, "the writer never started"
            time.sleep(0.05)
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=60) == -signal.SIGTERM
    finally:
        proc.kill()
        proc.stderr.close()
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- plots


def test_segments_plot_marks_ignored_turns_and_nothing_covers_the_data(session, tmp_path):
    """Drawn into a Figure and checked artist by artist: each ignored turn hatched with its reason, the
    legend right of the axes, no offset text above them (epoch stamps), time counted from the start."""
    from gyrocal.io import read_recording
    from gyrocal.plotting.calibration import calibration_figure
    from gyrocal.plotting.figure import plain_ticks
    from gyrocal.segmentation import segment

    lines = (session / "deg.csv").read_text().splitlines()
    cells = [line.split(",", 1) for line in lines[2:]]
    epoch = tmp_path / "epoch.csv"
    epoch.write_text("t,gx,gy,gz\n" + "\n".join(f"{1.7e9 + float(t)!r},{rest}" for t, rest in cells) + "\n")
    rec = read_recording(epoch, units="deg/s")
    seg = segment(rec, reference="angle", angle=math.pi / 2, require=False)  # 360 deg turns declared as 90
    fig = calibration_figure(rec, list(seg.windows), ignored=list(seg.ignored))
    ax = fig.axes[0]
    reasons = [t.get_text() for t in ax.texts if t.get_text().startswith("ignored:")]
    assert len(reasons) == 6 and all(r == "ignored: wrong angle" for r in reasons)
    assert sum(p.get_hatch() == "///" for p in ax.patches) == 6
    legend = ax.get_legend()
    assert legend.get_bbox_to_anchor().transformed(ax.transAxes.inverted()).x0 >= 1.0
    plain_ticks(fig)
    fig.canvas.draw()
    assert ax.xaxis.get_offset_text().get_text() == "" and ax.yaxis.get_offset_text().get_text() == ""
    assert ax.get_xlim()[0] < 100  # seconds since the first sample, not 1.7e9
    code, _, err = invoke("segments", epoch, "--units", "deg/s", "--angle", "90", "--plot", tmp_path / "s.png")
    assert code == 0 and (tmp_path / "s.png").stat().st_size > 10_000, err


# ---------------------------------------------------------------- simulate


def test_simulate_rates_with_their_units_and_counts_with_a_sensitivity(tmp_path):
    """Reference: the truth sidecar, which stores SI; 2 deg/s of noise is 0.0349 rad/s."""
    from gyrocal.io import read_recording
    from gyrocal.results.files import load
    from gyrocal.simulation.truth import SimulationTruth

    code, _, err = invoke("simulate", "-o", tmp_path / "a.csv", "--noise", "2deg/s", "--b", "0.5,0.1,0.2deg/s",
                          "--speed", "1.0471975511965976rad/s")
    assert code == 0, err
    truth = load(tmp_path / "a.truth.json", SimulationTruth)
    np.testing.assert_allclose(truth.settings["noise_std"], math.radians(2.0), rtol=1e-12)
    np.testing.assert_allclose(truth.model.b, np.radians([0.5, 0.1, 0.2]), rtol=1e-12)
    assert truth.settings["speed_deg_s"] == pytest.approx(60.0)
    assert "--noise must be a number" in refused("simulate", "-o", tmp_path / "b.csv", "--noise", "loud")
    line = refused("simulate", "-o", tmp_path / "c.csv", "--units", "counts")
    assert "--units counts needs the sensitivity" in line and "--sensitivity" in line
    code, _, err = invoke("simulate", "-o", tmp_path / "c.csv", "--units", "counts", "--sensitivity", "131")
    assert code == 0, err
    raw = read_recording(tmp_path / "c.csv", units="counts")
    deg = read_recording(tmp_path / "c.csv", units="counts", sensitivity=131)
    assert raw.units == "counts" and np.array_equal(raw.gyro, np.round(raw.gyro))
    assert (tmp_path / "c.csv").read_text().startswith("# gyrocal simulate --protocol servo; gyro in counts (131 LSB")
    assert np.abs(np.degrees(deg.gyro)).max() > 55  # the 60 deg/s turns, through the sensitivity


def test_a_large_session_says_its_size_first(tmp_path):
    code, out, err = invoke("simulate", "-o", tmp_path / "s.csv", "--protocol", "static", "--duration", "5100")
    assert code == 0, err
    first = out.splitlines()[0]
    assert first.startswith("simulating 1.02 M samples (1.42 h of data at 200 Hz): about ") and "MB of CSV" in first
    estimate = float(first.split("about ")[1].split(" MB")[0])
    actual = (tmp_path / "s.csv").stat().st_size / 1e6
    assert 0.7 < estimate / actual < 1.4, (estimate, actual)


def test_skip_rows_reaches_noise_and_thermal(tmp_path):
    code, _, err = invoke("simulate", "-o", tmp_path / "still.csv", "--protocol", "static", "--duration", "60")
    assert code == 0, err
    lines = [line for line in (tmp_path / "still.csv").read_text().splitlines() if not line.startswith("#")]
    pre = tmp_path / "pre.csv"
    width = len(lines[0].split(","))  # a preamble as wide as the table: only the user knows where it ends
    pre.write_text(",".join(["sensor"] + ["x"] * (width - 1)) + "\n" + ",".join(map(str, range(width))) + "\n"
                   + "\n".join(lines) + "\n")
    assert "--skip-rows N" in refused("noise", pre, "--units", "deg/s")
    code, out, err = invoke("noise", pre, "--units", "deg/s", "--skip-rows", "2")
    assert code == 0, err
    for command in ("thermal", "thermal-report"):
        code, out, _ = invoke(command, "--help")
        assert code == 0 and "--skip-rows" in out
