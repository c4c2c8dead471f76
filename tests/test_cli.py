"""The ``ndtgrid`` command line end to end: ``map`` (on a synthetic and real logs), ``eval``."""

from __future__ import annotations

import gzip
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ndtgrid
from ndtgrid.cli import main
from ndtgrid.export import load_map, read_ros_map, read_tum, write_tum
from ndtgrid.io import read_benchmark_index

from ._data import require_real
from ._room import scan as room_scan

N_SCANS = 40


def room_path(n: int) -> np.ndarray:
    t = np.arange(n, dtype=float)
    return np.stack([-1.5 + 0.06 * t, -0.8 + 0.4 * np.sin(t / 10.0), 0.2 * np.sin(t / 8.0)], 1)


def carmen_log(path: Path) -> np.ndarray:
    """A CARMEN log of the test room (181 beams over 180 degrees); returns the true poses."""
    poses = room_path(N_SCANS)
    lines = []
    for k, p in enumerate(poses):
        pts = room_scan(p, beams=181, fov_deg=180.0, noise=0.005, seed=k)
        ranges = np.hypot(pts[:, 0], pts[:, 1])
        odom = p + np.array([0.0, 0.0, 0.01 * k])  # drifting heading
        fields = ["FLASER", "181", *(f"{r:.4f}" for r in ranges)]
        fields += [f"{v:.6f}" for v in (*odom, *odom)]
        lines.append(" ".join([*fields, f"{10 + 0.1 * k:.3f}", "host", f"{10 + 0.1 * k:.3f}"]))
    path.write_text("\n".join(lines) + "\n")
    return poses


