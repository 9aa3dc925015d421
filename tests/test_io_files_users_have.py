"""Files as users have them: compressed tables, European spreadsheet exports, metadata lines
above the header, tables without a header, numpy and R headers, epoch time stamps.

Every odd file is written here, in the test, from a plain table whose values are known; the
reference is that plain table read by the same reader (or the values themselves).
"""

from __future__ import annotations

import bz2
import gzip
import lzma
import math
import sys
import zipfile

import numpy as np
import pytest

from gyrocal.errors import GyrocalError, InputError, MissingDependencyError
from gyrocal.io import read_recording, write_csv
from gyrocal.io.csvfile import read_csv_columns


def _table(rng, n=300):
    """A 200 Hz table [deg/s]: slow turns with noise, so no unit or saturation check fires."""
    t = np.arange(n) * 0.005
    g = 40.0 * np.sin(np.linspace(0.0, 5.0, n))[:, None] + rng.normal(0.0, 0.5, (n, 3))
    return t, g


def _text(t, g, delimiter=",", decimal=".", header="t,gx,gy,gz"):
    rows = [delimiter.join(repr(float(v)).replace(".", decimal) for v in (ti, *gi)) for ti, gi in zip(t, g)]
    return (header.replace(",", delimiter) + "\n" if header else "") + "\n".join(rows) + "\n"


def _same(data, t, g):
    np.testing.assert_array_equal(data["t"], t)
    np.testing.assert_array_equal(np.column_stack([data["gx"], data["gy"], data["gz"]]), g)


def refused(path, match, exc=InputError, **kwargs):
    kwargs.setdefault("units", "deg/s")
    with pytest.raises(exc, match=match) as info:
        read_recording(path, **kwargs)
    assert isinstance(info.value, GyrocalError) and "\n" not in str(info.value)
    return str(info.value)


# ---------------------------------------------------------------- compression


def _pyarrow_compressed(path, body: bytes, codec: str):
    import pyarrow as pa

    with pa.CompressedOutputStream(str(path), codec) as out:
        out.write(body)


_WRITERS = {
    "gz": lambda p, b: p.write_bytes(gzip.compress(b)),
    "bz2": lambda p, b: p.write_bytes(bz2.compress(b)),
    "xz": lambda p, b: p.write_bytes(lzma.compress(b)),
    "zst": lambda p, b: _pyarrow_compressed(p, b, "zstd"),
    "lz4": lambda p, b: _pyarrow_compressed(p, b, "lz4"),
    "br": lambda p, b: _pyarrow_compressed(p, b, "brotli"),
}


@pytest.mark.parametrize("use_pyarrow", [True, False])
@pytest.mark.parametrize("suffix", list(_WRITERS))
def test_compressed_tables_read_like_the_plain_one(tmp_path, rng, suffix, use_pyarrow):
    t, g = _table(rng)
    path = tmp_path / f"rec.csv.{suffix}"
    _WRITERS[suffix](path, _text(t, g).encode())
    data, _ = read_csv_columns(path, use_pyarrow=use_pyarrow)
    _same(data, t, g)


def test_compression_is_found_by_content_not_only_by_suffix(tmp_path, rng):
    # a gzip file saved as .csv (a browser download) and a zstd one without any suffix
    t, g = _table(rng)
    _WRITERS["gz"](tmp_path / "download.csv", _text(t, g).encode())
    _WRITERS["zst"](tmp_path / "log", _text(t, g).encode())
    for name in ("download.csv", "log"):
        rec = read_recording(tmp_path / name, units="deg/s")
        np.testing.assert_array_equal(np.degrees(rec.gyro), np.radians(g) * (180 / math.pi))
        assert len(rec) == len(t)


