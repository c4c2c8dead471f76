"""Tests of the CARMEN log reader ``ndtgrid.io.read_carmen`` / ``iter_carmen_messages``."""

from __future__ import annotations

import csv
import dataclasses
import gzip
import math
import re
import time
from pathlib import Path

import numpy as np
import pytest

from ndtgrid.io import OdomRecord, Scan, iter_carmen_messages, read_carmen

from ._data import require_real

INTEL = "radish-gfs-corrected/intel-corrected.log.gz"
INTEL_INDEX = "benchmark-scans-split/intel__intel-corrected__index.csv"
CSAIL = "mit-csail-flaser/dataset.txt"


def flaser(ranges: list[float], pose: tuple[float, float, float], odom=None, ts=12.5) -> str:
    """One FLASER line; ``odom`` defaults to ``pose``."""
    odom = pose if odom is None else odom
    fields = ["FLASER", str(len(ranges)), *map(str, ranges), *map(str, pose), *map(str, odom)]
    return " ".join([*fields, str(ts), "host", str(ts + 0.001)])


def write(path: Path, lines: list[str]) -> Path:
    path.write_text("\n".join(lines) + "\n")
    return path


# ----------------------------------------------------------------------- real logs


@pytest.fixture(scope="module")
def intel_scans() -> list[Scan]:
    return list(read_carmen(require_real(INTEL)))


@pytest.fixture(scope="module")
def csail_scans() -> list[Scan]:
    return list(read_carmen(require_real(CSAIL)))


def test_intel_counts_and_beams(intel_scans: list[Scan]) -> None:
    assert len(intel_scans) == 910
    assert {s.ranges.shape for s in intel_scans} == {(180,)}
    assert {s.source for s in intel_scans} == {"FLASER"}
    assert all(s.max_range is None for s in intel_scans)
    # the first FLASER is on line 175 (after 2 comments, 2 PARAM and 170 ODOM lines)
    first = intel_scans[0]
    assert first.line == 175
    assert first.ranges[0] == 1.09 and first.ranges[-1] == 1.23
    # 81.83 is the SICK "no return" value of this log
    assert max(float(s.ranges.max()) for s in intel_scans) == pytest.approx(81.83)


def test_intel_angles_span_half_circle(intel_scans: list[Scan]) -> None:
    angles = intel_scans[0].angles
    assert angles.dtype == np.float64
    assert angles[0] == pytest.approx(-math.pi / 2, abs=1e-12)
    assert angles[-1] == pytest.approx(math.pi / 2, abs=1e-12)
    np.testing.assert_allclose(np.diff(angles), math.pi / 179, rtol=1e-12)


def test_intel_poses_and_timestamps_match_index(intel_scans: list[Scan]) -> None:
    with require_real(INTEL_INDEX).open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(intel_scans) == 910
    first = intel_scans[0]
    corr = [float(rows[0][k]) for k in ("corr_x", "corr_y", "corr_theta")]
    assert corr == pytest.approx([0.600266, -0.0320327, -0.354665])
    np.testing.assert_allclose(first.laser_pose, corr, atol=1e-6)
    np.testing.assert_allclose(first.odom, corr, atol=1e-6)
    assert first.timestamp == pytest.approx(float(rows[0]["ipc_ts"]), abs=1e-6)
    assert first.timestamp == pytest.approx(32.9068)
    # and every other row, in order
    table = np.array(
        [[float(r[k]) for k in ("ipc_ts", "corr_x", "corr_y", "corr_theta")] for r in rows]
    )
    np.testing.assert_allclose([s.timestamp for s in intel_scans], table[:, 0], atol=1e-6)
    np.testing.assert_allclose([s.laser_pose for s in intel_scans], table[:, 1:], atol=1e-6)
    np.testing.assert_allclose([s.odom for s in intel_scans], table[:, 1:], atol=1e-6)


def test_intel_reads_fast() -> None:
    path = require_real(INTEL)
    start = time.perf_counter()
    n = sum(1 for _ in read_carmen(path))
    elapsed = time.perf_counter() - start
    assert n == 910
    assert elapsed < 1.0, f"reading 910 scans took {elapsed:.2f} s"


