"""Evaluation like the full-temperature-range method's Tables 3-4 and Figures 4-9, the report folder, and the figures.

References: the step noise floor (sigma / sqrt(samples)), the simulated truth, and numpy's polyfit for the
leave-one-out errors.
"""

import dataclasses

import numpy as np
import pytest

from gyrocal.plotting.thermal_report import markdown_table, write_report
from gyrocal.simulation.thermal_truth import ThermalTruth
from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable
from gyrocal.thermal import calibrate_thermal
from gyrocal.thermal.evaluate import METHODS, evaluate, loto_comparison

NOISE = np.radians(0.05)
PROTO = {"step_duration": 3.0}


@pytest.fixture(scope="module")
def calibrated():
    rng = np.random.default_rng(20181004)  # one simulated session shared by the module's tests
    truth = ThermalTruth()
    gyro = truth.gyro(NOISE)
    rec = simulate_turntable(gyro, TurntableProtocol(**PROTO), sample_rate=50.0, rng=rng)
    cal, _ = calibrate_thermal([rec], settle=1.0, output_units="deg/s")
    test = simulate_turntable(gyro, TurntableProtocol(temps=(-35.0, 5.0, 25.0, 45.0), **PROTO), sample_rate=50.0, rng=rng)
    return truth, cal, evaluate(cal, [test], settle=1.0)


def test_interpolated_beats_traditional_away_from_25_degc(calibrated):
    _, _cal, ev = calibrated
    rows = ev.by_temperature("deg/s")
    away = [r for r in rows if abs(r["temp"] - 25.0) >= 20]
    assert away and all(r["lagrange_rms"] < 0.2 * r["traditional_rms"] for r in away)
    assert all(r["traditional_rms"] < r["uncompensated_rms"] for r in rows)


def test_compensated_errors_are_at_the_noise_floor(calibrated):
    _, _cal, ev = calibrated
    # a step mean of 100 samples has sigma NOISE / 10 per axis; the table adds its own error of similar size
    sigma_step = np.degrees(NOISE) / np.sqrt(100)
    for row in ev.summary("deg/s"):
        assert row["lagrange_rms"] < 4 * np.sqrt(2) * sigma_step
        assert row["smooth_rms"] < 4 * np.sqrt(2) * sigma_step
        assert abs(row["lagrange_mean"]) < 4 * np.sqrt(2) * sigma_step


def test_summary_has_every_rotating_and_gyro_axis(calibrated):
    _, _, ev = calibrated
    rows = ev.summary()
    assert [(r["rotating_axis"], r["gyro_axis"]) for r in rows] == [(a, g) for a in "xyz" for g in "xyz"]
    assert {f"{m}_rms" for m in METHODS} <= set(rows[0])
    # the uncompensated cross-axis error of the large Kyx/Kxy (eq. 23) dominates, as in Table 3
    big = {(r["rotating_axis"], r["gyro_axis"]): r["uncompensated_rms"] for r in rows}
    assert big[("x", "y")] > 10 * big[("x", "z")]


def _loto_by_hand(temps: np.ndarray, values: np.ndarray, option, fit) -> float:
    """RMS error of predicting each node from the others (numpy only)."""
    errors = []
    for k in range(len(temps)):
        keep = np.arange(len(temps)) != k
        errors.append(fit(temps[keep], values[keep], temps[k], option) - values[k])
    return float(np.sqrt(np.mean(np.square(errors))))


def _lagrange(t, v, at, _):
    """The parabola through the stencil of docs/thermal.md (first node >= T is i; nodes i-2..i, kept inside)."""
    i = next((j for j, x in enumerate(t) if x >= at), len(t))
    s = min(max(i - 2, 0), len(t) - 3)
    return np.polyval(np.polyfit(t[s:s + 3], v[s:s + 3], 2), at)


def _polynomial(t, v, at, order):
    return np.polyval(np.polyfit(t, v, order), at)


def test_loto_comparison_matches_a_by_hand_leave_one_out(calibrated):
    """Reference: numpy's polyfit through the documented stencil (Lagrange) and of each element's chosen order
    (smooth), leaving each temperature out in turn."""
    _, cal, _ = calibrated
    rows = loto_comparison(cal)
    assert [r["element"] for r in rows][:3] == ["Kxx", "Kyy", "Kzz"]
    for j, row in enumerate(rows):
        t, v = np.asarray(cal.temps), np.asarray(cal.kg[:, j])
        assert row["lagrange_loto_rms"] == pytest.approx(_loto_by_hand(t, v, None, _lagrange), rel=1e-6)
        assert row["smooth_loto_rms"] == pytest.approx(_loto_by_hand(t, v, row["order"], _polynomial), rel=1e-6)


def test_report_folder(calibrated, tmp_path):
    _, cal, ev = calibrated
    paths = write_report(cal, ev, tmp_path / "rep", figures=False)  # the CLI test writes the figures
    names = {p.name for p in paths}
    assert names == {"summary.csv", "summary.md", "by_temperature.csv", "steps.csv", "loto.csv"}
    md = (tmp_path / "rep" / "summary.md").read_text()
    assert "| x | y |" in md and "lagrange_rms" in md
    header = (tmp_path / "rep" / "summary.csv").read_text().splitlines()[0]
    assert header.startswith("rotating_axis,gyro_axis,steps,uncompensated_mean")


def test_markdown_table():
    assert markdown_table([{"a": 1.234567, "b": "x"}]) == "| a | b |\n|---|---|\n| 1.235 | x |\n"


def test_figures_draw_the_expected_artists(calibrated):
    from gyrocal.plotting import new_figure
    from gyrocal.plotting.thermal import plot_coefficients, plot_error_vs_rate, plot_error_vs_temperature

    truth, cal, ev = calibrated
    out = plot_coefficients(cal, new_figure(), truth=truth)
    assert len(out["axes"]) == 12 and len(out["lagrange"]) == 12 and len(out["truth"]) == 12
    x, y = out["lagrange"][0].get_data()
    np.testing.assert_allclose(y, cal.kg_at(x, "lagrange")[:, 0])
    assert out["axes"][9].get_title() == "Bx [deg/s]"
    rate = plot_error_vs_rate(ev, new_figure())
    assert rate["axes"].shape == (3, 3) and len(rate["series"]["lagrange"]) == 9
    x, y = rate["series"]["traditional"][1].get_data()  # x rotating, y gyro
    sel = ev.steps.axis == 0
    np.testing.assert_allclose(y, np.degrees(ev.errors["traditional"][sel, 1]))
    fig = new_figure()
    temp = plot_error_vs_temperature(ev, fig.add_subplot())
    assert set(temp["lines"]) == set(METHODS)
    assert len(temp["lines"]["lagrange"].get_xdata()) == 4


def test_out_of_range_steps_are_refused_or_warned_about_once(calibrated):
    import warnings

    from gyrocal.errors import OutOfRangeError
    from gyrocal.thermal import ThermalRangeWarning
    from gyrocal.thermal.evaluate import evaluate_steps

    _, cal, ev = calibrated
    hot = dataclasses.replace(ev.steps, temp=ev.steps.temp + 20.0)  # the 45 degC steps land at 65
    with pytest.raises(OutOfRangeError, match="outside the calibrated range"):
        evaluate_steps(cal, hot)
    for policy in ("clamp", "extrapolate"):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            evaluate_steps(cal, hot, policy)
        assert [type(w.message) for w in caught] == [ThermalRangeWarning], policy
