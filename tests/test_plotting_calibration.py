"""The calibration picture, checked through its artists (no pyplot state).

References: the figure's own artists (lines, spans and labels) against the recording and windows drawn.
"""

import math

import numpy as np
import pytest
from matplotlib.figure import Figure

from gyrocal import Calibration, Recording, ScaleBias
from gyrocal.plotting import new_figure, save_figure
from gyrocal.plotting.calibration import calibration_figure, plot_corrected, plot_windows
from gyrocal.segmentation.windows import Window

FS = 100.0
SPEED = math.radians(60.0)
TRUE = ScaleBias(k=[1.02, 0.98, 1.01], b=[0.01, -0.02, 0.005])


def _session(rng):
    """Static 2 s, then +x and -z turns of 360 deg at 60 deg/s, 2 s apart."""
    n_turn, n_gap = int(6 * FS), int(2 * FS)
    w = np.zeros((n_gap + n_turn + n_gap + n_turn + n_gap, 3))
    w[n_gap:n_gap + n_turn, 0] = SPEED
    s = 2 * n_gap + n_turn
    w[s:s + n_turn, 2] = -SPEED
    m = TRUE.distort(w) + 1e-3 * rng.standard_normal(w.shape)
    rec = Recording.from_rate(m, FS, source_units="deg/s")
    windows = [
        Window(0, n_gap, "static"),
        Window(n_gap, n_gap + n_turn, "rotation", axis="x", sign=1, angle=2 * math.pi),
        Window(s, s + n_turn, "rotation", axis="z", sign=-1, angle=2 * math.pi),
    ]
    return rec, windows


def test_raw_panel_shades_and_labels_every_window(rng):
    rec, windows = _session(rng)
    fig = Figure()
    ax = fig.add_subplot()
    art = plot_windows(ax, rec, windows)
    assert len(art["lines"]) == 3 and len(art["spans"]) == 3
    assert [t.get_text() for t in art["labels"]] == ["static", "+x", "\u2212z"]
    # the lines are the raw data in deg/s, the unit the data were declared in
    assert np.allclose(art["lines"][0].get_ydata(), np.degrees(rec.gyro[:, 0]))
    assert ax.get_ylabel() == "raw [deg/s]"
    assert art["spans"][1].get_facecolor()[:3] != art["spans"][0].get_facecolor()[:3]


def test_corrected_panel_annotates_each_turn_with_its_reference(rng):
    rec, windows = _session(rng)
    cal = Calibration(model=TRUE, input_units="deg/s", output_units="deg/s")
    ax = Figure().add_subplot()
    art = plot_corrected(ax, rec, cal, windows, speed=SPEED)
    assert np.allclose(art["lines"][2].get_ydata(), np.degrees(TRUE.correct(rec.gyro)[:, 2]))
    assert [line.get_ydata()[0] for line in art["reference"]] == pytest.approx([60.0, -60.0])
    rates = [float(t.get_text()) for t in art["labels"][1:]]
    assert rates == pytest.approx([60.0, 60.0], abs=0.01)
    assert float(art["labels"][0].get_text()) < 4 * math.degrees(1e-3) / math.sqrt(len(windows[0])) * math.sqrt(3)


def test_angle_annotation_without_speed(rng):
    rec, windows = _session(rng)
    cal = Calibration(model=TRUE, input_units="deg/s", output_units="rad/s")
    art = plot_corrected(Figure().add_subplot(), rec, cal, windows)
    assert [t.get_text() for t in art["labels"][1:]] == ["360.0\u00b0", "360.0\u00b0"]


def test_figure_has_raw_over_corrected_and_saves(rng, tmp_path):
    rec, windows = _session(rng)
    fig = calibration_figure(rec, windows, Calibration(model=TRUE, input_units="deg/s"), title="t")
    axes = fig.get_axes()
    assert len(axes) == 2 and axes[0].get_position().y0 > axes[1].get_position().y0
    assert axes[1].get_xlabel() == "time since the first sample [s]"
    assert calibration_figure(rec, windows, fig=new_figure()).get_axes()[0].get_ylabel() == "raw [deg/s]"
    out = tmp_path / "cal.png"
    save_figure(fig, out)
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_long_recordings_are_drawn_as_an_envelope_that_keeps_spikes(rng):
    m = 1e-3 * rng.standard_normal((200_000, 3))
    m[123_457, 1] = 5.0
    rec = Recording.from_rate(m, 1000.0)
    line = plot_windows(Figure().add_subplot(), rec, [])["lines"][1]
    assert len(line.get_ydata()) <= 20_000
    assert line.get_ydata().max() == 5.0  # rad/s, the unit declared


def test_bad_plot_suffix_is_refused(tmp_path):
    from gyrocal.errors import InputError

    with pytest.raises(InputError, match="must end in .png"):
        save_figure(new_figure(), tmp_path / "plot.txt")
    assert not list(tmp_path.iterdir())
