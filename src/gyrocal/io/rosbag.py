"""``sensor_msgs/Imu`` topics of ROS 1 bags, ROS 2 bags (SQLite or MCAP), via ``rosbags``."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import InputError, MissingDependencyError

__all__ = ["read_bag_columns", "IMU_TYPES"]

IMU_TYPES = ("sensor_msgs/msg/Imu", "sensor_msgs/Imu")


def _pick_topic(connections, topic: str | None, source: str) -> list:
    imu = [c for c in connections if c.msgtype in IMU_TYPES]
    topics = sorted({c.topic for c in imu})
    if not imu:
        found = ", ".join(sorted({f"{c.topic} ({c.msgtype})" for c in connections})) or "none"
        raise InputError(f"{source}: no sensor_msgs/Imu topic; topics found: {found}")
    if topic is None:
        if len(topics) > 1:
            raise InputError(f"{source}: several Imu topics ({', '.join(topics)})", param="topic",
                             hint="choose one with {param}")
        return imu
    chosen = [c for c in imu if c.topic == topic]
    if not chosen:
        raise InputError(f"{source}: topic {topic!r} holds no Imu messages; Imu topics found: {', '.join(topics)}")
    return chosen


def read_bag_columns(path: str | os.PathLike, topic: str | None = None, *, accel: bool = False):
    """Angular velocity and header stamps of one Imu topic.

    Parameters
    ----------
    path : path-like
        A ROS 1 ``.bag``, a ROS 2 bag folder, or its ``.db3`` / ``.mcap`` file.
    topic : str, optional
        Needed when several topics carry Imu messages.
    accel : bool
        Return the accelerometer readings too.

    Returns
    -------
    data : dict
        ``t`` [s] (header stamps; the bag's receive times when every stamp is zero) and
        ``gx, gy, gz`` (``angular_velocity``, in whatever unit the publisher used) and
        with `accel`, ``ax, ay, az`` (``linear_acceleration``, m/s^2 by the message's definition).
    extra : dict
        Empty.
    """
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise MissingDependencyError("reading ROS bags needs rosbags: pip install 'gyrocal[ros]'") from None
    path = Path(path)
    stamps, logtimes, rates, accels = [], [], [], []
    try:
        with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
            chosen = _pick_topic(reader.connections, topic, path.name)
            for conn, logtime, raw in reader.messages(connections=chosen):
                msg = reader.deserialize(raw, conn.msgtype)
                stamps.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
                logtimes.append(logtime)
                w = msg.angular_velocity
                rates.append((w.x, w.y, w.z))
                a = msg.linear_acceleration
                accels.append((a.x, a.y, a.z))
    except InputError:
        raise
    except Exception as exc:  # rosbags' own errors: unreadable or unknown bag layout
        raise InputError(f"{path.name}: cannot read the bag ({type(exc).__name__}: {exc})") from None
    ns = np.asarray(stamps if any(stamps) else logtimes, dtype=np.int64)
    if len(ns) == 0:
        raise InputError(f"{path.name}: the Imu topic holds no messages")
    t = ns * 1e-9  # float64 keeps ~0.2 us at today's epoch: ample for IMU rates
    g, a = np.asarray(rates, dtype=float), np.asarray(accels, dtype=float)
    data = {"t": t, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]}
    if accel:
        data.update(ax=a[:, 0], ay=a[:, 1], az=a[:, 2])
    return data, {}