def test_intel_messages_include_odom() -> None:
    messages = list(iter_carmen_messages(require_real(INTEL)))
    odom = [m for m in messages if isinstance(m, OdomRecord)]
    scans = [m for m in messages if isinstance(m, Scan)]
    assert len(scans) == 910
    assert len(odom) == 14541
    assert odom[0].line == 5
    assert odom[0].timestamp == pytest.approx(0.000246)
    np.testing.assert_array_equal(odom[0].pose, [0.0, 0.0, 0.0])
    lines = [m.line for m in messages]
    assert lines == sorted(lines)


def test_csail_counts_and_poses(csail_scans: list[Scan]) -> None:
    assert len(csail_scans) == 1988
    assert {s.ranges.shape for s in csail_scans} == {(361,)}
    # SOURCE.md: the FLASER laser pose equals the odom pose in all 1988 lines
    for s in csail_scans:
        assert s.laser_pose is not None and s.odom is not None
        np.testing.assert_array_equal(s.laser_pose, s.odom)
    first, last = csail_scans[0], csail_scans[-1]
    assert first.line == 4  # after 3 comment lines
    np.testing.assert_allclose(first.odom, [576.536523, 0.106594, -2.255213], atol=1e-9)
    np.testing.assert_allclose(last.odom, [597.816512, -3.220376, -1.412351], atol=1e-9)
    assert first.timestamp == pytest.approx(1134864629.895182, abs=1e-6)
    assert last.timestamp == pytest.approx(1134865053.892206, abs=1e-6)
    # 361 beams over 180 degrees: 0.5 degree steps, both ends included
    np.testing.assert_allclose(np.diff(first.angles), math.pi / 360, rtol=1e-12)
    assert first.angles[0] == pytest.approx(-math.pi / 2)
    assert first.angles[-1] == pytest.approx(math.pi / 2)


def test_csail_has_no_odom_messages() -> None:
    kinds = {type(m) for m in iter_carmen_messages(require_real(CSAIL))}
    assert kinds == {Scan}


# ----------------------------------------------------------------------- written logs


def test_flaser_fields_and_fov(tmp_path: Path) -> None:
    line = flaser([1.0, 2.0, 3.0, 4.0, 5.5], (1.0, 2.0, 0.5), odom=(3.0, 4.0, -0.25), ts=7.25)
    path = write(tmp_path / "a.log", [line])
    (scan,) = read_carmen(path, fov=math.radians(240))
    np.testing.assert_array_equal(scan.ranges, [1.0, 2.0, 3.0, 4.0, 5.5])
    np.testing.assert_allclose(np.degrees(scan.angles), [-120.0, -60.0, 0.0, 60.0, 120.0])
    np.testing.assert_array_equal(scan.laser_pose, [1.0, 2.0, 0.5])
    np.testing.assert_array_equal(scan.odom, [3.0, 4.0, -0.25])
    assert scan.timestamp == 7.25
    assert scan.max_range is None
    assert (scan.source, scan.line) == ("FLASER", 1)


def test_skips_comments_params_and_unknown(tmp_path: Path) -> None:
    path = write(
        tmp_path / "a.log",
        [
            "# message formats defined: PARAM SYNC ODOM FLASER RLASER TRUEPOS",
            "PARAM robot_frontlaser_offset 0.0 nohost 0",
            "",
            "SYNC whatever 1 2 3",
            "TRUEPOS 1 2 3 4 5 6 0.1 host 0.1",
            "   ",
            "#FLASER 2 1 1 0 0 0 0 0 0 0 h 0",
            flaser([1.0, 2.0], (0.0, 0.0, 0.0), ts=1.0),
            "NEFF 15",
            "PARAM broken",
            flaser([3.0, 4.0], (1.0, 0.0, 0.0), ts=2.0),
        ],
    )
    scans = list(read_carmen(path))
    assert [s.line for s in scans] == [8, 11]
    assert [s.timestamp for s in scans] == [1.0, 2.0]
    np.testing.assert_array_equal(scans[1].ranges, [3.0, 4.0])


