"""The fleet report (gyrocal.station.fleet and ``gyrocal fleet``) on a real SQLite store of synthetic units.

References: the test's own seeded fleet (the values each unit was given, its newest calibration chosen by
hand), Cp/Cpk and their intervals written out here from the textbook formulas with scipy's quantiles, the
I-MR limits worked by hand, the Wilson interval as the root of its defining equation, and a seeded
Monte-Carlo run for the coverage of the Cp interval.
"""

from __future__ import annotations

import json
import math
from datetime import UTC, datetime, timedelta

import numpy as np
import pytest
from cli_runner import invoke, refused
from scipy import optimize
from scipy import stats as sps

from gyrocal.station.accept import accept
from gyrocal.station.fleet import capability, fleet_statistics, imr_limits, wilson
from gyrocal.station.fleet_report import SUMMARY, write_report
from gyrocal.station.limits import read_limits
from gyrocal.store import open_store

T0 = datetime(2025, 3, 1, 8, 0, tzinfo=UTC)
DEG = math.pi / 180
LIMITS = "guard = 2\n[limits.k]\nmin = 0.996\nmax = 1.006\n[limits.b]\nmax_abs = 0.3\nunit = \"deg/s\"\n"
K_SIGMA, B_SIGMA = 0.0003, 0.0004  # each calibration's 1-sigma (k [1], b [rad/s])
STATIONS = ("A", "B", "C")
DRIFTER = "SN-DRIFT"


def _doc(serial: str, k, b, station: str, limits) -> dict:
    doc = {"format": "gyrocal.calibration", "version": 1, "units": {"input": "rad/s", "internal": "rad/s"},
           "parameters": {"scale_bias": {"k": [float(v) for v in k], "b": [float(v) for v in b]}},
           "std": {**{f"k{a}": K_SIGMA for a in "xyz"}, **{f"b{a}": B_SIGMA for a in "xyz"}},
           "unit": {"serial": serial, "station": station}}
    return {**doc, "acceptance": accept(doc, limits).to_document()}


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """30 units over 3 stations, k ~ N(1.001, 0.002), b ~ N(0, 0.1 deg/s); 6 recalibrated a day later
    (one, DRIFTER, with kx moved by 0.01); an acceptance record that is no calibration."""
    rng = np.random.default_rng(20250301)
    folder = tmp_path_factory.mktemp("fleet")
    (folder / "limits.toml").write_text(LIMITS)
    limits = read_limits(folder / "limits.toml")
    newest, items = {}, []
    for i in range(30):
        serial = DRIFTER if i == 7 else f"SN{i:03d}"
        station = STATIONS[i % 3]
        k, b = rng.normal(1.001, 0.002, 3), rng.normal(0.0, 0.1 * DEG, 3)
        versions = [(k, b, T0 + timedelta(hours=i))]
        if i % 5 == 2:
            k2 = k + rng.normal(0, K_SIGMA, 3) + (np.array([0.01, 0, 0]) if serial == DRIFTER else 0)
            versions.append((k2, b + rng.normal(0, B_SIGMA, 3), T0 + timedelta(days=1, hours=i)))
        for k_, b_, created in versions:
            doc = _doc(serial, k_, b_, station, limits)
            items.append({"serial": serial, "kind": "calibration.servo", "document": doc, "created": created,
                          "station": station, "verdict": doc["acceptance"]["verdict"]})
        newest[serial] = versions[-1]
    items.append({"serial": "SN000", "kind": "acceptance", "document": {"k": 1}, "created": T0, "verdict": "fail"})
    db = folder / "fleet.db"
    with open_store(db) as st:
        st.add_many(items)
        records = st.list()
    return {"db": db, "limits": limits, "limits_path": folder / "limits.toml", "items": items, "newest": newest,
            "records": [r for r in records if r.kind != "acceptance"]}


def _param(stats: dict, name: str) -> dict:
    return next(p for p in stats["parameters"] if p["name"] == name)


