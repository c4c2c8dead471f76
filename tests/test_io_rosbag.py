"""Tests of ``ndtgrid.io.read_rosbag`` on ROS 1 and ROS 2 bags written with rosbags' writers."""

from __future__ import annotations

import inspect
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ndtgrid.io import read_log, read_rosbag

rosbags = pytest.importorskip("rosbags")
from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

STORE = get_typestore(Stores.ROS2_HUMBLE)
T = STORE.types
SCAN_T = 100.0  # first scan stamp [s]


def header(t: float, frame: str) -> Any:
    sec = math.floor(t)
    return T["std_msgs/msg/Header"](
        stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=round((t - sec) * 1e9)),
        frame_id=frame,
    )


def laser(t: float, ranges: list[float]) -> Any:
    return T["sensor_msgs/msg/LaserScan"](
        header=header(t, "laser"),
        angle_min=-1.0,
        angle_max=1.0,
        angle_increment=2.0 / (len(ranges) - 1),
        time_increment=0.0,
        scan_time=0.1,
        range_min=0.05,
        range_max=8.0,
        ranges=np.asarray(ranges, dtype=np.float32),
        intensities=np.zeros(0, dtype=np.float32),
    )


def odometry(t: float, x: float, y: float, yaw: float) -> Any:
    pose = T["geometry_msgs/msg/Pose"](
        position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
        orientation=T["geometry_msgs/msg/Quaternion"](
            x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)
        ),
    )
    twist = T["geometry_msgs/msg/Twist"](
        linear=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
        angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
    )
    return T["nav_msgs/msg/Odometry"](
        header=header(t, "odom"),
        child_frame_id="base_link",
        pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=np.zeros(36)),
    )


def messages(with_odom: bool = True) -> list[tuple[str, str, float, Any]]:
    out = []
    for k in range(5):
        t = SCAN_T + 0.1 * k + 0.05
        out.append(("/scan", "sensor_msgs/msg/LaserScan", t, laser(t, [1.0 + k, 2.0, 3.0])))
    if with_odom:
        for k in range(7):  # 0.1 m and 0.2 rad per 0.1 s, from t = 100.0
            t = SCAN_T + 0.1 * k
            out.append(("/odom", "nav_msgs/msg/Odometry", t, odometry(t, 0.1 * k, 0.0, 0.2 * k)))
    return sorted(out, key=lambda m: m[2])


def ros2_writer(path: Path) -> Any:
    """A ROS 2 bag writer: rosbags 0.10 on asks which bag version to write (9, the
    newest), 0.9 (the last for Python 3.9) writes its own."""
    if "version" in inspect.signature(Writer2).parameters:
        return Writer2(path, version=9)
    return Writer2(path)  # type: ignore[call-arg]  # rosbags 0.9


def write_bag(path: Path, version: int, msgs: list[tuple[str, str, float, Any]]) -> Path:
    writer = Writer1(path) if version == 1 else ros2_writer(path)
    with writer:
        conns: dict[str, Any] = {}
        for topic, msgtype, t, msg in msgs:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=STORE)
            data = (
                STORE.serialize_ros1(msg, msgtype)
                if version == 1
                else STORE.serialize_cdr(msg, msgtype)
            )
            writer.write(conns[topic], int(t * 1e9), data)
    return path