def test_gzip_reads_like_plain_text(tmp_path: Path) -> None:
    lines = [
        "# header",
        flaser([1.0, 2.0, 3.0], (0.1, 0.2, 0.3), ts=1.0),
        "ODOM 0.5 0.25 0.125 0 0 0 1.5 host 1.5",
        flaser([4.0, 5.0, 6.0], (0.4, 0.5, 0.6), ts=2.0),
    ]
    plain = write(tmp_path / "plain.gz", lines)  # a misleading name: the bytes decide
    packed = tmp_path / "packed.log"
    packed.write_bytes(gzip.compress(plain.read_bytes()))
    assert packed.read_bytes()[:2] == b"\x1f\x8b"
    a = list(iter_carmen_messages(plain))
    b = list(iter_carmen_messages(str(packed)))
    assert [type(m) for m in a] == [type(m) for m in b] == [Scan, OdomRecord, Scan]
    for x, y in zip(a, b):
        assert x.line == y.line and x.timestamp == y.timestamp
        if isinstance(x, Scan) and isinstance(y, Scan):
            np.testing.assert_array_equal(x.ranges, y.ranges)
            np.testing.assert_array_equal(x.angles, y.angles)
            np.testing.assert_array_equal(x.odom, y.odom)
            np.testing.assert_array_equal(x.laser_pose, y.laser_pose)
    assert [s.line for s in read_carmen(packed)] == [2, 4]


def test_robotlaser1(tmp_path: Path) -> None:
    ranges = [1.5, 2.5, 3.5, 4.5]
    line = " ".join(
        [
            "ROBOTLASER1 0 -2.0 3.0 0.75 30.0 0.01 0",
            f"{len(ranges)} {' '.join(map(str, ranges))}",
            "2 100 200",  # num_remissions and the remissions
            "1.0 2.0 0.1",  # laser pose
            "0.8 1.9 0.1",  # robot pose
            "0.3 0.05 0.5 0.2 0.0",  # tv rv forward_safety side_safety turn_axis
            "1234.5 myhost 1234.6",
        ]
    )
    path = write(tmp_path / "a.log", ["# x", line])
    (scan,) = read_carmen(path)
    assert (scan.source, scan.line) == ("ROBOTLASER1", 2)
    np.testing.assert_array_equal(scan.ranges, ranges)
    np.testing.assert_allclose(scan.angles, [-2.0, -1.25, -0.5, 0.25])
    np.testing.assert_array_equal(scan.laser_pose, [1.0, 2.0, 0.1])
    np.testing.assert_array_equal(scan.odom, [0.8, 1.9, 0.1])
    assert scan.max_range == 30.0
    assert scan.timestamp == 1234.5
    # excluded when not asked for
    assert list(read_carmen(path, lasers=("FLASER",))) == []


def test_odom_records(tmp_path: Path) -> None:
    path = write(
        tmp_path / "a.log",
        [
            "ODOM 1.5 -2.25 0.5 0.3 0.1 0 100.25 host 100.3",
            flaser([1.0], (0.0, 0.0, 0.0), ts=100.5),
            "ODOM 1.75 -2.5 0.625 0.3 0.1 0 100.75 host 100.8",
        ],
    )
    messages = list(iter_carmen_messages(path))
    assert [type(m) for m in messages] == [OdomRecord, Scan, OdomRecord]
    first, last = messages[0], messages[2]
    assert isinstance(first, OdomRecord) and isinstance(last, OdomRecord)
    np.testing.assert_array_equal(first.pose, [1.5, -2.25, 0.5])
    np.testing.assert_array_equal(last.pose, [1.75, -2.5, 0.625])
    assert (first.timestamp, first.line) == (100.25, 1)
    assert (last.timestamp, last.line) == (100.75, 3)
    # read_carmen yields the scan only
    assert [s.line for s in read_carmen(path)] == [2]


def test_rlaser_ignored_by_default(tmp_path: Path) -> None:
    rear = flaser([7.0, 8.0], (0.0, 0.0, math.pi), ts=2.0).replace("FLASER", "RLASER")
    path = write(tmp_path / "a.log", [flaser([1.0, 2.0], (0.0, 0.0, 0.0), ts=1.0), rear])
    assert [s.source for s in read_carmen(path)] == ["FLASER"]
    (only,) = read_carmen(path, lasers=("RLASER",))
    assert (only.source, only.line, only.timestamp) == ("RLASER", 2, 2.0)
    np.testing.assert_array_equal(only.ranges, [7.0, 8.0])
    both = list(read_carmen(path, lasers=("FLASER", "RLASER")))
    assert [s.source for s in both] == ["FLASER", "RLASER"]


GOOD = flaser([1.0, 2.0, 3.0], (0.0, 0.0, 0.0))
ROBOT = "ROBOTLASER1 0 -1.5 3.0 1.5 30 0.01 0 3 1 2 3 {k} {rem} 0 0 0 0 0 0 0 0 0 0 0 5.0 h 5.0"

