"""Parquet and ROS bags (ROS 1, ROS 2 SQLite, MCAP) read back into recordings; the CSV writer.

References: the arrays written with pyarrow and rosbags' own writers, read back by gyrocal; Python's csv
module for the writer.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from gyrocal.errors import InputError
from gyrocal.io import read_recording, write_csv


def test_parquet_round_trip(tmp_path, rng):
    n = 64
    g = rng.normal(0, 0.02, (n, 3)) + [0.5, -1.0, 2.0]  # constant turns with MEMS-like noise [rad/s]
    t = 1000.0 + np.arange(n) / 200.0
    table = pa.table({"time": t, "gyro_x": g[:, 0], "gyro_y": g[:, 1], "gyro_z": g[:, 2],
                      "temp": np.full(n, 31.5), "counter": np.arange(n, dtype=np.int32)})
    pq.write_table(table, tmp_path / "rec.parquet")
    rec = read_recording(tmp_path / "rec.parquet", units="rad/s")
    np.testing.assert_array_equal(rec.t, t)
    np.testing.assert_array_equal(rec.gyro, g)
    np.testing.assert_array_equal(rec.temp, 31.5)
    np.testing.assert_array_equal(rec.extra["counter"], np.arange(n))


def test_parquet_timestamp_and_text_columns(tmp_path):
    stamps = np.array([0, 5_000_000, 10_000_000], dtype="datetime64[ns]")
    pq.write_table(pa.table({"t": stamps, "gx": ["1", "2", "3"], "gy": [0.0] * 3, "gz": [0.0] * 3}), tmp_path / "a.parquet")
    rec = read_recording(tmp_path / "a.parquet", units="rad/s")
    np.testing.assert_allclose(rec.t, [0.0, 0.005, 0.01])
    np.testing.assert_array_equal(rec.gyro[:, 0], [1.0, 2.0, 3.0])
    pq.write_table(pa.table({"gx": ["1", "x"], "gy": [0.0] * 2, "gz": [0.0] * 2}), tmp_path / "b.parquet")
    with pytest.raises(InputError, match="column 'gx' holds non-numeric cell 'x' at data row 2"):
        read_recording(tmp_path / "b.parquet", units="rad/s", sample_rate=10)


def _imu_messages(typestore, n, ros1=False):
    """Serialised Imu messages with stamps 100 s + 10 ms * i and known rates [rad/s]."""
    types = typestore.types
    header_kw = {"seq": 0} if ros1 else {}
    rates = np.column_stack([0.01 * np.arange(n), np.full(n, -0.2), np.full(n, 0.3)])
    out = []
    for i in range(n):
        msg = types["sensor_msgs/msg/Imu"](
            header=types["std_msgs/msg/Header"](
                **header_kw, stamp=types["builtin_interfaces/msg/Time"](sec=100, nanosec=10_000_000 * i), frame_id="imu"
            ),
            orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=np.zeros(9),
            angular_velocity=types["geometry_msgs/msg/Vector3"](x=rates[i, 0], y=rates[i, 1], z=rates[i, 2]),
            angular_velocity_covariance=np.zeros(9),
            linear_acceleration=types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=9.81),
            linear_acceleration_covariance=np.zeros(9),
        )
        raw = typestore.serialize_ros1(msg, msg.__msgtype__) if ros1 else typestore.serialize_cdr(msg, msg.__msgtype__)
        out.append((1_000_000_000 + i, raw))
    return rates, out


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_ros2_bags(tmp_path, storage):
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    rates, msgs = _imu_messages(ts, 30)
    bag = tmp_path / "bag"
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(bag, version=9, storage_plugin=plugin) as writer:
        conn = writer.add_connection("/imu/data", "sensor_msgs/msg/Imu", typestore=ts)
        other = writer.add_connection("/imu2", "sensor_msgs/msg/Imu", typestore=ts)
        for stamp, raw in msgs:
            writer.write(conn, stamp, raw)
            writer.write(other, stamp, raw)
    with pytest.raises(InputError, match="several Imu topics \\(/imu/data, /imu2\\)"):
        read_recording(bag, units="rad/s")
    with pytest.raises(InputError, match="topic '/cam' holds no Imu messages; Imu topics found: /imu/data, /imu2"):
        read_recording(bag, units="rad/s", topic="/cam")
    single = next(bag.glob("*.db3" if storage == "sqlite3" else "*.mcap"))
    for path in (bag, single):
        rec = read_recording(path, units="rad/s", topic="/imu/data")
        np.testing.assert_allclose(rec.gyro, rates)
        np.testing.assert_allclose(rec.t - 100.0, 0.01 * np.arange(30), atol=1e-6)
        assert rec.has_time and rec.sample_rate == pytest.approx(100.0)


def test_ros1_bag(tmp_path):
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    rates, msgs = _imu_messages(ts, 20, ros1=True)
    with Writer(tmp_path / "r.bag") as writer:
        conn = writer.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=ts)
        for stamp, raw in msgs:
            writer.write(conn, stamp, raw)
    rec = read_recording(tmp_path / "r.bag", units="rad/s")
    np.testing.assert_allclose(rec.gyro, rates)
    assert rec.sample_rate == pytest.approx(100.0)


def test_bag_without_imu_lists_topics(tmp_path):
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    with Writer(tmp_path / "s.bag") as writer:
        conn = writer.add_connection("/chatter", "std_msgs/msg/String", typestore=ts)
        writer.write(conn, 1, ts.serialize_ros1(ts.types["std_msgs/msg/String"](data="hi"), "std_msgs/msg/String"))
    with pytest.raises(InputError, match=r"no sensor_msgs/Imu topic; topics found: /chatter \(std_msgs/msg/String\)"):
        read_recording(tmp_path / "s.bag", units="rad/s")


def test_write_csv_keeps_order_and_exact_floats(tmp_path, rng):
    cols = {"z": rng.normal(size=7), "a": np.arange(7), "label": np.array(list("abcdefg"))}
    write_csv(tmp_path / "o.csv", cols)
    lines = (tmp_path / "o.csv").read_text().splitlines()
    assert lines[0] == "z,a,label" and lines[1].endswith(",0,a")
    np.testing.assert_array_equal([float(line.split(",")[0]) for line in lines[1:]], cols["z"])
    numeric = {"t": np.array([0.0, 0.1, 1 / 3]), "gx": np.array([1e-5, -2.5, 3e300])}
    write_csv(tmp_path / "n.csv", numeric)  # the pyarrow path when installed
    back = np.loadtxt(tmp_path / "n.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(back, np.column_stack(list(numeric.values())))


def test_write_csv_refuses_ragged_columns_and_leaves_nothing(tmp_path):
    with pytest.raises(InputError, match="equal length"):
        write_csv(tmp_path / "o.csv", {"a": [1, 2], "b": [1]})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("arrow", [True, False], ids=["pyarrow", "python"])
def test_csv_writer_streams_chunks_and_reads_back_exactly(tmp_path, rng, monkeypatch, arrow):
    """Reference: Python's csv module reading the file back, and the arrays written."""
    import csv

    from gyrocal.io import writer

    monkeypatch.setattr(writer, "CHUNK_ROWS", 7)  # many chunks, one short at the end
    if not arrow:
        monkeypatch.setattr(writer, "_arrow_chunk_writer", lambda: writer._python_chunk)
    n = 40
    x = rng.normal(size=n) * 10.0 ** rng.integers(-300, 300, n)
    text = np.array(["x", "y", "z", "a,b", 'say "hi"'] * 8)
    flags = np.arange(n) % 3 == 0
    out = tmp_path / "w.csv"
    write_csv(out, {"x": x, "label": text, "flag": flags, "i": np.arange(n)}, header_comment="two\nlines")
    lines = out.read_text().splitlines()
    assert lines[:3] == ["# two", "# lines", "x,label,flag,i"]
    rows = list(csv.reader(lines[3:]))
    assert len(rows) == n
    np.testing.assert_array_equal([float(r[0]) for r in rows], x)
    assert [r[1] for r in rows] == text.tolist()
    assert [r[2] for r in rows] == ["1" if f else "0" for f in flags]
    assert [int(r[3]) for r in rows] == list(range(n))
    plain = tmp_path / "plain.csv"
    write_csv(plain, {"axis": np.array(["x", "y"] * 10), "v": np.zeros(20)})
    assert plain.read_text().splitlines()[1] in ("x,0", "x,0.0")  # no quotes where none are needed
