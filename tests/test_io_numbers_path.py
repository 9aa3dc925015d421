"""The small-table path (numpy's compiled parser, taken by default under a MiB) against the two other
readers, pyarrow's and the pure-Python one, as independent references: same numbers, bit for bit, and
every table it does not take still read as before."""

from __future__ import annotations

import numpy as np
import pytest

from gyrocal.io.csvfile import read_csv_columns

TABLES = {
    "comma": "t,gx,gy,gz\n0.000,-7.22137,0.74809,-2.02290\n0.005,1e-3,-0.0,3.5E+2\n0.010,1,2,3\n",
    "spaced": "t gx gy gz\n0.0  1.5\t2.5 3.5\n0.01 -1 -2 -3\n0.02 4 5 6\n",
    "blank lines": "t,gx,gy,gz\n\n0.0,1,2,3\n\n0.01,4,5,6\n0.02,7,8,9\n",
    "nan cell": "t,gx,gy,gz\n0.0,1,2,3\n0.01,nan,5,6\n0.02,7,8,9\n",
    "text column": "t,gx,gy,gz,note\n0.0,1,2,3,a\n0.01,4,5,6,b\n0.02,7,8,9,c\n",
    "empty cell": "t,gx,gy,gz\n0.0,1,2,3\n0.01,,5,6\n0.02,7,8,9\n",
    "metadata above": "# logger v2\nrate: 100 Hz\nt,gx,gy,gz\n0.0,1,2,3\n0.01,4,5,6\n0.02,7,8,9\n",
    "windows line ends": "t,gx,gy,gz\r\n0.0,1.5,2,3\r\n0.01,4,5,6\r\n0.02,7,8,9.25\r\n",
}


@pytest.mark.parametrize("name", sorted(TABLES))
def test_default_reader_equals_pyarrow_and_python(tmp_path, name):
    path = tmp_path / "log.csv"
    path.write_bytes(TABLES[name].encode())
    default, extra = read_csv_columns(path)
    for forced in (True, False):
        other, other_extra = read_csv_columns(path, use_pyarrow=forced)
        assert sorted(default) == sorted(other) and sorted(extra) == sorted(other_extra)
        for key in default:
            a, b = default[key], other[key]
            assert a.dtype == b.dtype and a.tobytes() == b.tobytes() if a.dtype == np.float64 else list(a) == list(b)


def test_bundled_example_bit_for_bit():
    from gyrocal.cli.calibrate_cmds import _example_paths

    path, _ = _example_paths()
    default, _ = read_csv_columns(path)
    arrow, _ = read_csv_columns(path, use_pyarrow=True)
    assert len(default["gx"]) > 10_000
    for key in ("t", "gx", "gy", "gz"):
        assert default[key].tobytes() == arrow[key].tobytes()
