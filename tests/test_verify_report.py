"""The verification report: its JSON document, its Markdown summary and its pictures.

Independent references: the document read back must rebuild the same report (a round
trip through ``json``), fields are checked against the issue's required names, the
summary's numbers against the report's, and the pictures through their artists' data.
"""

import json
import math

import numpy as np
import pytest
from matplotlib.figure import Figure
from verify_pairs import make_pair

from gyrocal.errors import FileFormatError
from gyrocal.plotting.verify import default_stretch, error_figure, overlay_figure, plot_errors, plot_overlay
from gyrocal.verify import VerifyReport, verify_rates
from gyrocal.verify.summary import format_pm, summary_markdown

REQUIRED = ("time_offset_s", "clock_drift_ppm", "mounting_rotation_deg", "mounting_rotation", "axes")


@pytest.fixture(scope="module")
def verified():
    rng = np.random.default_rng(5)
    pair = make_pair(rng, motion="servo", offset=-1.5, drift=50.0, mounting_deg=8.0)
    raw = pair.test.gyro + [0.02, -0.01, 0.015]  # a bias the "calibration" removes
    report, series = verify_rates(pair.test.t, raw, pair.test.gyro, pair.ref.t, pair.ref.gyro, units="deg/s",
                                  seed=3, replicates=100, inputs={"calibration": "cal.json", "test": "test.csv",
                                                                  "reference": "ref.csv"})
    return report, series


def test_document_has_the_issue_fields_and_round_trips(verified):
    report, _ = verified
    doc = json.loads(json.dumps(report.to_document()))
    assert doc["format"] == "gyrocal.verify" and doc["version"] == 1
    assert all(key in doc for key in REQUIRED)
    assert set(doc["axes"]) == {"x", "y", "z"}
    assert {"mse_before", "mse_after", "rmse_before", "rmse_after", "p99_after", "reduction_pct"} <= set(doc["axes"]["x"])
    assert np.asarray(doc["mounting_rotation"]).shape == (3, 3)
    again = VerifyReport.from_document(doc, "v.json")
    assert again.to_document() == report.to_document()


def test_document_figures_are_in_the_output_units(verified):
    report, series = verified
    doc = report.to_document()
    err = series.calibrated - series.reference  # deg/s
    assert doc["units"]["rates"] == "deg/s"
    assert doc["axes"]["y"]["mse_after"] == pytest.approx(float(np.mean(err[:, 1] ** 2)))


def test_missing_before_figures_are_null_and_read_back_as_nan(verified):
    report, _series = verified
    doc = report.to_document()
    for ax in doc["axes"].values():
        ax["mse_before"] = None
    again = VerifyReport.from_document(json.loads(json.dumps(doc)))
    assert math.isnan(again.metrics.values["mse_before"][0])


@pytest.mark.parametrize("field, value", [("format", "gyrocal.noise"), ("mounting_rotation", [[1, 0], [0, 1]]),
                                          ("time_offset_s", "soon"), ("axes", [])])
def test_bad_documents_name_the_field(verified, field, value):
    doc = json.loads(json.dumps(verified[0].to_document()))
    doc[field] = value
    with pytest.raises(FileFormatError, match=field):
        VerifyReport.from_document(doc, "v.json")


def test_summary_is_laid_out_like_table_v(verified):
    report, _ = verified
    text = summary_markdown(report)
    lines = text.splitlines()
    head = lines.index("| Axis | Error before calibration, MSE (deg/s)² | Error after calibration, MSE (deg/s)² | "
                       "Reduction |")
    rows = lines[head + 2:head + 5]
    assert [r.split("|")[1].strip() for r in rows] == ["x", "y", "z"]
    v, s = report.metrics.values, report.metrics.std
    assert format_pm(v["mse_after"][2], s["mse_after"][2]) in rows[2]
    assert "`cal.json` applied to `test.csv`" in text and "time_offset_s" in text


def test_format_pm_rounds_to_the_uncertainty():
    assert format_pm(4.58923, 0.2062) == "4.59 ± 0.21"
    assert format_pm(-2.3006050, 0.00071455, "s") == "-2.30061 ± 0.00071 s"
    assert format_pm(float("nan"), 1.0) == "n/a"


def test_overlay_draws_the_gyro_over_the_reference(verified):
    _, series = verified
    fig = Figure()
    ax = fig.add_subplot()
    gyro, ref = plot_overlay(ax, series.t, series.raw, series.reference, 1, units="deg/s", label="raw")
    assert np.array_equal(gyro.get_ydata(), series.raw[:, 1]) and np.array_equal(ref.get_ydata(), series.reference[:, 1])
    assert ref.get_linestyle() == "--" and ax.get_ylabel() == "y [deg/s]"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["raw y", "reference y"]


def test_error_panel_and_stretch(verified):
    _, series = verified
    fig = Figure()
    ax = fig.add_subplot()
    stretch = (series.t[100], series.t[600])
    err_after = series.calibrated - series.reference
    before, after, before_mean, after_mean = plot_errors(ax, series.t, series.raw - series.reference, err_after, 0,
                                                         units="deg/s", stretch=stretch, smooth_s=0.5)
    assert before.get_xdata()[0] == series.t[100] and after.get_xdata()[-1] == series.t[600]
    assert np.allclose(after.get_ydata(), err_after[100:601, 0])
    # the bold line is the centred 0.5 s mean (100 samples at 200 Hz) of the error, checked at one sample
    i = 300
    assert after_mean.get_ydata()[i - 100] == pytest.approx(err_after[i - 50:i + 50, 0].mean())
    assert after_mean.get_linewidth() > after.get_linewidth()


def test_whole_figures_have_three_panels(verified):
    _, series = verified
    for fig in (overlay_figure(series, calibrated=False), overlay_figure(series, calibrated=True),
                error_figure(series)):
        assert len(fig.axes) == 3 and all(len(ax.get_lines()) >= 2 for ax in fig.axes)


def test_default_stretch_picks_the_busiest_minute():
    t = np.arange(0, 600, 0.1)
    ref = np.zeros((len(t), 3))
    ref[(t > 300) & (t < 330), 0] = 1.0
    lo, hi = default_stretch(t, ref)
    assert hi - lo == pytest.approx(60.0) and lo <= 300 and hi >= 330