MALFORMED = {
    "flaser too few fields": (
        "FLASER 3 1 2 3 0 0 0 0 0 0 12.5 host",
        ["expected 14 fields for n=3 beams", "got 13"],
    ),
    "flaser too many fields": (GOOD + " extra", ["expected 14 fields", "got 15"]),
    "flaser nothing after kind": ("FLASER", ["expected the beam count n", "end of the line"]),
    "flaser count not an integer": (
        GOOD.replace("FLASER 3", "FLASER 3.0"),
        ["the beam count n as a non-negative integer in field 2", "got '3.0'"],
    ),
    "flaser negative count": (
        GOOD.replace("FLASER 3", "FLASER -3"),
        ["non-negative integer", "got '-3'"],
    ),
    "flaser range not a number": (
        "FLASER 3 1 abc 3 0 0 0 0 0 0 12.5 host 12.5",
        ["expected a number for range 2 of 3 (field 4)", "got 'abc'"],
    ),
    "flaser pose not a number": (
        "FLASER 3 1 2 3 0 0 0 0 y? 0 12.5 host 12.5",
        ["expected a number for odom_y (field 10)", "got 'y?'"],
    ),
    "flaser logger timestamp not a number": (
        "FLASER 3 1 2 3 0 0 0 0 0 0 12.5 host later",
        ["expected a number for logger_timestamp (field 14)", "got 'later'"],
    ),
    "flaser non-finite laser pose": (
        "FLASER 3 1 2 3 nan 0 0 0 0 0 12.5 host 12.5",
        ["expected a finite laser pose", "got nan 0.0 0.0"],
    ),
    "flaser non-finite odom": (
        "FLASER 3 1 2 3 0 0 0 0 inf 0 12.5 host 12.5",
        ["expected a finite odometry pose", "got 0.0 inf 0.0"],
    ),
    "flaser non-finite timestamp": (
        "FLASER 3 1 2 3 0 0 0 0 0 0 nan host 12.5",
        ["expected a finite ipc_timestamp", "got nan"],
    ),
    "robotlaser too few fields": (
        ROBOT.format(k=2, rem="7") + "",
        ["expected 29 fields for num_readings=3 and num_remissions=2", "got 28"],
    ),
    "robotlaser remission count bad": (
        ROBOT.format(k="two", rem="7 8"),
        ["expected num_remissions as a non-negative integer in field 13", "got 'two'"],
    ),
    "robotlaser remission not a number": (
        ROBOT.format(k=2, rem="7 x"),
        ["expected a number for remission 2 of 2 (field 15)", "got 'x'"],
    ),
    "robotlaser start angle not a number": (
        ROBOT.format(k=0, rem="").replace("-1.5", "left"),
        ["expected a number for start_angle (field 3)", "got 'left'"],
    ),
}


@pytest.mark.parametrize("bad, expected", MALFORMED.values(), ids=list(MALFORMED))
def test_malformed_line_messages(tmp_path: Path, bad: str, expected: list[str]) -> None:
    path = write(tmp_path / "bad.log", ["# comment", GOOD, bad, GOOD])
    scans = read_carmen(path)
    assert next(scans).line == 2  # lines before the bad one are read
    with pytest.raises(ValueError) as info:
        next(scans)
    message = str(info.value)
    assert message.startswith(f"{path}:3: ")
    for part in expected:
        assert part in message


@pytest.mark.parametrize(
    "bad, expected",
    [
        ("ODOM 1 2 3 0 0 0 5.0 host", ["expected 10 fields (ODOM x y theta", "got 9"]),
        ("ODOM 1 2 three 0 0 0 5.0 host 5.0", ["a number for theta (field 4)", "'three'"]),
        ("ODOM 1 -inf 3 0 0 0 5.0 host 5.0", ["expected a finite pose", "got 1.0 -inf 3.0"]),
    ],
)
def test_malformed_odom(tmp_path: Path, bad: str, expected: list[str]) -> None:
    path = write(tmp_path / "bad.log", [GOOD, GOOD, bad])
    with pytest.raises(ValueError) as info:
        list(iter_carmen_messages(path))
    assert str(info.value).startswith(f"{path}:3: ")
    for part in expected:
        assert part in str(info.value)
    # read_carmen does not parse ODOM lines at all
    assert [s.line for s in read_carmen(path)] == [1, 2]