def test_version_and_help(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"ndtgrid {ndtgrid.__version__}"
    assert main([]) == 0
    out = capsys.readouterr().out
    assert "map" in out and "eval" in out


def test_map_writes_every_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    truth = carmen_log(tmp_path / "room.log")
    out = tmp_path / "out"
    assert main(["map", str(tmp_path / "room.log"), "--out", str(out), "--quiet"]) == 0
    assert f"{N_SCANS} scans in" in capsys.readouterr().out
    for name in ("map.png", "map.pgm", "map.yaml", "trajectory.tum", "map.ndtgrid"):
        assert (out / name).stat().st_size > 0, name
    times, poses = read_tum(out / "trajectory.tum")
    np.testing.assert_allclose(times, 10 + 0.1 * np.arange(N_SCANS), atol=1e-6)
    # The odometry's heading drifts by 0.01 rad per scan (0.39 rad at the end); matching
    # keeps the error to what the first scans put into the map.
    heading = np.abs(poses[:, 2] - truth[:, 2])
    assert heading.max() < 0.1 * 0.01 * (N_SCANS - 1)
    assert heading[-10:].max() < math.radians(1.5)
    assert np.max(np.hypot(*(poses[:, :2] - truth[:, :2]).T)) < 0.05
    image = read_ros_map(out / "map.yaml")
    assert image.resolution == 0.05
    assert (image.cells == 100).sum() > 300 and (image.cells == 0).sum() > 1000
    assert (out / "map.ndtgrid").read_bytes()[:8] == b"NDTGRID\x00"
    grid = load_map(out / "map.ndtgrid")
    assert grid.cell_size == 0.02 and len(grid) > 500
    assert (out / "map.png").read_bytes()[:4] == b"\x89PNG"


def test_eval_against_tum_and_index(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ref = room_path(10)
    est = ref.copy()
    est[5:, 0] += 0.1  # one relation off by 10 cm
    write_tum(tmp_path / "ref.tum", np.arange(10.0), ref)
    write_tum(tmp_path / "est.tum", np.arange(10.0) + 0.01, est)
    args = ["eval", "--estimate", str(tmp_path / "est.tum"), "--reference"]
    assert main([*args, str(tmp_path / "ref.tum"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["n"] == 9
    assert summary["translation_max"] == pytest.approx(0.1, abs=1e-6)
    assert summary["translation_mean"] == pytest.approx(0.1 / 9, abs=1e-6)
    # Nothing within 1 ms: a clear failure, not a silent empty result.
    assert main([*args, str(tmp_path / "ref.tum"), "--max-dt", "0.001"]) == 1
    assert "only 0 reference poses" in capsys.readouterr().err


def index_csv(path: Path, raw_scan: np.ndarray, poses: np.ndarray) -> Path:
    """A benchmark index CSV: corrected scan k is raw scan ``raw_scan[k]`` at pose k."""
    rows = [
        "gfs_scan,raw_scan,ipc_ts,logger_ts,corr_x,corr_y,corr_theta,raw_odo_x,raw_odo_y,"
        "raw_odo_theta"
    ]
    for k, (r, p) in enumerate(zip(raw_scan, poses)):
        rows.append(f"{k},{r},{100.0 + k},{100.0 + k},{p[0]},{p[1]},{p[2]},0,0,0")
    path.write_text("\n".join(rows) + "\n")
    return path


def test_eval_pairs_scan_numbers_by_the_column_asked_for(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Scan numbers pair by raw_scan (the full-rate log's, the default) or by gfs_scan
    (the corrected log's) as asked."""
    ref = room_path(20)
    index = index_csv(tmp_path / "index.csv", 3 + 7 * np.arange(20), ref)
    write_tum(tmp_path / "own.tum", np.arange(20.0), ref)  # the corrected log's numbers
    raw = np.zeros((140, 3))
    raw[3 + 7 * np.arange(20)] = ref
    write_tum(tmp_path / "raw.tum", np.arange(140.0), raw)  # the full-rate log's numbers
    for name, extra in [("raw.tum", []), ("own.tum", ["--reference-time", "gfs_scan"])]:
        argv = ["eval", "--estimate", str(tmp_path / name), "--reference", str(index)]
        assert main([*argv, *extra, "--json"]) == 0
        summary = json.loads(capsys.readouterr().out)
        assert summary["n"] == 19 and summary["translation_max"] < 1e-9, name
    # The corrected log's numbers read as raw ones: 3, 10 and 17 pair, wrongly.
    own = ["eval", "--estimate", str(tmp_path / "own.tum"), "--reference", str(index)]
    assert main([*own, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n"] == 2


def test_map_and_eval_on_the_subsampled_intel_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The GMapping-corrected Intel log (910 scans, its times out of order in 4 places,
    so the trajectory numbers the scans, and says so) against the benchmark index, paired
    by gfs_scan."""
    log = require_real("radish-gfs-corrected/intel-corrected.log.gz")
    index = require_real("benchmark-scans-split/intel__intel-corrected__index.csv")
    out = tmp_path / "intel"
    assert main(["map", str(log), "--out", str(out), "--quiet"]) == 0
    assert capsys.readouterr().err == (
        "ndtgrid map: the log's times go back or repeat in 4 places, so trajectory.tum "
        "numbers the scans (0, 1, ...) instead (ndtgrid eval pairs them with an index CSV "
        "by --reference-time raw_scan for a full-rate log, gfs_scan for a corrected one)\n"
    )
    times, _ = read_tum(out / "trajectory.tum")
    np.testing.assert_array_equal(times, np.arange(910.0))
    est = ["eval", "--estimate", str(out / "trajectory.tum"), "--reference", str(index)]
    assert main([*est, "--reference-time", "gfs_scan", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["n"] == 909
    assert summary["translation_mean"] < 0.06 and summary["rotation_mean"] < 1.0


def test_map_and_eval_on_the_intel_split(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = require_real("benchmark-scans-split/intel.tar.gz")
    index = require_real("benchmark-scans-split/intel__intel-corrected__index.csv")
    out = tmp_path / "intel"
    assert main(["map", str(log), "--out", str(out), "--max-scans", "1500", "--quiet"]) == 0
    capsys.readouterr()
    times, _ = read_tum(out / "trajectory.tum")
    np.testing.assert_array_equal(times, np.arange(1500.0))  # no time in the split: indices
    assert (
        main(
            ["eval", "--estimate", str(out / "trajectory.tum"), "--reference", str(index), "--json"]
        )
        == 0
    )
    summary = json.loads(capsys.readouterr().out)
    rows = read_benchmark_index(index)
    assert summary["n"] == int((rows.raw_scan < 1500).sum()) - 1  # consecutive relations
    assert summary["translation_mean"] < 0.05 and summary["rotation_mean"] < 1.5


def test_map_on_the_mines_log_with_forced_format(tmp_path: Path) -> None:
    log = require_real("breezyslam-mines-urg04lx/exp1.dat")
    out = tmp_path / "mines"
    assert (
        main(
            [
                "map",
                str(log),
                "--out",
                str(out),
                "--format",
                "mines",
                "--max-scans",
                "200",
                "--quiet",
            ]
        )
        == 0
    )
    times, _ = read_tum(out / "trajectory.tum")
    assert times.shape == (200,) and times[0] == pytest.approx(212.387282)


def test_bad_files_and_values_are_one_line_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A missing, unknown, cut or unreadable file, or a bad value: exit status 1 and one
    line on stderr naming the command and the file (no traceback); no outputs written."""
    log = tmp_path / "room.log"
    carmen_log(log)
    cut = tmp_path / "cut.log.gz"
    whole = gzip.compress(log.read_bytes())
    cut.write_bytes(whole[: len(whole) // 2])
    out = tmp_path / "out"
    cases = [
        (["map", str(tmp_path / "absent.log")], "No such file or directory"),
        (["map", str(tmp_path)], f"{tmp_path}: a directory without metadata.yaml is not"),
        (["map", str(log.with_suffix(".png"))], "cannot tell the log format from the name"),
        (["map", str(cut)], f"{cut}: damaged gzip data after line"),
        (["map", str(log), "--cell-size", "-1"], "cell_size: expected a finite cell size"),
        (["eval", "--estimate", str(log), "--reference", str(log)], f"{log}:1: expected 8"),
    ]
    for argv, expected in cases:
        command = argv[0]
        if command == "map":
            argv = [*argv, "--out", str(out), "--quiet"]
        assert main(argv) == 1, argv
        err = capsys.readouterr().err
        assert err.startswith(f"ndtgrid {command}: ") and expected in err, (argv, err)
        assert err.count("\n") == 1, err
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["map", "x.log", "--max-scans", "-3"], "argument --max-scans: expected a whole number"),
        (["map", "x.log", "--max-scans", "2.5"], "argument --max-scans: expected a whole number"),
        (["eval", "--estimate", "a", "--reference", "b", "--max-dt", "nan"], "argument --max-dt"),
        (["eval", "--estimate", "a", "--reference", "b", "--max-dt", "-1"], "expected seconds"),
        (["demo", "--seed", "-5"], "argument --seed: expected a whole number >= 0, got '-5'"),
        (["bench", "--seed", "x"], "argument --seed: expected a whole number >= 0, got 'x'"),
    ],
)
def test_bad_counts_and_times_are_usage_errors(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A negative or fractional scan count, or a time gap that is negative or not a
    number: argparse's usage error (exit status 2), before any file is read."""
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    assert message in capsys.readouterr().err


def test_readings_beyond_max_range_are_dropped() -> None:
    from ndtgrid.cli import usable_ranges
    from ndtgrid.io import Scan

    scan = Scan(0.0, [1.0, 8.0, 9.5, 2.0], [0.0, 0.1, 0.2, 0.3], max_range=8.0)
    np.testing.assert_array_equal(usable_ranges(scan), [1.0, np.nan, np.nan, 2.0])
    free = Scan(0.0, [1.0, 9.5], [0.0, 0.1])
    np.testing.assert_array_equal(usable_ranges(free), [1.0, 9.5])


def test_console_script_runs() -> None:
    res = subprocess.run(
        [
            sys.executable,
            "-c",
            "from ndtgrid.cli import main; raise SystemExit(main())",
            "--version",
        ],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0 and res.stdout.startswith("ndtgrid ")
