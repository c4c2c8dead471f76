"""Reader for ``sensor_msgs/LaserScan`` (+ ``nav_msgs/Odometry``) in ROS 1 and ROS 2 bags.

Needs the optional extra ``rosbag`` (the pure-Python `rosbags
<https://gitlab.com/ternaris/rosbags>`_ package): ``pip install ndtgrid[rosbag]``. A ROS 1
bag is a ``.bag`` file, a ROS 2 bag the directory holding ``metadata.yaml``.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Generator
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from .scan import Scan

__all__ = ["LASER_SCAN", "ODOMETRY", "read_rosbag"]

#: ROS message type of laser scans.
LASER_SCAN = "sensor_msgs/msg/LaserScan"
#: ROS message type of odometry.
ODOMETRY = "nav_msgs/msg/Odometry"

F64 = npt.NDArray[np.float64]


def _rosbags() -> Any:
    try:
        from rosbags import highlevel, typesys
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "reading ROS bags needs the optional 'rosbags' package: pip install ndtgrid[rosbag]"
        ) from exc
    return highlevel, typesys


def read_rosbag(
    path: str | os.PathLike[str],
    *,
    scan_topic: str | None = None,
    odom_topic: str | None = None,
    use_odom: bool = True,
) -> Generator[Scan, None, None]:
    """Read the laser scans of a ROS 1 or ROS 2 bag, in time order.

    Parameters
    ----------
    path : str or os.PathLike
        A ROS 1 ``.bag`` file or a ROS 2 bag directory.
    scan_topic : str, optional
        Topic of the ``sensor_msgs/LaserScan`` messages; by default the only such topic.
    odom_topic : str, optional
        Topic of the ``nav_msgs/Odometry`` messages; by default the only such topic, if any.
    use_odom : bool, default True
        Attach odometry to the scans. ``False`` leaves ``odom`` ``None``.

    Returns
    -------
    Generator[Scan, None, None]
        One :class:`~ndtgrid.io.Scan` per message: ``timestamp`` the header stamp [s];
        ``ranges`` (B,) [m] as float64; ``angles`` (B,) ``angle_min + i * angle_increment``
        [rad]; ``max_range`` ``range_max`` (``None`` unless positive); ``odom`` (3,) the
        odometry pose ``[x, y, yaw]`` of ``pose.pose`` interpolated linearly (yaw along the
        shorter arc) at the scan's stamp, or ``None`` without odometry or when the stamp
        lies outside the odometry's time span; ``laser_pose`` ``None`` (``/tf`` is not
        read: the scan frame's offset from the odometry frame is not applied);
        ``source`` the topic; ``line`` the 1-based index of the message on its topic.

    Raises
    ------
    ImportError
        If ``rosbags`` is not installed (names ``pip install ndtgrid[rosbag]``).
    FileNotFoundError
        If ``path`` does not exist (raised by this call, before iterating).
    ValueError
        If ``path`` is a directory without ``metadata.yaml`` (raised by this call), or,
        when iterating starts, not a bag rosbags can open (``"{path}: not a readable ROS
        bag: ..."``); if there is no LaserScan topic or several and ``scan_topic`` is not
        given (the message lists them), if a named topic is missing or of another type,
        or if several Odometry topics exist and ``odom_topic`` is not given.

    Notes
    -----
    The odometry messages are read first (a (T, 4) array), then the scans are streamed.
    ROS 2 bags without embedded message definitions are read with the ROS 2 Humble types.
    """
    highlevel, typesys = _rosbags()
    p = Path(os.fspath(path))
    if not p.exists():
        raise FileNotFoundError(f"{p}: no such file or directory")
    if p.is_dir() and not (p / "metadata.yaml").is_file():
        raise ValueError(f"{p}: a directory without metadata.yaml is not a ROS 2 bag")
    return _scans(highlevel, typesys, p, scan_topic, odom_topic, use_odom)


def _pick(reader: Any, msgtype: str, topic: str | None, required: bool) -> list[Any]:
    """Connections of the chosen topic of ``msgtype`` (empty when none and not required)."""
    by_topic: dict[str, list[Any]] = {}
    for c in reader.connections:
        by_topic.setdefault(c.topic, []).append(c)
    typed = sorted(t for t, cs in by_topic.items() if cs[0].msgtype == msgtype)
    if topic is not None:
        if topic not in by_topic:
            raise ValueError(f"topic {topic!r} is not in the bag (topics: {sorted(by_topic)})")
        if by_topic[topic][0].msgtype != msgtype:
            raise ValueError(
                f"topic {topic!r} holds {by_topic[topic][0].msgtype}, expected {msgtype}"
            )
        return by_topic[topic]
    if len(typed) == 1:
        return by_topic[typed[0]]
    if not typed and not required:
        return []
    kind = msgtype.split("/")[-1]
    which = "no" if not typed else f"several ({typed})"
    arg = "scan_topic" if msgtype == LASER_SCAN else "odom_topic"
    raise ValueError(f"the bag has {which} {kind} topics; name one with {arg}=")


def _stamp(msg: Any) -> float:
    stamp = msg.header.stamp
    return float(stamp.sec) + 1e-9 * float(stamp.nanosec)


def _odometry(reader: Any, connections: list[Any]) -> F64:
    rows = []
    for conn, _, raw in reader.messages(connections=connections):
        msg = reader.deserialize(raw, conn.msgtype)
        q = msg.pose.pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        pos = msg.pose.pose.position
        rows.append((_stamp(msg), pos.x, pos.y, yaw))
    table = np.array(rows, dtype=np.float64).reshape(-1, 4)
    table = table[np.argsort(table[:, 0], kind="stable")]
    table[:, 3] = np.unwrap(table[:, 3])
    return table


def _odom_at(table: F64, t: float) -> F64 | None:
    if table.shape[0] == 0 or not table[0, 0] <= t <= table[-1, 0]:
        return None
    x, y, yaw = (float(np.interp(t, table[:, 0], table[:, i])) for i in (1, 2, 3))
    return np.array([x, y, math.atan2(math.sin(yaw), math.cos(yaw))])


def _scans(
    highlevel: Any,
    typesys: Any,
    path: Path,
    scan_topic: str | None,
    odom_topic: str | None,
    use_odom: bool,
) -> Generator[Scan, None, None]:
    store = typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
    reader = highlevel.AnyReader([path], default_typestore=store)
    try:
        reader.open()
    except highlevel.AnyReaderError as exc:
        raise ValueError(f"{path}: not a readable ROS bag: {exc}") from exc
    with contextlib.closing(reader):
        scans = _pick(reader, LASER_SCAN, scan_topic, required=True)
        odom_conns = _pick(reader, ODOMETRY, odom_topic, required=False) if use_odom else []
        table = _odometry(reader, odom_conns) if odom_conns else np.zeros((0, 4))
        angle_cache: dict[tuple[float, float, int], F64] = {}
        for number, (conn, _, raw) in enumerate(reader.messages(connections=scans), start=1):
            msg = reader.deserialize(raw, conn.msgtype)
            ranges = np.asarray(msg.ranges, dtype=np.float64)
            key = (float(msg.angle_min), float(msg.angle_increment), ranges.shape[0])
            if key not in angle_cache:
                angle_cache[key] = key[0] + np.arange(key[2], dtype=np.float64) * key[1]
            t = _stamp(msg)
            range_max = float(msg.range_max)
            yield Scan(
                timestamp=t,
                ranges=ranges,
                angles=angle_cache[key],
                odom=_odom_at(table, t),
                max_range=range_max if range_max > 0.0 and math.isfinite(range_max) else None,
                source=conn.topic,
                line=number,
            )