@pytest.mark.parametrize("version", [1, 2])
def test_scans_and_interpolated_odometry(tmp_path: Path, version: int) -> None:
    path = write_bag(tmp_path / ("b.bag" if version == 1 else "b2"), version, messages())
    scans = list(read_rosbag(path))
    assert len(scans) == 5
    first = scans[0]
    assert first.timestamp == pytest.approx(100.05)
    np.testing.assert_allclose(first.ranges, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(first.angles, [-1.0, 0.0, 1.0], atol=1e-6)
    assert first.max_range == pytest.approx(8.0)
    assert first.source == "/scan" and [s.line for s in scans] == [1, 2, 3, 4, 5]
    # Halfway between odometry poses k = 0 and 1: x 0.05 m, yaw 0.1 rad.
    assert first.odom is not None
    np.testing.assert_allclose(first.odom, [0.05, 0.0, 0.1], atol=1e-9)
    assert scans[4].odom is not None
    np.testing.assert_allclose(scans[4].odom, [0.45, 0.0, 0.9], atol=1e-9)
    assert [s.ranges[0] for s in read_log(path)] == [1.0, 2.0, 3.0, 4.0, 5.0]


def test_no_odometry_and_odometry_off(tmp_path: Path) -> None:
    bare = write_bag(tmp_path / "bare.bag", 1, messages(with_odom=False))
    assert all(s.odom is None for s in read_rosbag(bare))
    full = write_bag(tmp_path / "full.bag", 1, messages())
    assert all(s.odom is None for s in read_rosbag(full, use_odom=False))


def test_topic_choice_errors(tmp_path: Path) -> None:
    msgs = messages()
    extra = [("/scan2", m[1], m[2], m[3]) for m in msgs if m[0] == "/scan"]
    two = write_bag(tmp_path / "two.bag", 1, sorted(msgs + extra, key=lambda m: m[2]))
    with pytest.raises(ValueError, match=r"several \(\['/scan', '/scan2'\]\) LaserScan topics"):
        list(read_rosbag(two))
    assert len(list(read_rosbag(two, scan_topic="/scan2"))) == 5
    with pytest.raises(ValueError, match=r"topic '/nope' is not in the bag"):
        list(read_rosbag(two, scan_topic="/nope"))
    with pytest.raises(ValueError, match=r"holds nav_msgs/msg/Odometry"):
        list(read_rosbag(two, scan_topic="/odom"))
    only_odom = write_bag(tmp_path / "odom.bag", 1, [m for m in msgs if m[0] == "/odom"])
    with pytest.raises(ValueError, match=r"no LaserScan topics; name one with scan_topic="):
        list(read_rosbag(only_odom))
    with pytest.raises(FileNotFoundError):
        read_rosbag(tmp_path / "absent.bag")


def test_what_is_not_a_bag_is_named(tmp_path: Path) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ValueError) as info:
        read_rosbag(empty)
    assert str(info.value) == f"{empty}: a directory without metadata.yaml is not a ROS 2 bag"
    fake = tmp_path / "fake.bag"
    fake.write_text("hello\n")
    with pytest.raises(ValueError) as info:
        list(read_rosbag(fake))
    assert str(info.value).startswith(f"{fake}: not a readable ROS bag: ")


def test_cli_maps_a_bag_and_drops_readings_beyond_range_max(tmp_path: Path) -> None:
    from ndtgrid.cli import main
    from ndtgrid.export import read_tum

    from ._room import scan as room_scan

    msgs = []
    for k in range(20):
        t = SCAN_T + 0.1 * k
        pose = np.array([-1.0 + 0.05 * k, -0.5, 0.02 * k])
        pts = room_scan(pose, beams=181, fov_deg=180.0, noise=0.003, seed=k)
        ranges = np.hypot(pts[:, 0], pts[:, 1])
        ranges[::10] = 9.5  # "no return" readings beyond range_max = 8 m
        scan = laser(t, list(ranges))
        scan.angle_min, scan.angle_increment = -math.pi / 2, math.pi / 180
        msgs.append(("/scan", "sensor_msgs/msg/LaserScan", t, scan))
        msgs.append(("/odom", "nav_msgs/msg/Odometry", t, odometry(t, *pose)))
    bag = write_bag(tmp_path / "room.bag", 1, msgs)
    out = tmp_path / "out"
    assert main(["map", str(bag), "--out", str(out), "--quiet"]) == 0
    times, poses = read_tum(out / "trajectory.tum")
    np.testing.assert_allclose(times, SCAN_T + 0.1 * np.arange(20), atol=1e-6)
    np.testing.assert_allclose(poses[:, 0], -1.0 + 0.05 * np.arange(20), atol=0.01)
    # No cell of the exported map lies outside the 6 m x 4 m room (the 9.5 m readings
    # would put points far outside it).
    from ndtgrid.export import load_map

    centres, _ = load_map(out / "map.ndtgrid").cells()
    assert np.abs(centres[:, 0]).max() < 3.1 and np.abs(centres[:, 1]).max() < 2.1
