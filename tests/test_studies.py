"""Monte Carlo studies: outputs, and their numbers against theory."""

import csv
import math

import numpy as np
import pytest

from gyrocal.errors import InputError
from gyrocal.studies import STUDY_NAMES, run_study, study_units


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def normal(tmp_path_factory):
    out = tmp_path_factory.mktemp("normal")
    calls = []
    result = run_study("servo-normal", out, gyros=4, reps=250, seed=11, progress=lambda n, label: calls.append(n))
    return out, result, calls


def test_servo_normal_writes_figure_and_tables(normal):
    out, result, calls = normal
    assert {p.name for p in result.files} == {"errors.csv", "errors.md", "errors.png"}
    assert sum(calls) == study_units("servo-normal")
    rows = _rows(out / "errors.csv")
    assert len(rows) == 2 * 3 * 6
    assert (out / "errors.md").read_text().startswith("| noise")


def test_first_moment_reaches_the_cramer_rao_bound(normal):
    out, _, _ = normal
    n = 4 * 250
    for r in _rows(out / "errors.csv"):
        if r["method"] != "first moment":
            continue
        rms, crb = float(r["rms"]), float(r["CRB std"])
        # an RMS from n draws has relative sd ~ 1/sqrt(2n) around the bound
        assert abs(rms / crb - 1) < 4 / math.sqrt(2 * n), r


def test_algorithm1_equals_lm_with_six_observations(normal):
    """Six equations fix six unknowns, so both solvers land on the same point (the servo method of Wang et al., Fig. 2)."""
    out, _, _ = normal
    rows = _rows(out / "errors.csv")
    alg = {(r["noise [rad/s]"], r["param"]): float(r["rms"]) for r in rows if r["method"] == "Algorithm 1"}
    lm = {(r["noise [rad/s]"], r["param"]): float(r["rms"]) for r in rows if r["method"] == "LM"}
    assert alg.keys() == lm.keys()
    for key in alg:
        assert alg[key] == pytest.approx(lm[key], rel=1e-6)


def test_servo_extreme_runs_scaled_down(tmp_path):
    result = run_study("servo-extreme", tmp_path, gyros=2, reps=50, seed=3)
    rows = _rows(tmp_path / "errors.csv")
    assert len(rows) == 36 and result.name == "servo-extreme"


def test_servo_speed_mse_falls_with_speed(tmp_path):
    result = run_study("servo-speed", tmp_path, gyros=3, reps=200, seed=5, speeds=(0.4, 2.0),
                       methods=("algorithm1", "first-moment"))
    rows = _rows(tmp_path / "mse.csv")
    assert len(rows) == 2 * 2 * 2
    assert "mse.png" in {p.name for p in result.files}
    for method in ("first moment", "Algorithm 1"):
        for noise in ("0.035", "0.2"):
            slow, fast = [r for r in rows if r["method"] == method and r["noise [rad/s]"] == noise]
            assert float(slow["MSE kx"]) > float(fast["MSE kx"])
            assert float(slow["CRB var kx"]) > float(fast["CRB var kx"])


def test_servo_convergence_table(tmp_path):
    result = run_study("servo-convergence", tmp_path, reps=20, seed=2)
    rows = _rows(tmp_path / "convergence.csv")
    cases = {r["case"] for r in rows}
    assert len(cases) == 3
    for case in cases:
        mine = [r for r in rows if r["case"] == case]
        assert mine[0]["iteration"] == "actual value" and mine[-1]["iteration"].endswith("(converged)")
    assert "convergence.png" in {p.name for p in result.files}
    assert len(_rows(tmp_path / "iterations.csv")) == 3


def test_thermal_compare_table_beats_traditional(tmp_path):
    from gyrocal.studies.thermal_compare import NOISE, step_noise_floor

    calls = []
    run_study("thermal-compare", tmp_path, gyros=2, seed=1, step_duration=4.0, sample_rate=50.0,
              progress=lambda n, label: calls.append(n))
    assert sum(calls) == study_units("thermal-compare", gyros=2) == 2
    rows = _rows(tmp_path / "by_temperature.csv")
    far = [r for r in rows if abs(float(r["temp [degC]"]) - 25) > 20]
    assert far and all(float(r["lagrange rms [deg/s]"]) < float(r["traditional rms [deg/s]"]) for r in far)
    assert len(_rows(tmp_path / "table34.csv")) == 9
    # Each RMS is over 2 gyros x 63 steps x 3 axes, relative sd ~ 1/sqrt(2 * 378) = 4 %: none beats the floor.
    floor = step_noise_floor(NOISE, 50.0, 4.0)
    smooth = [float(r["smooth rms [deg/s]"]) / floor for r in rows]
    assert 0.85 < min(smooth) < 1.15  # and the smooth model reaches it
    assert all(float(r["lagrange rms [deg/s]"]) > 0.85 * floor for r in rows)


def test_run_study_rejects_bad_arguments(tmp_path):
    with pytest.raises(InputError, match="not one of"):
        run_study("servo-fast", tmp_path)
    with pytest.raises(InputError, match="--gyros"):
        run_study("servo-normal", tmp_path, gyros=0)
    with pytest.raises(InputError, match="--gyros does not apply"):
        run_study("servo-convergence", tmp_path, gyros=2)
    assert set(STUDY_NAMES) >= {"servo-normal", "servo-speed", "thermal-compare"}


def test_study_plots_draw_their_artists():
    from gyrocal.plotting import new_figure
    from gyrocal.plotting.studies import convergence, error_boxes, mse_vs_speed, rms_by_temperature

    fig = new_figure()
    ax1, ax2, ax3, ax4 = fig.subplots(1, 4)
    errors = np.random.default_rng(0).standard_normal((200, 6)) * 1e-3
    art = error_boxes(ax1, errors, np.full(6, 1e-3))
    assert len(art["boxes"]) == 6 and len(art["crb"]) == 2
    np.testing.assert_allclose(art["crb"][1].get_ydata(), 2e-3)
    lines = mse_vs_speed(ax2, [0.5, 1.0], np.ones((2, 6)), np.full((2, 6), 0.5))
    assert len(lines) == 12 and lines[1].get_linestyle() == "--"
    history = np.array([[1.1] * 3 + [0.1] * 3, [1.0] * 3 + [0.1] * 3])
    lines = convergence(ax3, history, np.array([1.0] * 3 + [0.1] * 3))
    assert len(lines) == 6
    np.testing.assert_allclose(lines[0].get_ydata(), [0.1, 1e-12], atol=1e-12)
    lines = rms_by_temperature(ax4, [0.0, 10.0], {"lagrange": [0.02, 0.03]}, floor=0.01)
    assert len(lines) == 2 and lines[1].get_linestyle() == "--"
    np.testing.assert_allclose(lines[1].get_ydata(), 0.01)
    assert "noise floor" in lines[1].get_label()