def test_cp_and_cpk_with_their_intervals_follow_the_formulas(fleet):
    stats = fleet_statistics(fleet["records"], fleet["limits"])
    kx = _param(stats, "kx")
    x = np.array([fleet["newest"][s][0][0] for s in sorted(fleet["newest"])])
    n, mean, s = x.size, x.mean(), x.std(ddof=1)
    lsl, usl = 0.996, 1.006
    cp, cpk = (usl - lsl) / (6 * s), min(usl - mean, mean - lsl) / (3 * s)
    chi_lo, chi_hi = sps.chi2.ppf([0.025, 0.975], n - 1)
    se = math.sqrt(1 / (9 * n) + cpk ** 2 / (2 * (n - 1)))  # Bissell (1990)
    z = sps.norm.ppf(0.975)
    assert (kx["n"], kx["low"], kx["high"], kx["unit"]) == (30, lsl, usl, "1")
    assert kx["serials"] == sorted(fleet["newest"])
    assert kx["mean"] == pytest.approx(mean, rel=1e-12) and kx["sd"] == pytest.approx(s, rel=1e-12)
    assert kx["cp"] == pytest.approx(cp, rel=1e-12) and kx["cpk"] == pytest.approx(cpk, rel=1e-12)
    assert kx["cp_ci"] == pytest.approx([cp * math.sqrt(chi_lo / (n - 1)), cp * math.sqrt(chi_hi / (n - 1))], rel=1e-12)
    assert kx["cpk_ci"] == pytest.approx([cpk - z * se, cpk + z * se], rel=1e-12)
    bz = _param(stats, "bz")  # in the limit's unit, deg/s, one-sided bounds both set by max_abs
    xb = np.array([fleet["newest"][s_][1][2] for s_ in sorted(fleet["newest"])]) / DEG
    assert bz["unit"] == "deg/s" and bz["mean"] == pytest.approx(xb.mean(), rel=1e-9)
    assert bz["cp"] == pytest.approx(0.6 / (6 * xb.std(ddof=1)), rel=1e-9)


def test_one_sided_and_degenerate_capability():
    x = [1.0, 2.0, 4.0]
    s = np.std(x, ddof=1)
    upper = capability(x, -math.inf, 5.0)
    assert upper["cp"] is None and upper["cpk"] == pytest.approx((5.0 - 7 / 3) / (3 * s))
    assert capability([1.0], 0, 2)["cpk"] is None and capability([1.0, 1.0], 0, 2)["cp"] is None


def test_the_limits_come_from_the_records_when_no_file_is_given(fleet):
    own = fleet_statistics(fleet["records"])
    given = fleet_statistics(fleet["records"], fleet["limits"])
    for name in ("kx", "by"):
        a, b = _param(own, name), _param(given, name)
        assert (a["low"], a["high"], a["unit"]) == (b["low"], b["high"], b["unit"])
        assert a["cpk"] == pytest.approx(b["cpk"], rel=1e-12)
    assert own["limits"] == "records' acceptance" and given["limits"] == str(fleet["limits_path"])


def test_imr_limits_by_hand(fleet):
    chart = imr_limits([1.0, 3.0, 2.0, 5.0, 4.0])  # moving ranges 2, 1, 3, 1: mean 1.75; centre 3
    assert chart["centre"] == 3.0 and chart["mr_bar"] == 1.75
    assert chart["lcl"] == pytest.approx(3 - 3 * 1.75 / 1.128) and chart["ucl"] == pytest.approx(3 + 3 * 1.75 / 1.128)
    assert imr_limits([0, 0, 0, 0, 10])["out"] == [4] and imr_limits([2.0])["ucl"] is None
    # station B's chart of ky: every calibration made there, in time order
    rows = sorted((it["created"], it["document"]["parameters"]["scale_bias"]["k"][1]) for it in fleet["items"]
                  if it.get("station") == "B" and it["kind"] == "calibration.servo")
    values = [v for _, v in rows]
    chart = _param(fleet_statistics(fleet["records"], fleet["limits"]), "ky")["control"]["B"]
    mr = np.mean(np.abs(np.diff(values)))
    assert chart["values"] == pytest.approx(values, rel=1e-15) and chart["mr_bar"] == pytest.approx(mr)
    assert chart["ucl"] == pytest.approx(np.mean(values) + 3 * mr / 1.128)


def _wilson_root(passed: int, n: int, z: float) -> list[float]:
    """Wilson's interval as the two p where |p_hat - p| = z sqrt(p (1 - p) / n)."""
    f = lambda p: (passed / n - p) ** 2 - z * z * p * (1 - p) / n  # noqa: E731
    p_hat = passed / n
    return [optimize.brentq(f, 1e-12, p_hat), optimize.brentq(f, p_hat, 1 - 1e-12)]


def test_yield_with_the_wilson_interval(fleet):
    stats = fleet_statistics(fleet["records"], fleet["limits"])
    cal = [it for it in fleet["items"] if it["kind"] == "calibration.servo"]
    passed = sum(it["verdict"] == "pass" for it in cal)
    assert 0 < passed < len(cal), "the fleet must hold some failures"
    overall = stats["yield"]["overall"]
    assert (overall["passed"], overall["n"]) == (passed, len(cal))
    assert overall["ci"] == pytest.approx(_wilson_root(passed, len(cal), z := 1.959963984540054), rel=1e-9)
    for station in STATIONS:
        mine = [it for it in cal if it["station"] == station]
        got = stats["yield"]["stations"][station]
        assert got["n"] == len(mine) and got["passed"] == sum(it["verdict"] == "pass" for it in mine)
    assert wilson(0, 0)["yield"] is None and wilson(10, 10)["ci"][1] == pytest.approx(1.0)
    assert wilson(3, 10, 0.9)["ci"] == pytest.approx(_wilson_root(3, 10, sps.norm.ppf(0.95)), rel=1e-9)
    assert z == pytest.approx(sps.norm.ppf(0.975), rel=1e-12)
    kx_yield = _param(stats, "kx")["yield"]
    newest_kx = [fleet["newest"][s][0][0] for s in fleet["newest"]]
    assert kx_yield["n"] == 30 and kx_yield["passed"] == sum(0.996 + 2 * K_SIGMA <= v <= 1.006 - 2 * K_SIGMA
                                                             for v in newest_kx)