def test_zip_with_one_table_reads_and_with_several_is_refused(tmp_path, rng):
    t, g = _table(rng)
    with zipfile.ZipFile(tmp_path / "one.zip", "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("session/rec.csv", _text(t, g))
    _same(read_csv_columns(tmp_path / "one.zip")[0], t, g)
    with zipfile.ZipFile(tmp_path / "two.zip", "w") as z:
        z.writestr("a.csv", _text(t, g))
        z.writestr("b.csv", _text(t, g))
    refused(tmp_path / "two.zip", r"two\.zip: a zip archive holding 2 files \(a\.csv, b\.csv\); unzip it")


def test_damaged_and_binary_files_are_refused_in_one_line(tmp_path, rng):
    t, g = _table(rng, 3000)
    body = gzip.compress(_text(t, g).encode())
    (tmp_path / "cut.csv.gz").write_bytes(body[: len(body) // 2])  # an interrupted download
    refused(tmp_path / "cut.csv.gz", r"cut\.csv\.gz: cannot (decompress it as gzip|parse the table)")
    (tmp_path / "blob.csv").write_bytes(bytes(range(256)) * 4)
    refused(tmp_path / "blob.csv", r"blob\.csv: binary data, not a text table")


def test_zstd_without_pyarrow_names_the_extra(tmp_path, rng, monkeypatch):
    t, g = _table(rng)
    _WRITERS["zst"](tmp_path / "rec.csv.zst", _text(t, g).encode())
    _WRITERS["gz"](tmp_path / "rec.csv.gz", _text(t, g).encode())
    monkeypatch.setitem(sys.modules, "pyarrow", None)  # import pyarrow now raises ImportError
    monkeypatch.setitem(sys.modules, "pyarrow.csv", None)
    refused(tmp_path / "rec.csv.zst", r"rec\.csv\.zst is zstd-compressed; reading it needs pyarrow: "
            r"pip install 'gyrocal\[arrow\]'", MissingDependencyError)
    _same(read_csv_columns(tmp_path / "rec.csv.gz")[0], t, g)  # gzip needs the standard library only


# ---------------------------------------------------------------- European spreadsheet exports


@pytest.mark.parametrize("use_pyarrow", [True, False])
@pytest.mark.parametrize("delimiter", [";", "\t"])
def test_decimal_comma_with_its_separator(tmp_path, rng, delimiter, use_pyarrow):
    t, g = _table(rng)
    path = tmp_path / "export.csv"
    path.write_text(_text(t, g, delimiter=delimiter, decimal=","), encoding="utf-8")
    data, _ = read_csv_columns(path, use_pyarrow=use_pyarrow)
    _same(data, t, g)


@pytest.mark.parametrize("use_pyarrow", [True, False])
def test_decimal_comma_table_with_a_point_is_refused(tmp_path, use_pyarrow):
    # "1.234,5" or "1.234" in a decimal-comma table: a thousands separator, or a mix; never guess
    path = tmp_path / "export.csv"
    path.write_text("t;gx;gy;gz\n0,000;1,5;2,25;3\n0,005;1.234;2,5;3\n0,010;1,5;2,25;3\n")
    with pytest.raises(InputError, match=r"column 'gx' holds '1\.234' at data row 2, but the table writes decimal "
                                         r"commas \(1,5\); a point there may be a thousands separator"):
        read_csv_columns(path, use_pyarrow=use_pyarrow)


def test_comma_separated_file_keeps_its_decimal_comma_hint(tmp_path):
    (tmp_path / "c.csv").write_text('t,gx,gy,gz\n0,1,2,3\n0.01,"1,5",2,3\n')
    refused(tmp_path / "c.csv", r"non-numeric cell '1,5' at data row 2 \(decimal comma\?")


# ---------------------------------------------------------------- lines above the header


def test_logger_metadata_lines_are_skipped(tmp_path, rng):
    t, g = _table(rng)
    lead = "Fs,100\nDevice,MPU9250\nfirmware,1.2.3\nStart,2024-05-01 10:00:00\n\n"
    (tmp_path / "logger.csv").write_text(lead + _text(t, g))
    _same(read_csv_columns(tmp_path / "logger.csv")[0], t, g)
    # metadata with as many fields as the table, but not followed by data, is skipped as well
    (tmp_path / "wide.csv").write_text("Logger,X200,serial,AB12\n" + _text(t, g))
    _same(read_csv_columns(tmp_path / "wide.csv")[0], t, g)


def test_excel_sep_line_names_the_delimiter(tmp_path, rng):
    t, g = _table(rng)
    (tmp_path / "x.csv").write_text("sep=;\n" + _text(t, g, delimiter=";", decimal=","))
    _same(read_csv_columns(tmp_path / "x.csv")[0], t, g)


def test_skip_rows_places_the_header_and_the_message_suggests_it(tmp_path, rng):
    t, g = _table(rng)
    # a preamble that reads like a header followed by data: detection cannot tell, the user can
    lead = "sensor,gyro,range,2000\n0,1,2,3\n"
    (tmp_path / "pre.csv").write_text(lead + _text(t, g))
    msg = refused(tmp_path / "pre.csv", r"no column for gx, gy, gz; columns found \(header on line 1\): 'sensor'")
    assert "skip the lines above it with skip_rows N" in msg
    rec = read_recording(tmp_path / "pre.csv", units="deg/s", skip_rows=2)
    np.testing.assert_array_equal(rec.t, t)
    with pytest.raises(InputError, match=r"skip_rows must be a whole number >= 0, got -1"):
        read_recording(tmp_path / "pre.csv", units="deg/s", skip_rows=-1)
    refused(tmp_path / "pre.csv", r"no header row after skipping 999 line\(s\)", skip_rows=999)


# ---------------------------------------------------------------- no header, numpy and R headers


@pytest.mark.parametrize("use_pyarrow", [True, False])
@pytest.mark.parametrize("delimiter", [",", " ", "\t"])
def test_headerless_table_by_column_number(tmp_path, rng, delimiter, use_pyarrow):
    t, g = _table(rng)
    temp = np.full(len(t), 25.5)
    body = _text(t, np.column_stack([temp, g]), delimiter=delimiter, header="")
    (tmp_path / "serial.txt").write_text(body)
    data, extra = read_csv_columns(tmp_path / "serial.txt", "t=1,gx=3,gy=4,gz=5,temp=2", use_pyarrow=use_pyarrow)
    _same(data, t, g)
    np.testing.assert_array_equal(data["temp"], temp)
    assert extra == {}
    # gyro columns only, no time: the sample rate makes the time base
    rec = read_recording(tmp_path / "serial.txt", units="deg/s", columns={"gx": 3, "gy": 4, "gz": 5}, sample_rate=200)
    assert rec.has_time is False and list(rec.extra) == ["1", "2"]
    refused(tmp_path / "serial.txt", r"column '7' \(given for gz\) is not in the file; columns found \(no header "
            r"row; columns count from 1\): '1', '2', '3', '4', '5'; in columns, give a name or a number from 1 to 5",
            columns="gx=3,gy=4,gz=7")
    refused(tmp_path / "serial.txt", r"no column for gz; .*give them by number, e\.g\. columns gx=2,gy=3,gz=4",
            columns="gx=3,gy=4")


def test_headerless_without_time_suggests_the_sample_rate(tmp_path, rng):
    _, g = _table(rng)
    (tmp_path / "g.txt").write_text("\n".join(" ".join(f"{v:.4f}" for v in row) for row in g) + "\n")
    msg = refused(tmp_path / "g.txt", r"is data, not a header; say which column holds what by number, counting "
                  r"from 1 \(columns gx=1,gy=2,gz=3 with sample_rate HZ\)")
    assert "'t gx gy gz'" in msg


def test_numpy_savetxt_comment_header_and_r_row_names(tmp_path, rng):
    t, g = _table(rng)
    np.savetxt(tmp_path / "np.txt", np.column_stack([t, g]), header="t gx gy gz", fmt="%.17g")
    data, _ = read_csv_columns(tmp_path / "np.txt")
    _same(data, t, g)
    # R's write.csv: quoted names, no name above the row-number column
    rows = "\n".join(f'"{i + 1}",' + ",".join(repr(float(v)) for v in (ti, *gi)) for i, (ti, gi) in enumerate(zip(t, g)))
    (tmp_path / "r.csv").write_text('"t","gx","gy","gz"\n' + rows + "\n")
    data, extra = read_csv_columns(tmp_path / "r.csv")
    _same(data, t, g)
    assert list(extra) == [""] and extra[""][0] == "1"


def test_same_column_for_two_quantities_is_refused(tmp_path, rng):
    t, g = _table(rng)
    (tmp_path / "r.csv").write_text(_text(t, g))
    refused(tmp_path / "r.csv", r"column 'gx' is given for both gx and gy", columns="gx=2,gy=gx,gz=4")


# ---------------------------------------------------------------- epoch time stamps


def test_epoch_time_stamps_give_the_same_calibration(tmp_path):
    """A 200 Hz session stamped from 0 and from 1.7e9 s (float64 stamps, 0.24 us apart at that
    epoch, as time.time() writes them) must give the same windows and parameters.

    Reference: the same session stamped from 0. Before the fix the epoch file's nominal rate read
    199.995 Hz, detection decimated differently and the windows moved. The parameters may differ
    only through the stamps' own resolution: 2.4e-7 s over windows of at least 1 s, < 1e-6 relative.
    """
    from gyrocal.models import ScaleBias
    from gyrocal.pipeline import calibrate
    from gyrocal.simulation import VirtualGyro
    from gyrocal.simulation.servo import ServoProtocol, simulate_servo

    rec, _ = simulate_servo(VirtualGyro(ScaleBias([1.01, 0.99, 1.0], [0.01, -0.02, 0.005]), noise_std=(0.01,) * 3),
                            ServoProtocol(turns=("+x", "-x", "+y", "-y", "+z", "-z")), sample_rate=200.0,
                            rng=np.random.default_rng(3))
    g = np.degrees(rec.gyro)
    runs = {}
    for start in (0.0, 1.7e9, 1_712_345_678.123):
        write_csv(tmp_path / "r.csv", {"t": rec.t + start, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
        r = read_recording(tmp_path / "r.csv", units="deg/s")
        assert r.sample_rate == pytest.approx(200.0, rel=1e-6)
        for ref in ("speed", "angle"):
            kw = {"speed": math.radians(60)} if ref == "speed" else {"angle": 2 * math.pi}
            cal = calibrate(r, output_units="deg/s", **kw).calibration
            runs[start, ref] = ([(w["start"], w["stop"]) for w in cal.windows], cal.model.params)
    for (start, ref), (windows, params) in runs.items():
        base_windows, base_params = runs[0.0, ref]
        assert windows == base_windows, (start, ref)
        np.testing.assert_allclose(params, base_params, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("use_pyarrow", [True, False])
def test_units_row_under_the_header_is_skipped_and_a_bad_first_row_is_not(tmp_path, rng, use_pyarrow):
    t, g = _table(rng)
    (tmp_path / "daq.csv").write_text("Time,gyro_x,gyro_y,gyro_z\n[s],[deg/s],[deg/s],[deg/s]\n" + _text(t, g, header=""))
    _same(read_csv_columns(tmp_path / "daq.csv", use_pyarrow=use_pyarrow)[0], t, g)
    # a first data row of text is not taken for units: it stays data and is reported
    (tmp_path / "bad.csv").write_text("t,gx,gy,gz\n0,oops,x,y\n" + _text(t[1:], g[1:], header=""))
    with pytest.raises(InputError, match=r"column 'gx' holds non-numeric cell 'oops' at data row 1"):
        read_csv_columns(tmp_path / "bad.csv", use_pyarrow=use_pyarrow)


def test_packet_receive_stamps_shared_by_two_samples_are_named(tmp_path):
    """Two samples per USB packet, both stamped with its receive time: the refusal says what the ties are and how
    to read the log (no time column, a declared rate), not to drop half the rows; one repeated row keeps the
    sort-and-drop advice. Reference: how the stamps were made."""
    from gyrocal.io import read_recording

    t = np.repeat(np.arange(200) * 0.02, 2)
    rows = "".join(f"{a:.3f},0.1,0.2,0.3\n" for a in t)
    path = tmp_path / "pairs.csv"
    path.write_text("t,gx,gy,gz\n" + rows)
    with pytest.raises(InputError, match="samples of one packet stamped with its receive time"):
        read_recording(path, units="deg/s")
    single = tmp_path / "one.csv"
    single.write_text("t,gx,gy,gz\n" + "".join(f"{a:.3f},0.1,0.2,0.3\n" for a in [0.0, 0.01, 0.01, *np.arange(3, 200) * 0.01]))
    with pytest.raises(InputError, match="sort the log and drop repeated rows"):
        read_recording(single, units="deg/s")
