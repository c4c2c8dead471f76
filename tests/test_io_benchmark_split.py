"""Tests of ``ndtgrid.io.read_benchmark_split`` (per-scan split of the benchmark logs)."""

from __future__ import annotations

import io
import math
import re
import tarfile
from pathlib import Path

import numpy as np
import pytest

from ndtgrid.io import read_benchmark_index, read_benchmark_split, read_carmen, read_log

from ._data import require_real

CSAIL_SPLIT = "benchmark-scans-split/mit_csail.tar.gz"
CSAIL_INDEX = "benchmark-scans-split/mit_csail__csail-corrected__index.csv"
CSAIL_FLASER = "mit-csail-flaser/dataset.txt"


def member(ranges: list[float], pose: tuple[float, float, float]) -> str:
    return "\n".join(["1 " + str(len(ranges)), *map(str, ranges), " ".join(map(str, pose))]) + "\n"


def archive(path: Path, members: dict[str, str]) -> Path:
    with tarfile.open(path, "w:gz") as tf:
        for name, text in members.items():
            data = text.encode()
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tf.addfile(info, io.BytesIO(data))
    return path


# ----------------------------------------------------------------------- real logs


@pytest.fixture(scope="module")
def csail() -> list:
    return list(read_benchmark_split(require_real(CSAIL_SPLIT)))


def test_csail_split_counts_order_and_angles(csail: list) -> None:
    assert len(csail) == 1988
    assert [s.source for s in csail[:3]] == [
        f"datasets/mit_csail/dataset_{k}.txt" for k in range(3)
    ]
    assert {s.n_beams for s in csail} == {361}
    assert all(math.isnan(s.timestamp) for s in csail)
    a = csail[0].angles
    assert a[0] == pytest.approx(-math.pi / 2, abs=1e-12)
    assert a[-1] == pytest.approx(math.pi / 2, abs=1e-12)
    np.testing.assert_allclose(np.diff(a), math.pi / 360, rtol=1e-12)
    # first and last raw pose as SOURCE.md lists them
    np.testing.assert_allclose(csail[0].odom, [576.536523, 0.106594, -2.255213])
    np.testing.assert_allclose(csail[-1].odom, [597.816512, -3.220376, -1.412351])


def test_csail_split_equals_the_flaser_log(csail: list) -> None:
    # The split and mit-csail-flaser/dataset.txt hold the same 1988 FLASER scans.
    flaser = list(read_carmen(require_real(CSAIL_FLASER)))
    assert len(flaser) == len(csail)
    for a, b in zip(csail, flaser):
        np.testing.assert_array_equal(a.ranges, b.ranges)
        np.testing.assert_allclose(a.odom, b.laser_pose, atol=1e-9)
        np.testing.assert_allclose(a.angles, b.angles, atol=1e-12)


def test_csail_split_poses_match_the_index(csail: list) -> None:
    index = read_benchmark_index(require_real(CSAIL_INDEX))
    poses = np.array([s.odom for s in csail])
    assert len(index) == 406
    np.testing.assert_allclose(poses[index.raw_scan], index.raw_odom, atol=2e-6)


def test_read_log_picks_the_split_reader() -> None:
    first = next(iter(read_log(require_real(CSAIL_SPLIT))))
    assert first.source == "datasets/mit_csail/dataset_0.txt"


# ----------------------------------------------------------------------- synthetic archives


def test_members_are_yielded_in_numeric_order(tmp_path: Path) -> None:
    names = [10, 2, 0, 1, 3, 4, 5, 6, 7, 8, 9]
    path = archive(
        tmp_path / "x.tar.gz",
        {f"datasets/x/dataset_{k}.txt": member([1.0 + k, 2.0], (k, 0, 0)) for k in names},
    )
    scans = list(read_benchmark_split(path, fov=math.pi / 2))
    assert [s.odom[0] for s in scans] == list(range(11))
    assert [s.ranges[0] for s in scans] == [1.0 + k for k in range(11)]
    np.testing.assert_allclose(scans[0].angles, [-math.pi / 4, math.pi / 4])


@pytest.mark.parametrize(
    ("text", "line", "expected"),
    [
        ("2 3\n1\n2\n3\n0 0 0\n", 1, "expected '1 <number of beams>'"),
        ("1 3\n1\n2\n0 0 0\n", 4, "expected 5 lines"),
        ("1 3\n1\nabc\n3\n0 0 0\n", 3, "expected one range in metres, got 'abc'"),
        ("1 2\n1\n2\n0 0\n", 4, "expected the pose 'x y theta' (3 numbers)"),
        ("1 2\n1\n2\n0 nan 0\n", 4, "expected a finite pose"),
    ],
)
def test_malformed_member_names_archive_member_and_line(
    tmp_path: Path, text: str, line: int, expected: str
) -> None:
    path = archive(
        tmp_path / "bad.tar.gz",
        {"datasets/x/dataset_0.txt": member([1.0], (0, 0, 0)), "datasets/x/dataset_1.txt": text},
    )
    with pytest.raises(ValueError) as info:
        list(read_benchmark_split(path))
    msg = str(info.value)
    assert msg.startswith(f"{path}:datasets/x/dataset_1.txt:{line}: ")
    assert expected in msg


def test_gap_and_duplicate_members_are_errors(tmp_path: Path) -> None:
    gap = archive(
        tmp_path / "gap.tar.gz",
        {f"d/dataset_{k}.txt": member([1.0], (0, 0, 0)) for k in (0, 1, 3)},
    )
    with pytest.raises(ValueError, match=r"member dataset_2.txt is missing"):
        list(read_benchmark_split(gap))
    dup = archive(
        tmp_path / "dup.tar.gz",
        {"a/dataset_0.txt": member([1.0], (0, 0, 0)), "b/dataset_0.txt": member([1.0], (0, 0, 0))},
    )
    with pytest.raises(ValueError, match=r"b/dataset_0.txt: scan 0 appears twice"):
        list(read_benchmark_split(dup))


def test_a_cut_archive_or_another_file_names_the_file(tmp_path: Path) -> None:
    whole = archive(
        tmp_path / "x.tar.gz",
        {f"d/dataset_{k}.txt": member([1.0 + k] * 200, (k, 0, 0)) for k in range(40)},
    ).read_bytes()
    cut = tmp_path / "cut.tar.gz"
    cut.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(
        ValueError, match=rf"^{re.escape(str(cut))}: not a readable \.tar\.gz after \d+ scans: "
    ):
        list(read_benchmark_split(cut))
    other = tmp_path / "other.tgz"
    other.write_text("1 2 3\n")
    with pytest.raises(ValueError) as info:
        list(read_benchmark_split(other))
    assert str(info.value) == f"{other}: not a readable .tar.gz after 0 scans: not a gzip file"


def test_other_members_are_skipped_and_bad_arguments_fail_early(tmp_path: Path) -> None:
    path = archive(
        tmp_path / "x.tar.gz",
        {"README.md": "hello\n", "d/dataset_0.txt": member([4.0, 5.0, 6.0], (1, 2, 3))},
    )
    (scan,) = list(read_benchmark_split(path))
    np.testing.assert_array_equal(scan.ranges, [4.0, 5.0, 6.0])
    with pytest.raises(FileNotFoundError):
        read_benchmark_split(tmp_path / "absent.tar.gz")
    with pytest.raises(ValueError, match="fov"):
        read_benchmark_split(path, fov=0.0)