def test_the_planted_drift_ranks_first(fleet):
    drift = fleet_statistics(fleet["records"], fleet["limits"])["drift"]
    assert len(drift) == 6 and drift[0]["serial"] == DRIFTER and drift[0]["parameter"] == "kx"
    (old, new) = [it["document"] for it in fleet["items"] if it["serial"] == DRIFTER]
    change = new["parameters"]["scale_bias"]["k"][0] - old["parameters"]["scale_bias"]["k"][0]
    assert drift[0]["z"] == pytest.approx(change / math.hypot(K_SIGMA, K_SIGMA), rel=1e-12)
    assert all(abs(d["z"]) < abs(drift[0]["z"]) / 3 for d in drift[1:])


def test_the_cp_interval_covers_the_true_cp_at_its_nominal_rate():
    rng = np.random.default_rng(7)
    draws, n, sigma, lsl, usl = 2000, 15, 0.5, -2.0, 2.0
    true_cp = (usl - lsl) / (6 * sigma)
    covered = 0
    for x in rng.normal(0.1, sigma, (draws, n)):
        lo, hi = capability(x, lsl, usl, 0.9)["cp_ci"]
        covered += lo <= true_cp <= hi
    band = sps.binom.interval(0.999, draws, 0.9)  # the count a correct 90% interval gives, two-sided
    assert band[0] <= covered <= band[1], (covered, band)


def test_the_command_writes_the_report(fleet, tmp_path):
    out = tmp_path / "report"
    code, stdout, err = invoke("fleet", "--store", fleet["db"], "-o", out, "--limits", fleet["limits_path"])
    assert code == 0, (stdout, err)
    pngs = sorted(out.glob("*.png"))
    assert len(pngs) == 12 and all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)
    summary = (out / SUMMARY).read_text()
    assert "| kx | 1 | 0.996 | 1.006 | 30 |" in summary and f"| {DRIFTER} | kx |" in summary
    assert all(f"({p.name})" in summary for p in pngs)
    assert not list(tmp_path.glob(".*"))  # no temporary left
    code, stdout, err = invoke("fleet", "--store", fleet["db"], "--json", "--since", "2025-03-02T14:00Z", "--kind",
                               "calibration")
    assert code == 0, err
    stats = json.loads(stdout)
    assert stats["units"] == 5 and stats["records"] == 5 and stats["drift"] == [] and stats["limits"] == "records' acceptance"


def test_a_failed_report_leaves_the_folder_as_it_was(fleet, tmp_path, monkeypatch):
    import gyrocal.plotting.fleet as figures

    out = tmp_path / "report"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    stats = fleet_statistics(fleet["records"], fleet["limits"])
    calls = []

    def broken(p):
        calls.append(p["name"])
        if len(calls) == 3:
            raise RuntimeError("disk full")
        return real(p)

    real = figures.control_figure
    monkeypatch.setattr(figures, "control_figure", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        write_report(stats, out)
    assert [p.name for p in tmp_path.iterdir()] == ["report"] and [p.name for p in out.iterdir()] == ["notes.txt"]


def test_bad_input_is_refused_in_one_line(fleet, tmp_path):
    empty = tmp_path / "empty.db"
    open_store(empty).close()
    assert "is empty" in refused("fleet", "--store", empty, "--json")
    only = tmp_path / "other.db"
    with open_store(only) as st:
        st.add("SN1", "acceptance", {"x": 1}, verdict="pass")
    assert "holds no calibration records" in refused("fleet", "--store", only, "--json")
    assert "not a calibration kind" in refused("fleet", "--store", fleet["db"], "--json", "--kind", "refusal")
    assert "holds no 'imu' records" in refused("fleet", "--store", fleet["db"], "--json", "--kind", "imu")
    assert "since" in refused("fleet", "--store", fleet["db"], "--json", "--since", "2030-01-01")
    assert "no store at" in refused("fleet", "--store", tmp_path / "missing.db", "--json")
    assert "-o FOLDER" in refused("fleet", "--store", fleet["db"])
    assert "--confidence must lie" in refused("fleet", "--store", fleet["db"], "--json", "--confidence", "95")
    assert not (tmp_path / "missing.db").exists()
