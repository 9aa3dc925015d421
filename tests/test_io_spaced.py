"""Whitespace-separated tables: the compiled reader (pyarrow kernels) against the pure-Python one.

Reference: the pure-Python reader (``use_pyarrow=False``), which splits each line with ``str.split``.
Both round each decimal cell to the nearest double, so the numbers agree to the last bit.
"""

from __future__ import annotations

import gzip

import numpy as np
import pytest

from gyrocal.errors import InputError
from gyrocal.io.csvfile import read_csv_columns


def _both(path, columns=None):
    fast, slow = (read_csv_columns(path, columns, use_pyarrow=u) for u in (True, False))
    for got, want in zip(fast, slow):
        assert list(got) == list(want)
        for name in want:
            if want[name].dtype == np.float64:
                np.testing.assert_array_equal(got[name], want[name])
            else:
                assert [str(v) for v in got[name]] == [str(v) for v in want[name]]
    return fast


def _rows(rng, n=50):
    return np.column_stack([np.arange(n) * 0.005, rng.normal(0.0, 30.0, (n, 3))])


def test_runs_of_spaces_and_tabs_blank_lines_and_crlf(tmp_path, rng):
    rows = _rows(rng)
    lines = [f"  {t!r} \t {x!r}   {y!r}\t{z!r}  " for t, x, y, z in rows.tolist()]
    lines[10:10] = ["", "   \t "]  # blank lines inside the data are no rows
    path = tmp_path / "spaced.txt"
    path.write_bytes(("t gx gy gz\r\n" + "\r\n".join(lines) + "\r\n").encode())
    data, extra = _both(path)
    np.testing.assert_array_equal(np.column_stack([data[c] for c in ("t", "gx", "gy", "gz")]), rows)
    assert extra == {}


def test_imu_tk_headerless_gzip_and_comment_header(tmp_path, rng):
    rows = _rows(rng)
    body = "".join(f"  {t:.6f}  {x:.9f}  {y:.9f}  {z:.9f}\n" for t, x, y, z in rows)
    path = tmp_path / "gyro.mat.gz"
    path.write_bytes(gzip.compress(("# imu_tk gyro log\n" + body).encode()))
    data, _ = _both(path, "t=1,gx=2,gy=3,gz=4")
    np.testing.assert_allclose(data["gx"], rows[:, 1], atol=0.5e-9)  # written with 9 decimals


def test_text_columns_missing_cells_and_latin1(tmp_path, rng):
    rows = _rows(rng, 6)
    axis = ["x", "x", "y", "y", "z", "z"]
    note = ["caf\xe9", "a", "b", "c", "d", "e"]
    lines = [f"{t!r} {x!r} {y!r} {'nan' if i == 3 else repr(z)} {a} {n}"
             for i, ((t, x, y, z), a, n) in enumerate(zip(rows.tolist(), axis, note))]
    path = tmp_path / "mixed.txt"
    path.write_bytes(("t gx gy gz axis note\n" + "\n".join(lines) + "\n").encode("latin-1"))
    (data, extra), (slow, _) = (read_csv_columns(path, use_pyarrow=u) for u in (True, False))
    np.testing.assert_array_equal(data["gz"], slow["gz"])
    assert list(data["axis"]) == axis and np.isnan(data["gz"][3])
    assert list(extra["note"]) == note  # read as latin-1, as the CSV reader does (the Python one writes U+FFFD)


def test_decimal_commas_between_spaces(tmp_path, rng):
    rows = np.round(_rows(rng), 4)
    text = "t gx gy gz\n" + "".join(" ".join(f"{v:.4f}".replace(".", ",") for v in r) + "\n" for r in rows)
    (tmp_path / "comma.txt").write_text(text)
    data, _ = _both(tmp_path / "comma.txt")
    np.testing.assert_array_equal(data["gy"], rows[:, 2])


@pytest.mark.parametrize("bad, message", [
    ("0.02 1 2", r"data row 3 has 3 fields, the header has 4"),
    ("0.02 1 2 3 4", r"data row 3 has 5 fields, the header has 4"),
    ("0.02 1 two 3", r"column 'gy' holds non-numeric cell 'two' at data row 3"),
])
def test_bad_rows_are_refused_alike(tmp_path, bad, message):
    path = tmp_path / "bad.txt"
    path.write_text("t gx gy gz\n0 1 2 3\n\n0.01 1 2 3\n" + bad + "\n0.03 1 2 3\n")
    for use_pyarrow in (True, False):
        with pytest.raises(InputError, match=message):
            read_csv_columns(path, use_pyarrow=use_pyarrow)


def test_header_only_and_utf16(tmp_path, rng):
    (tmp_path / "empty.txt").write_text("t gx gy gz\n")
    data, _ = _both(tmp_path / "empty.txt")
    assert all(len(v) == 0 for v in data.values())
    rows = _rows(rng, 10)
    text = "t gx gy gz\n" + "".join(" ".join(map(repr, r)) + "\n" for r in rows.tolist())
    (tmp_path / "u16.txt").write_bytes(text.encode("utf-16"))
    data, _ = _both(tmp_path / "u16.txt")
    np.testing.assert_array_equal(data["gz"], rows[:, 3])


def _imu_tk(rows) -> str:
    return "".join(f"  {t:.6f}  {x:.9g}  {y:.9g}  {z:.9g}\n" for t, x, y, z in rows)