def test_missing_file_raises_at_call(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        read_carmen(tmp_path / "nope.log")
    with pytest.raises(FileNotFoundError):
        iter_carmen_messages(str(tmp_path / "nope.log.gz"))


def test_a_cut_or_damaged_gzip_log_names_the_file_and_the_last_line(tmp_path: Path) -> None:
    whole = gzip.compress("".join(f"{GOOD}\n" for _ in range(400)).encode())
    cut = tmp_path / "cut.log.gz"
    cut.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(ValueError) as info:
        list(read_carmen(cut))
    m = re.fullmatch(
        rf"{re.escape(str(cut))}: damaged gzip data after line (\d+): Compressed file ended "
        "before the end-of-stream marker was reached",
        str(info.value),
    )
    assert m is not None, str(info.value)
    assert 0 < int(m.group(1)) < 400
    damaged = tmp_path / "damaged.log.gz"
    damaged.write_bytes(whole[:40] + bytes(b ^ 0xFF for b in whole[40:80]) + whole[80:])
    with pytest.raises(ValueError, match=rf"^{re.escape(str(damaged))}: damaged gzip data after"):
        list(iter_carmen_messages(damaged))


def test_bad_arguments(tmp_path: Path) -> None:
    path = write(tmp_path / "a.log", [GOOD])
    with pytest.raises(TypeError, match="lasers"):
        read_carmen(path, lasers="FLASER")
    with pytest.raises(ValueError, match=r"lasers: .*got 'LASER9'"):
        read_carmen(path, lasers=("FLASER", "LASER9"))
    with pytest.raises(ValueError, match=r"fov: .*got 0\.0"):
        read_carmen(path, fov=0.0)
    with pytest.raises(ValueError, match="fov"):
        read_carmen(path, fov=7.0)
    with pytest.raises(TypeError, match="fov"):
        read_carmen(path, fov="pi")  # type: ignore[arg-type]
    assert list(read_carmen(path, lasers=())) == []


# ----------------------------------------------------------------------- Scan itself


def test_scan_validates_and_converts() -> None:
    scan = Scan(timestamp=1, ranges=[1, 2], angles=np.array([0.0, 0.5], dtype=np.float32))
    assert scan.ranges.dtype == scan.angles.dtype == np.float64
    assert scan.timestamp == 1.0 and isinstance(scan.timestamp, float)
    assert scan.odom is None and scan.laser_pose is None
    with pytest.raises(ValueError, match="same length, got 2 ranges and 3 angles"):
        Scan(timestamp=0.0, ranges=np.ones(2), angles=np.zeros(3))
    with pytest.raises(ValueError, match=r"ranges must be 1-D, got shape \(2, 2\)"):
        Scan(timestamp=0.0, ranges=np.ones((2, 2)), angles=np.zeros(4))
    with pytest.raises(ValueError, match=r"odom must have shape \(3,\)"):
        Scan(timestamp=0.0, ranges=np.ones(2), angles=np.zeros(2), odom=np.zeros(2))
    with pytest.raises(dataclasses.FrozenInstanceError):
        scan.timestamp = 2.0  # type: ignore[misc]


def test_scan_repr_shows_shapes_not_arrays() -> None:
    ranges = np.full(180, 3.14159)
    scan = Scan(
        timestamp=32.9068,
        ranges=ranges,
        angles=np.linspace(-math.pi / 2, math.pi / 2, 180),
        odom=np.array([0.6, -0.03, -0.35]),
        source="FLASER",
        line=175,
    )
    text = repr(scan)
    assert "ranges=<180 float64>" in text
    assert "3.14159" not in text
    assert "odom=[0.6, -0.03, -0.35]" in text
    assert "line=175" in text and "source='FLASER'" in text
    assert len(text) < 300


def test_scan_points_skip_invalid_ranges() -> None:
    angles = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5])
    ranges = np.array([1.0, 0.0, np.nan, np.inf, 4.0, 2.0])
    scan = Scan(
        timestamp=0.0,
        ranges=ranges,
        angles=angles,
        odom=None,
        laser_pose=None,
        max_range=4.0,
        source="FLASER",
        line=1,
    )
    expected = np.array([[np.cos(0.0), 0.0], [2 * np.cos(2.5), 2 * np.sin(2.5)]])
    np.testing.assert_allclose(scan.points(), expected, atol=1e-15)
    assert scan.points(max_range=10.0).shape == (3, 2)
    assert scan.points(min_range=1.5, max_range=10.0).shape == (2, 2)
    with pytest.raises(ValueError, match=r"^max_range: expected a range > min_range, got 0\.5$"):
        scan.points(min_range=1.0, max_range=0.5)
