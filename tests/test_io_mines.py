"""Tests of ``ndtgrid.io.read_mines`` (Mines URG-04LX logs of BreezySLAM)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from ndtgrid.io import read_log, read_mines
from ndtgrid.io.mines import HALF_AXLE, LASER_OFFSET, WHEEL_RADIUS

from ._data import require_real

EXP1 = "breezyslam-mines-urg04lx/exp1.dat"


def line(stamp: int, left: int, right: int, ranges_mm: list[int]) -> str:
    """A 707-token line: stamp, 1 undocumented, ticks, 20 status fields, 0, 682 ranges."""
    assert len(ranges_mm) == 682
    status = ["0"] * 20
    return " ".join(
        [str(stamp), "14710", str(left), str(right), *status, "0 ", *map(str, ranges_mm)]
    )


def write(path: Path, lines: list[str]) -> Path:
    path.write_text("\n".join(lines) + "\n")
    return path


# ----------------------------------------------------------------------- real log


def test_exp1_counts_times_and_beams() -> None:
    scans = list(read_mines(require_real(EXP1)))
    assert len(scans) == 756
    assert scans[0].timestamp == pytest.approx(212.387282)
    assert scans[-1].timestamp - scans[0].timestamp == pytest.approx(74.620139)
    assert {s.n_beams for s in scans} == {682}
    a = scans[0].angles
    assert math.degrees(a[0]) == pytest.approx(-120.0)
    assert math.degrees(a[-1]) == pytest.approx(120.0)
    ranges = np.array([s.ranges for s in scans])
    # SOURCE.md: about half the readings are "no return" (0), the largest is 5562 mm
    assert 0.50 < np.mean(ranges == 0.0) < 0.55
    assert ranges.max() <= 5.562
    # beams at the ends are blocked by the robot: valid in < 5 % of the scans
    valid = np.mean(ranges > 0.0, axis=0)
    assert valid[:50].max() < 0.05 and valid[660:].max() < 0.05
    assert valid[100:600].min() > 0.05
    np.testing.assert_array_equal(scans[0].odom, [0.0, 0.0, 0.0])
    assert all(s.line == k + 1 for k, s in enumerate(scans))


def test_exp1_laser_sits_ahead_of_the_robot() -> None:
    for scan in list(read_mines(require_real(EXP1)))[::50]:
        assert scan.odom is not None and scan.laser_pose is not None
        x, y, th = scan.odom
        np.testing.assert_allclose(
            scan.laser_pose,
            [x + LASER_OFFSET * math.cos(th), y + LASER_OFFSET * math.sin(th), th],
            atol=1e-12,
        )


def test_read_log_picks_the_mines_reader() -> None:
    first = next(iter(read_log(require_real(EXP1))))
    assert first.source == "MINES" and first.n_beams == 682


# ----------------------------------------------------------------------- synthetic logs


def test_wheel_ticks_integrate_as_breezyslam(tmp_path: Path) -> None:
    r = [0] * 682
    path = write(
        tmp_path / "odo.dat",
        [
            line(1_000_000, 0, 0, r),
            line(1_100_000, 2000, 2000, r),  # both wheels half a turn: straight ahead
            line(1_200_000, 1000, 3000, r),  # left -1000, right +1000 ticks: turn in place
            line(1_300_000, 2000, 4000, r),  # both +1000 ticks: straight, along the new heading
        ],
    )
    scans = list(read_mines(path))
    dxy = WHEEL_RADIUS * (math.pi + math.pi)  # r * (dleft + dright) in rad
    dtheta = math.radians((WHEEL_RADIUS / HALF_AXLE) * (90.0 - (-90.0)))
    np.testing.assert_allclose(scans[1].odom, [dxy, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(scans[2].odom, [dxy, 0.0, dtheta], atol=1e-12)
    half = dxy / 2
    np.testing.assert_allclose(
        scans[3].odom,
        [dxy + half * math.cos(dtheta), half * math.sin(dtheta), dtheta],
        atol=1e-12,
    )
    assert [s.timestamp for s in scans] == pytest.approx([1.0, 1.1, 1.2, 1.3])


def test_range_tokens_follow_the_loader_or_the_other_reading(tmp_path: Path) -> None:
    ranges = list(range(1000, 1682))
    path = write(tmp_path / "r.dat", [line(5, 0, 0, ranges)])
    (loader,) = list(read_mines(path))
    # Tokens 24..705: the always-zero token 24, then the first 681 of the 682 values.
    assert loader.ranges[0] == 0.0
    np.testing.assert_allclose(loader.ranges[1:], np.array(ranges[:681]) / 1000.0)
    (other,) = list(read_mines(path, first_range_token=25))
    np.testing.assert_allclose(other.ranges, np.array(ranges) / 1000.0)
    with pytest.raises(ValueError, match="first_range_token"):
        read_mines(path, first_range_token=3)


def test_malformed_lines_name_file_and_line(tmp_path: Path) -> None:
    good = line(1, 0, 0, [0] * 682)
    short = write(tmp_path / "short.dat", [good, "1 2 3 4 5"])
    with pytest.raises(ValueError, match=rf"^{short}:2: expected at least 706 tokens"):
        list(read_mines(short))
    bad = good.split()
    bad[3] = "x12"
    path = write(tmp_path / "bad.dat", [good, "", " ".join(bad)])
    with pytest.raises(ValueError, match=rf"^{path}:3: token 3: expected an integer, got 'x12'"):
        list(read_mines(path))
    with pytest.raises(FileNotFoundError):
        read_mines(tmp_path / "absent.dat")