def test_one_spacing_throughout_takes_the_multithreaded_parser(tmp_path, rng, monkeypatch):
    """imu_tk's two spaces before each field: read by pyarrow's CSV parser with a space as delimiter
    (the line-splitting route is not called), to the same bits as the Python reader."""
    import gyrocal.io._spaced as spaced

    rows = _rows(rng, 3000)
    path = tmp_path / "gyro.txt"
    path.write_text(_imu_tk(rows))

    def not_called(*args, **kwargs):
        raise AssertionError("the line-splitting route read a file of one spacing")

    monkeypatch.setattr(spaced, "spaced_pieces", not_called)
    data, _ = _both(path, "t=1,gx=2,gy=3,gz=4")
    np.testing.assert_allclose(data["gx"], rows[:, 1], rtol=1e-8)  # written with 9 digits


@pytest.mark.parametrize("late, message", [
    ("  9.000000 1 2 3\n", None),  # other spacing: the line-splitting route reads it all
    ("5  9.000000  1  2  3\n", r"has 5 fields, the header has 4"),  # a field in a gap
    ("  9.000000  1    3\n", r"has 3 fields, the header has 4"),  # a field missing
    ("nan  9.000000  1  2  3\n", r"has 5 fields, the header has 4"),  # "nan" in a gap is a field too
])
def test_a_line_past_the_sample_that_departs_from_its_spacing(tmp_path, rng, late, message):
    """Beyond the first 64 KiB the parser's delimiter meets a line of other spacing: the table is read by
    the line-splitting route, with the same numbers and the same refusals as the Python reader."""
    rows = _rows(rng, 3000)
    text = _imu_tk(rows)
    assert len(text.encode()) > 2 * 65536
    path = tmp_path / "gyro.txt"
    path.write_text(text + late + _imu_tk(rows[:5]))
    if message is None:
        data, _ = _both(path, "t=1,gx=2,gy=3,gz=4")
        assert len(data["t"]) == 3006 and data["t"][3000] == 9.0
        return
    for use_pyarrow in (True, False):
        with pytest.raises(InputError, match=message):
            read_csv_columns(path, "t=1,gx=2,gy=3,gz=4", use_pyarrow=use_pyarrow)


def _aligned(rows, end="\n") -> str:
    """Columns aligned by padding: the runs of spaces vary with each number's width. 64 bytes a line, so
    lines end exactly where the reader's 1 MiB blocks do."""
    return "".join(f"{t:12.6f} {x:16.9g} {y:16.9g} {z:16.9g}{end}" for t, x, y, z in rows)


def _loadtxt_equal(data, path, skip=0):
    """numpy's own whitespace parser as a second, independent reference."""
    ref = np.loadtxt(path, skiprows=skip)
    for j, c in enumerate(("t", "gx", "gy", "gz")):
        np.testing.assert_array_equal(data[c], ref[:, j])


@pytest.mark.parametrize("end, header", [("\n", ""), ("\r\n", "t gx gy gz\r\n")])
def test_aligned_columns_over_many_blocks_are_split_into_one_allocation(tmp_path, rng, monkeypatch, end, header):
    """Varying spacing, 2.5 MiB (blocks end on line ends), a blank line and no newline at the end: split on
    every core straight into the arrays (the piecewise route is not called), the same bits as the Python
    reader and numpy.loadtxt; the rates share one (3, N) block."""
    import gyrocal.io._spaced as spaced

    rows = _rows(rng, 41_000)
    text = header + _aligned(rows[:20_000], end) + end + _aligned(rows[20_000:], end)
    path = tmp_path / "aligned.txt"
    path.write_bytes(text[: -len(end)].encode())
    assert len(text.encode()) > 2 * (1 << 20)

    def not_called(*args, **kwargs):
        raise AssertionError("the piecewise route read a table of numbers")

    monkeypatch.setattr(spaced, "spaced_pieces", not_called)
    data, _ = _both(path, None if header else "t=1,gx=2,gy=3,gz=4")
    _loadtxt_equal(data, path, skip=1 if header else 0)
    assert len(data["t"]) == 41_000
    assert data["gx"].base is not None and data["gx"].base is data["gz"].base


@pytest.mark.parametrize("late, message", [
    ("   9.000000 1 2\n", r"data row 30001 has 3 fields, the header has 4"),
    ("   9.000000 1 2 3 4\n", r"data row 30001 has 5 fields, the header has 4"),
    ("   9.000000 1 two 3\n", r"column 'gy' holds non-numeric cell 'two' at data row 30001"),
])
def test_aligned_columns_refuse_a_bad_row_by_its_number(tmp_path, rng, late, message):
    """A bad row in the second MiB is named by its row in the file, as the Python reader names it."""
    rows = _rows(rng, 40_000)
    path = tmp_path / "aligned.txt"
    path.write_text("t gx gy gz\n" + _aligned(rows[:30_000]) + late + _aligned(rows[30_000:]))
    for use_pyarrow in (True, False):
        with pytest.raises(InputError, match=message):
            read_csv_columns(path, use_pyarrow=use_pyarrow)


@pytest.mark.parametrize("kind", ["latin-1 note", "bare CR"])
def test_aligned_columns_the_block_reader_cannot_take_are_read_as_before(tmp_path, rng, kind):
    """Bytes that are not UTF-8, and old Mac line ends: the block reader declines, the other routes read
    the file, with the Python reader's numbers."""
    rows = _rows(rng, 2000)
    path = tmp_path / "aligned.txt"
    if kind == "bare CR":
        path.write_bytes(("t gx gy gz\r" + _aligned(rows, "\r")).encode())
        data, _ = _both(path)
    else:
        path.write_bytes(("t gx gy gz note\n" + _aligned(rows).replace("\n", " caf\xe9\n")).encode("latin-1"))
        data, extra = read_csv_columns(path)
        assert set(extra["note"]) == {"caf\xe9"}
    np.testing.assert_allclose(data["gy"], rows[:, 2], rtol=1e-8)
